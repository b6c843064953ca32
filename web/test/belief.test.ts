import { describe, expect, it } from 'vitest';
import type { CellState } from '../src/api';
import { believe, emptyBelief, whereFrom } from '../src/model/belief';

const I: [number, number, number, number] = [0, 0, 0, 1];
function snapshot(tool: [number, number, number], holding: boolean, part: [number, number, number] = [0.5, 0.2, 0.02]): CellState {
  return {
    type: 'state', t: 0, run: 0, mode: 'idle',
    arm: { endpoint: { p: tool, q: I } },
    gripper: { open: !holding, closed: holding, holding },
    objects: [{ name: 'node_1', class: 'node', p: part, q: I }],
    waypoints: [], frames: [],
    predicates: holding ? ['holding(node_1)', 'gripper_holding()'] : [],
  };
}

describe('the world the system believes', () => {
  it('moves a held part with the tool and leaves it where it was put', () => {
    let belief = emptyBelief();
    // Grasped: the tool is 2 cm above the part's centre.
    expect(whereFrom(believe(belief, snapshot([0.5, 0.2, 0.3], false)), 'node_1')).toBe('detected');
    let step = believe(belief, snapshot([0.5, 0.2, 0.04], true));
    expect(step.poses.get('node_1')!.p).toEqual([0.5, 0.2, 0.02]);
    expect(whereFrom(step, 'node_1')).toBe('held');
    belief = step.belief;
    step = believe(belief, snapshot([0.3, -0.1, 0.2], true));
    step.poses.get('node_1')!.p.forEach((v, i) => expect(v).toBeCloseTo([0.3, -0.1, 0.18][i], 9));
    belief = step.belief;
    // Released there: the stale detection (still at the start) does not pull it back.
    step = believe(belief, snapshot([0.3, -0.1, 0.2], false));
    step.poses.get('node_1')!.p.forEach((v, i) => expect(v).toBeCloseTo([0.3, -0.1, 0.18][i], 9));
    step = believe(step.belief, snapshot([0.4, 0, 0.3], false));
    step.poses.get('node_1')!.p.forEach((v, i) => expect(v).toBeCloseTo([0.3, -0.1, 0.18][i], 9));
    expect(whereFrom(step, 'node_1')).toBe('put down');
    // A new detection wins.
    step = believe(step.belief, snapshot([0.4, 0, 0.3], false, [0.3, -0.1, 0.02]));
    expect(step.poses.get('node_1')!.p).toEqual([0.3, -0.1, 0.02]);
    expect(whereFrom(step, 'node_1')).toBe('detected');
  });

  it('puts a part down where it was last held, though the first snapshot without the hold comes after the tool retreated', () => {
    let belief = believe(emptyBelief(), snapshot([0.5, 0.2, 0.04], true)).belief;
    belief = believe(belief, snapshot([0.3, -0.1, 0.2], true)).belief; // held above the place, at rest
    // Sparse snapshots (a loaded machine): the next one is after the fingers opened and the tool
    // rose 8 cm; the part stays where the tool let it go.
    const step = believe(belief, snapshot([0.3, -0.1, 0.28], false));
    step.poses.get('node_1')!.p.forEach((v, i) => expect(v).toBeCloseTo([0.3, -0.1, 0.18][i], 9));
    expect(whereFrom(step, 'node_1')).toBe('put down');
  });

  it('takes the grasp where the tool was nearest the part, though the first snapshot with the hold comes after the lift began', () => {
    let belief = believe(emptyBelief(), snapshot([0.5, 0.2, 0.04], false)).belief; // closing on the part
    // Sparse snapshots: the next one is held, with the tool already 10 cm up.
    const step = believe(belief, snapshot([0.5, 0.2, 0.14], true));
    step.poses.get('node_1')!.p.forEach((v, i) => expect(v).toBeCloseTo([0.5, 0.2, 0.12][i], 9));
    belief = step.belief;
    expect(whereFrom(step, 'node_1')).toBe('held');
  });
});
