import { describe, expect, it } from 'vitest';
import { formatPredicates, parsePredicates, referenceChoices } from '../src/model/predicates';

describe("SmartMove's predicate list", () => {
  it('parses and formats the list SmartMove reads', () => {
    const terms = parsePredicates('right_of(table_center); near( node_1 , x ) ;gripper_open');
    expect(terms).toEqual([
      { name: 'right_of', args: ['table_center'] },
      { name: 'near', args: ['node_1', 'x'] },
      { name: 'gripper_open', args: [] },
    ]);
    expect(formatPredicates(terms)).toBe('right_of(table_center); near(node_1,x); gripper_open()');
    expect(parsePredicates('')).toEqual([]);
    expect(formatPredicates([])).toBe('');
  });
});

describe("a condition's reference list", () => {
  it('offers what the cell knows now, and marks a part the cell no longer has', () => {
    const references = ['table_center', 'world', 'node_1'];
    expect(referenceChoices('node_1', references).map((r) => r.label)).toEqual(['table_center', 'world', 'node_1']);
    const gone = referenceChoices('node_7', references);
    expect(gone[0]).toEqual({ value: 'node_7', label: 'node_7 (not in the cell now)', known: false });
    expect(gone.slice(1).map((r) => r.value)).toEqual(references);
  });
});
