// Comparing two versions of a plan as trees: which nodes were added, removed or changed (and
// which attributes), tree by tree. Children are matched in order by their type and name (the
// longest common subsequence), so inserting a node does not mark everything after it changed.

import { Attribute, EditorNode, EditorPlan } from './tree';

export interface AttributeChange {
  name: string;
  from?: string;
  to?: string;
}

export interface DiffEntry {
  kind: 'added' | 'removed' | 'changed';
  tree: string;
  /** Where the node is: type and name of each node from the root, e.g. Sequence › SmartGrasp “grasp”. */
  path: string;
  id: string;
  /** The node's key in the newer plan (added, changed) or the older one (removed). */
  key: string;
  attributes: AttributeChange[];
}

function label(node: EditorNode): string {
  const name = node.attributes.find(([k]) => k === 'name')?.[1];
  return name ? `${node.id} “${name}”` : node.id;
}

function attributeChanges(a: Attribute[], b: Attribute[]): AttributeChange[] {
  const before = new Map(a);
  const after = new Map(b);
  const changes: AttributeChange[] = [];
  for (const [name, value] of a) {
    if (!after.has(name)) changes.push({ name, from: value });
    else if (after.get(name) !== value) changes.push({ name, from: value, to: after.get(name) });
  }
  for (const [name, value] of b) if (!before.has(name)) changes.push({ name, to: value });
  return changes;
}

const signature = (node: EditorNode) => `${node.id}\u0000${node.attributes.find(([k]) => k === 'name')?.[1] ?? ''}`;

/** Index pairs of the longest common subsequence of the two child lists (by signature). */
function matchChildren(a: EditorNode[], b: EditorNode[]): [number, number][] {
  const n = a.length;
  const m = b.length;
  const table: number[][] = Array.from({ length: n + 1 }, () => new Array<number>(m + 1).fill(0));
  for (let i = n - 1; i >= 0; i--) {
    for (let j = m - 1; j >= 0; j--) {
      table[i][j] = signature(a[i]) === signature(b[j]) ? table[i + 1][j + 1] + 1 : Math.max(table[i + 1][j], table[i][j + 1]);
    }
  }
  const pairs: [number, number][] = [];
  let i = 0;
  let j = 0;
  while (i < n && j < m) {
    if (signature(a[i]) === signature(b[j])) {
      pairs.push([i, j]);
      i++;
      j++;
    } else if (table[i + 1][j] >= table[i][j + 1]) i++;
    else j++;
  }
  return pairs;
}

function walkAll(node: EditorNode, tree: string, path: string, kind: 'added' | 'removed', out: DiffEntry[]) {
  const here = path ? `${path} › ${label(node)}` : label(node);
  out.push({ kind, tree, path: here, id: node.id, key: node.key, attributes: [] });
  for (const child of node.children) walkAll(child, tree, here, kind, out);
}

function diffNodes(a: EditorNode, b: EditorNode, tree: string, path: string, out: DiffEntry[]) {
  const here = path ? `${path} › ${label(b)}` : label(b);
  const changes = attributeChanges(a.attributes, b.attributes);
  if (changes.length) out.push({ kind: 'changed', tree, path: here, id: b.id, key: b.key, attributes: changes });
  const pairs = matchChildren(a.children, b.children);
  let i = 0;
  let j = 0;
  for (const [pi, pj] of [...pairs, [a.children.length, b.children.length] as [number, number]]) {
    for (; i < pi; i++) walkAll(a.children[i], tree, here, 'removed', out);
    for (; j < pj; j++) walkAll(b.children[j], tree, here, 'added', out);
    if (pi < a.children.length && pj < b.children.length) diffNodes(a.children[pi], b.children[pj], tree, here, out);
    i = pi + 1;
    j = pj + 1;
  }
}

/** What changed from `older` to `newer`, tree by tree (trees only in one of them: every node). */
export function diffPlans(older: EditorPlan, newer: EditorPlan): DiffEntry[] {
  const out: DiffEntry[] = [];
  for (const tree of newer.trees) {
    const before = older.trees.find((t) => t.id === tree.id);
    if (!tree.root) continue;
    if (!before?.root) walkAll(tree.root, tree.id, '', 'added', out);
    else if (signature(before.root) === signature(tree.root)) diffNodes(before.root, tree.root, tree.id, '', out);
    else {
      walkAll(before.root, tree.id, '', 'removed', out);
      walkAll(tree.root, tree.id, '', 'added', out);
    }
  }
  for (const tree of older.trees) {
    if (tree.root && !newer.trees.some((t) => t.id === tree.id)) walkAll(tree.root, tree.id, '', 'removed', out);
  }
  return out;
}

/** One line per entry, as the comparison lists them. */
export function describeEntry(entry: DiffEntry): string {
  const sign = entry.kind === 'added' ? '+' : entry.kind === 'removed' ? '−' : '~';
  const details = entry.attributes
    .map((c) => (c.from === undefined ? `${c.name}=${c.to}` : c.to === undefined ? `${c.name} (was ${c.from})` : `${c.name}: ${c.from} → ${c.to}`))
    .join(', ');
  return `${sign} ${entry.path}${details ? `: ${details}` : ''}`;
}
