import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import { describeEntry, diffPlans } from '../src/model/diff';

const plan = (children: T.PlanNodeJson[]) => T.fromPlanJson({ main_tree: 'main', trees: [{ id: 'main', root: { id: 'Sequence', children } }] });

describe('comparing two versions of a plan', () => {
  it('finds a node added in the middle without marking the ones after it changed', () => {
    const older = plan([{ id: 'Open' }, { id: 'Home' }, { id: 'Close' }]);
    const newer = plan([{ id: 'Open' }, { id: 'DetectObjects' }, { id: 'Home' }, { id: 'Close' }]);
    const entries = diffPlans(older, newer);
    expect(entries).toHaveLength(1);
    expect(entries[0]).toMatchObject({ kind: 'added', id: 'DetectObjects', tree: 'main' });
    expect(entries[0].key).toBe(newer.trees[0].root!.children[1].key);
  });

  it('names changed attributes with their old and new values, and removed nodes', () => {
    const older = plan([{ id: 'Move', attributes: [['waypoint', 'over_left']] }, { id: 'Close' }, { id: 'Home', attributes: [['name', 'park']] }]);
    const newer = plan([{ id: 'Move', attributes: [['waypoint', 'above_left'], ['speed', '0.5']] }, { id: 'Close' }]);
    const entries = diffPlans(older, newer);
    expect(entries.map((e) => e.kind).sort()).toEqual(['changed', 'removed']);
    const changed = entries.find((e) => e.kind === 'changed')!;
    expect(changed.attributes).toEqual([
      { name: 'waypoint', from: 'over_left', to: 'above_left' },
      { name: 'speed', to: '0.5' },
    ]);
    expect(describeEntry(changed)).toBe('~ Sequence › Move: waypoint: over_left → above_left, speed=0.5');
    const removed = entries.find((e) => e.kind === 'removed')!;
    expect(describeEntry(removed)).toBe('− Sequence › Home “park”');
  });

  it('lists every node of a subtree that was added, and nothing for the same plan', () => {
    const older = plan([{ id: 'Open' }]);
    const newer = plan([{ id: 'Open' }, { id: 'Repeat', attributes: [['num_cycles', '2']], children: [{ id: 'Home' }] }]);
    expect(diffPlans(older, newer).map((e) => `${e.kind} ${e.id}`)).toEqual(['added Repeat', 'added Home']);
    expect(diffPlans(newer, newer)).toEqual([]);
  });
});
