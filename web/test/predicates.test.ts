import { describe, expect, it } from 'vitest';
import { formatPredicates, parsePredicates } from '../src/model/predicates';

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
