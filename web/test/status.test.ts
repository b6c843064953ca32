import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import {
  applyTransition,
  mapRun,
  mapRunOnto,
  mergeStatuses,
  NodeStatus,
  RunNode,
  runningNode,
  statusesAt,
  statusesByKey,
  Transition,
  unchangedStatusesByKey,
} from '../src/model/status';

// A plan with a SubTree: main = Sequence(Open, SubTree grasp, Move); grasp = Fallback(Close, Open).
const plan = T.fromPlanJson({
  main_tree: 'main',
  trees: [
    {
      id: 'main',
      root: { id: 'Sequence', children: [{ id: 'Open' }, { id: 'SubTree', attributes: [['ID', 'grasp']] }, { id: 'Move' }] },
    },
    { id: 'grasp', root: { id: 'Fallback', children: [{ id: 'Close' }, { id: 'Open' }] } },
  ],
});
// The tree the server built: pre-order uids, the SubTree's child is the subtree's root.
const runNodes: RunNode[] = [
  { uid: 0, parent: -1, id: 'Sequence', name: '', path: 'main' },
  { uid: 1, parent: 0, id: 'Open', name: '', path: '' },
  { uid: 2, parent: 0, id: 'SubTree', name: '', path: '' },
  { uid: 3, parent: 2, id: 'Fallback', name: '', path: '' },
  { uid: 4, parent: 3, id: 'Close', name: '', path: '' },
  { uid: 5, parent: 3, id: 'Open', name: '', path: '' },
  { uid: 6, parent: 0, id: 'Move', name: '', path: '' },
];

describe('mapping a run onto the editor', () => {
  it('maps every uid, through the SubTree into its tree', () => {
    const mapping = mapRun(plan, runNodes);
    const main = T.findTree(plan, 'main')!.root!;
    const grasp = T.findTree(plan, 'grasp')!.root!;
    expect(mapping.size).toBe(7);
    expect(mapping.get(0)).toEqual({ tree: 'main', key: main.key });
    expect(mapping.get(6)).toEqual({ tree: 'main', key: main.children[2].key });
    expect(mapping.get(3)).toEqual({ tree: 'grasp', key: grasp.key });
    expect(mapping.get(5)).toEqual({ tree: 'grasp', key: grasp.children[1].key });
  });

  it('stops where the plan was edited since the run started', () => {
    const edited = T.setAttribute(plan, 'main', T.findTree(plan, 'main')!.root!.key, 'name', 'x');
    const changed: RunNode[] = runNodes.map((n) => (n.uid === 6 ? { ...n, id: 'Home' } : n));
    const mapping = mapRun(edited, changed);
    expect(mapping.has(6)).toBe(false);
    expect(mapping.has(5)).toBe(true);
  });
});

describe('statuses', () => {
  const transitions: Transition[] = [
    { seq: 1, t: 0, uid: 1, from: 'IDLE', to: 'SUCCESS' },
    { seq: 2, t: 0, uid: 4, from: 'IDLE', to: 'RUNNING' },
    { seq: 3, t: 0, uid: 3, from: 'IDLE', to: 'RUNNING' },
    { seq: 4, t: 0, uid: 0, from: 'IDLE', to: 'RUNNING' },
    { seq: 5, t: 1.5, uid: 4, from: 'RUNNING', to: 'FAILURE', reason: 'nothing to grasp', origin: 'main/grasp/Close[1]', data: { force: 0 } },
    { seq: 6, t: 1.5, uid: 5, from: 'IDLE', to: 'RUNNING' },
    { seq: 7, t: 2.0, uid: 5, from: 'RUNNING', to: 'IDLE' },
    { seq: 8, t: 2.0, uid: 0, from: 'RUNNING', to: 'IDLE' },
  ];

  it('replays to any point: last status, failure reason, halted nodes', () => {
    expect(statusesAt(transitions, 0).size).toBe(0);
    const at4 = statusesAt(transitions, 4);
    expect(at4.get(4)).toMatchObject({ status: 'RUNNING', last: 'RUNNING' });
    const at6 = statusesAt(transitions, 6);
    expect(at6.get(4)).toMatchObject({ status: 'FAILURE', last: 'FAILURE', reason: 'nothing to grasp', data: { force: 0 } });
    const end = statusesAt(transitions, transitions.length);
    expect(end.get(5)).toMatchObject({ status: 'IDLE', last: 'HALTED' });
    expect(end.get(1)).toMatchObject({ status: 'SUCCESS', last: 'SUCCESS' });
    expect(statusesAt(transitions, 1000).size).toBe(statusesAt(transitions, transitions.length).size);
  });

  it('keeps the last status when a parent resets a completed child', () => {
    const statuses = new Map<number, NodeStatus>();
    applyTransition(statuses, { seq: 1, t: 0, uid: 1, from: 'IDLE', to: 'SUCCESS' });
    applyTransition(statuses, { seq: 2, t: 0, uid: 1, from: 'SUCCESS', to: 'IDLE' });
    expect(statuses.get(1)).toMatchObject({ status: 'IDLE', last: 'SUCCESS' });
    applyTransition(statuses, { seq: 3, t: 0, uid: 1, from: 'IDLE', to: 'FAILURE', reason: 'r' });
    applyTransition(statuses, { seq: 4, t: 0, uid: 1, from: 'FAILURE', to: 'IDLE' });
    applyTransition(statuses, { seq: 5, t: 0, uid: 1, from: 'IDLE', to: 'RUNNING' });
    expect(statuses.get(1)!.reason).toBeUndefined();
  });

  it('gives each editor node of a tree its status, and merges live updates', () => {
    const mapping = mapRun(plan, runNodes);
    const statuses = statusesAt(transitions, 6);
    const grasp = T.findTree(plan, 'grasp')!.root!;
    const byKey = statusesByKey(statuses, mapping, 'grasp');
    expect(byKey.get(grasp.children[0].key)?.last).toBe('FAILURE');
    expect(byKey.has(T.findTree(plan, 'main')!.root!.key)).toBe(false);
    const merged = mergeStatuses(statuses, [{ uid: 6, status: 'SUCCESS', last: 'SUCCESS' }]);
    expect(merged.get(6)?.last).toBe('SUCCESS');
    expect(statuses.has(6)).toBe(false);
  });
});

describe("the cell's run on the plan open in the editor", () => {
  const all = (status: NodeStatus['status']) => new Map(runNodes.map((n) => [n.uid, { uid: n.uid, status, last: status } as NodeStatus]));

  it('clears the badge of a node edited since the run (and of its parent when a child is added), not the others', () => {
    const mapping = mapRunOnto(plan, runNodes, plan);
    const main = T.findTree(plan, 'main')!.root!;
    const before = unchangedStatusesByKey(all('SUCCESS'), mapping, plan, 'main');
    expect(before.size).toBe(4); // Sequence, Open, SubTree, Move
    const moved = T.setAttribute(plan, 'main', main.children[2].key, 'waypoint', 'above_pick');
    const after = unchangedStatusesByKey(all('SUCCESS'), mapping, moved, 'main');
    expect(after.has(main.children[2].key)).toBe(false);
    expect(after.has(main.children[0].key)).toBe(true);
    expect(after.has(main.key)).toBe(true);
    const added = T.addChild(plan, 'main', main.key, T.makeNode('Home'), () => 'Control');
    const withChild = unchangedStatusesByKey(all('SUCCESS'), mapping, added, 'main');
    expect(withChild.has(main.key)).toBe(false);
    expect(withChild.has(main.children[1].key)).toBe(true);
  });

  it("maps only the nodes that are still what ran (the run's own plan says what that was)", () => {
    const main = T.findTree(plan, 'main')!.root!;
    // The plan open here has Move with a waypoint the run did not have.
    const open = T.setAttribute(plan, 'main', main.children[2].key, 'waypoint', 'pick');
    const mapping = mapRunOnto(open, runNodes, plan);
    expect(mapping.has(6)).toBe(false);
    expect(mapping.has(1)).toBe(true);
    expect(mapping.get(5)?.tree).toBe('grasp');
  });

  it('names the node that runs now: the deepest one RUNNING', () => {
    const statuses = new Map<number, NodeStatus>([
      [0, { uid: 0, status: 'RUNNING', last: 'RUNNING' }],
      [2, { uid: 2, status: 'RUNNING', last: 'RUNNING' }],
      [3, { uid: 3, status: 'RUNNING', last: 'RUNNING' }],
      [4, { uid: 4, status: 'RUNNING', last: 'RUNNING' }],
      [1, { uid: 1, status: 'SUCCESS', last: 'SUCCESS' }],
    ]);
    expect(runningNode(statuses, runNodes)?.uid).toBe(4);
    expect(runningNode(new Map(), runNodes)).toBeUndefined();
  });
});
