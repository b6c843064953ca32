import { describe, expect, it } from 'vitest';
import type { NodeInfo, PortInfo } from '../src/api';
import { boundProblem, boundText, rangeProblem, rangeProblems, rangeText, toPlan, toShown, unitOf } from '../src/model/units';
import { argumentKinds, argumentWords, waypointPaths } from '../src/model/paths';
import { forceReadout } from '../src/model/forceReadout';
import type { CellState } from '../src/api';

// The ports as GET /api/nodes lists them on iiwa-3f-sim (recorded from costar serve).
const speed: PortInfo = { name: 'speed', type: 'double', description: 'how fast the tool follows the path (m/s)', default: '0.03', min: 0.005, max: 0.2 };
const force: PortInfo = { name: 'force', type: 'double', description: 'the force (N) the tool presses with, along its axis', default: '10', min: 1, max: 60 };
const approach: PortInfo = { name: 'approach', type: 'double', description: "the tool comes down from this far above the path's start (m)", default: '0.05', min: 0.01, max: 0.2 };
const toolSpeed: PortInfo = { name: 'speed', type: 'double', description: 'how fast it runs (opm, orbital palm sander / polisher)', default: '10000', min: 4000, max: 12000 };
const fraction: PortInfo = { name: 'speed', type: 'double', description: "fraction of the arm's top speed and acceleration", default: '0.5', min: 0.01, max: 1 };
const joint: PortInfo = { name: 'joint', type: 'int', description: 'the joint, 1 to 7', min: 1, max: 7 };

describe('numbers in the units a technician states them in', () => {
  it('reads the unit its description names, and shows lengths and speeds in mm and mm/s', () => {
    expect(unitOf(speed)).toEqual({ plan: 'm/s', shown: 'mm/s', scale: 1000 });
    expect(unitOf(approach)?.shown).toBe('mm');
    expect(unitOf(force)?.shown).toBe('N');
    expect(unitOf(toolSpeed)?.shown).toBe('per minute');
    expect(unitOf(fraction)).toBeNull();
    expect(toShown(unitOf(speed), '0.03')).toBe('30');
    expect(toPlan(unitOf(speed), '30')).toBe('0.03');
    expect(toPlan(unitOf(approach), '7.5')).toBe('0.0075');
    expect(toShown(unitOf(force), '10')).toBe('10');
    expect(toPlan(unitOf(speed), '')).toBeUndefined();
  });

  it('shows the range in the shown unit and refuses a value outside it with the reason', () => {
    expect(rangeText(speed)).toBe('from 5 to 200 mm/s');
    expect(rangeText(force)).toBe('from 1 to 60 N');
    expect(rangeProblem(force, '80')).toBe('force 80 N is out of range: from 1 to 60 N');
    expect(rangeProblem(speed, '0.3')).toBe('speed 300 mm/s is out of range: from 5 to 200 mm/s');
    expect(rangeProblem(force, '60')).toBeNull();
    expect(rangeProblem(force, undefined)).toBeNull();
    expect(rangeProblem(force, 'abc')).toBe("force: 'abc' is not a number");
    expect(rangeProblem(joint, '2.5')).toBe('joint: 2.5 is not a whole number');
    expect(rangeProblem(joint, '9')).toBe('joint 9 is out of range: from 1 to 7');
  });

  it('finds every node of the plan with a number out of range', () => {
    const press: NodeInfo = { id: 'PressAndFollow', kind: 'Action', category: 'robot_action', description: '', asynchronous: true, ports: [force, speed] };
    const leaf = (key: string, attributes: [string, string][]) => ({ key, id: 'PressAndFollow', attributes, children: [], collapsed: false });
    const root = { key: 'r', id: 'Sequence', attributes: [], collapsed: false, children: [leaf('a', [['force', '10']]), leaf('b', [['force', '70'], ['speed', '1']])] };
    const found = rangeProblems(root as never, (id) => (id === 'PressAndFollow' ? press : undefined));
    expect(found).toEqual([{ key: 'b', id: 'PressAndFollow', message: 'force 70 N is out of range: from 1 to 60 N' }]);
  });
});

describe('a number that must stay below another of its node (less_than)', () => {
  // MoveUntilContact's force and max_force as GET /api/nodes lists them (server/palette.cpp: less_than).
  const pressing: PortInfo = { ...force, default: '5', less_than: 'max_force' };
  const maxForce: PortInfo = { name: 'max_force', type: 'double', description: 'the force (N) that stops the motion', default: '40', min: 5, max: 150 };
  const ports = [pressing, maxForce];

  it('names the bound next to the field, with the value the node has now or its default', () => {
    expect(boundText(pressing, ports, [])).toBe('below max_force (40 N)');
    expect(boundText(pressing, ports, [['max_force', '25']])).toBe('below max_force (25 N)');
    expect(boundText(maxForce, ports, [])).toBe('');
    expect(boundText(force, ports, [])).toBe('');
  });

  it('refuses a force at or above max_force, whether max_force is written or its default', () => {
    expect(boundProblem(pressing, ports, [['force', '40']])).toBe('force 40 N must be below max_force (40 N)');
    expect(boundProblem(pressing, ports, [['force', '30'], ['max_force', '20']])).toBe('force 30 N must be below max_force (20 N)');
    expect(boundProblem(pressing, ports, [['force', '39.9']])).toBeNull();
    expect(boundProblem(pressing, ports, [])).toBeNull(); // 5 N below 40 N by default
    expect(boundProblem(pressing, ports, [['force', 'abc']])).toBeNull(); // the range check names that
  });

  it('refuses the plan before Run: rangeProblems lists the node', () => {
    const contact: NodeInfo = { id: 'MoveUntilContact', kind: 'Action', category: 'robot_action', description: '', asynchronous: true, ports };
    const leaf = (key: string, attributes: [string, string][]) => ({ key, id: 'MoveUntilContact', attributes, children: [], collapsed: false });
    const root = { key: 'r', id: 'Sequence', attributes: [], collapsed: false, children: [leaf('a', [['force', '10']]), leaf('b', [['force', '50'], ['max_force', '45']])] };
    const found = rangeProblems(root as never, (id) => (id === 'MoveUntilContact' ? contact : undefined));
    expect(found).toEqual([{ key: 'b', id: 'MoveUntilContact', message: 'force 50 N must be below max_force (45 N)' }]);
  });
});

describe('paths taught as one', () => {
  it('groups waypoints sharing a prefix, in path order', () => {
    const polishing = ['ready', 'row1_end', 'row1_start', 'row2_end', 'row2_start'];
    expect(waypointPaths(polishing)).toEqual([
      { prefix: 'row1_', waypoints: ['row1_start', 'row1_end'] },
      { prefix: 'row2_', waypoints: ['row2_start', 'row2_end'] },
    ]);
    const wire = ['bend_b_done', 'bend_b_10', 'bend_b_over', 'bend_b_90', 'bend_b_20', 'wire_grip'];
    expect(waypointPaths(wire)).toEqual([{ prefix: 'bend_b_', waypoints: ['bend_b_10', 'bend_b_20', 'bend_b_90', 'bend_b_over', 'bend_b_done'] }]);
    expect(waypointPaths(['home', 'above_pick', 'pick'])).toEqual([]);
  });

  it("reads a predicate's argument kinds from its signature", () => {
    expect(argumentKinds("force_above(N): the wrist sensor's force is above N newtons", 1)).toEqual(['number']);
    expect(argumentKinds('pressed_at(w): a PressAndFollow pressed the tool through waypoint w', 1)).toEqual(['waypoint']);
    expect(argumentKinds('left_of(a, b): see docs/PREDICATES.md', 2)).toEqual(['reference', 'reference']);
    expect(argumentKinds('the tool is on', 0)).toEqual([]);
    // The hand's predicates quote the words they take: the editor offers them to choose.
    expect(argumentWords("gesture('hand_1', 'offer'): the open palm up held still", 2)).toEqual([['hand_1'], ['offer']]);
    expect(argumentWords("in_zone('hand_1', 'handover'|'bench'): the hand's centre lies in the named zone", 2)).toEqual([['hand_1'], ['handover', 'bench']]);
    expect(argumentWords('left_of(a, b): see docs/PREDICATES.md', 2)).toEqual([null, null]);
    expect(argumentWords("in_zone('hand_1', zone|'x'): mixed", 2)).toEqual([['hand_1'], null]);
  });
});

describe('the force and tool strip', () => {
  const base = { type: 'state', t: 0, run: 0, mode: 'running', gripper: { open: false, closed: false, holding: true }, objects: [], waypoints: [], frames: [], predicates: [] };
  it('shows the force, along the tool, and the tool', () => {
    const state = {
      ...base,
      arm: { wrench: { frame: 'tool', force: [3, 4, 12], torque: [0, 0, 0] }, in_contact: true },
      tool: { speed: 9984.2, unit: 'opm', on: true, at_speed: true, held: true, docked: false },
    } as unknown as CellState;
    const readout = forceReadout(state);
    expect(readout.magnitude).toBeCloseTo(13);
    expect(readout.along).toBe(12);
    expect(readout.inContact).toBe(true);
    expect(readout.tool).toBe('tool on, 9984 per minute, in the gripper');
  });
  it('says when the tool stops or is not in position, and nothing on a cell without either', () => {
    const stopping = { ...base, arm: {}, tool: { speed: 3000, unit: 'opm', on: false, at_speed: false, held: false, docked: false } } as unknown as CellState;
    expect(forceReadout(stopping).tool).toBe('tool off, 3000 per minute (stopping), not in position');
    expect(forceReadout(stopping).magnitude).toBeNull();
    const none = forceReadout({ ...base, arm: {} } as unknown as CellState);
    expect(none.magnitude === null && none.tool === null).toBe(true);
  });
});
