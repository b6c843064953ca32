// SmartMove's `predicates` parameter: "right_of(table_center); near(node_1)", each applied to
// the part (as its first argument, or where "?" stands). The editor builds it from lists.

export interface PredicateTerm {
  name: string;
  args: string[];
}

export function parsePredicates(text: string): PredicateTerm[] {
  const terms: PredicateTerm[] = [];
  for (const raw of text.split(';')) {
    const item = raw.trim();
    if (!item) continue;
    const open = item.indexOf('(');
    if (open < 0) {
      terms.push({ name: item, args: [] });
      continue;
    }
    const close = item.lastIndexOf(')');
    const inside = item.slice(open + 1, close < 0 ? undefined : close);
    terms.push({
      name: item.slice(0, open).trim(),
      args: inside.trim() === '' ? [] : inside.split(',').map((a) => a.trim()),
    });
  }
  return terms;
}

export function formatPredicates(terms: PredicateTerm[]): string {
  return terms
    .filter((term) => term.name)
    .map((term) => `${term.name}(${term.args.join(',')})`)
    .join('; ');
}

/**
 * The choices for a condition's reference: what the cell knows now (frames, parts, classes),
 * and the one the plan names first, marked, when the cell does not know it any more (a part the
 * last detection did not see): it stays shown until it is changed.
 */
export function referenceChoices(current: string, references: string[]): { value: string; label: string; known: boolean }[] {
  const known = references.includes(current);
  return [
    ...(known ? [] : [{ value: current, label: `${current} (not in the cell now)`, known: false }]),
    ...references.map((r) => ({ value: r, label: r, known: true })),
  ];
}
