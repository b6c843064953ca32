import { describe, expect, it } from 'vitest';
import { groupCandidates, type Candidate } from '../src/components/ObjectsPane';

const c = (object: string, cost: number | undefined, rejected?: string, chosen = false): Candidate => ({
  object, symmetry: 0, goal: [0, 0, 0], cost, rejected, chosen,
});

describe("SmartMove's candidates", () => {
  it('lists the chosen one first, the feasible ones by cost, and groups the rejected by reason', () => {
    const { feasible, rejected } = groupCandidates([
      c('node_3', 0.9), c('node_1', undefined, 'not checked'), c('node_2', 0.4, undefined, true), c('node_4', 0.2),
      c('node_5', undefined, 'not checked'), c('link_1', undefined, 'no collision-free configuration'),
    ]);
    expect(feasible.map((x) => x.object)).toEqual(['node_2', 'node_4', 'node_3']);
    expect(rejected.map((g) => [g.reason, g.candidates.length])).toEqual([
      ['not checked', 2],
      ['no collision-free configuration', 1],
    ]);
  });
});
