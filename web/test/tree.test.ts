import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import type { NodeKind } from '../src/model/tree';

const KINDS: Record<string, NodeKind> = {
  Sequence: 'Control',
  Fallback: 'Control',
  Repeat: 'Decorator',
  Inverter: 'Decorator',
  Open: 'Action',
  Close: 'Action',
  Move: 'Action',
  CheckPredicate: 'Condition',
  SubTree: 'SubTree',
};
const kindOf = (id: string) => KINDS[id];

function ids(node: T.EditorNode | null): unknown {
  if (!node) return null;
  return node.children.length ? [node.id, node.children.map(ids)] : node.id;
}
const mainIds = (plan: T.EditorPlan) => ids(T.findTree(plan, 'main')!.root);
const rootKey = (plan: T.EditorPlan) => T.findTree(plan, 'main')!.root!.key;

describe('editing the tree', () => {
  it('builds the pick-up plan by adding children and siblings', () => {
    let plan = T.emptyPlan();
    const open = T.makeNode('Open');
    plan = T.addChild(plan, 'main', rootKey(plan), open, kindOf);
    const move = T.makeNode('Move', [['waypoint', 'above_pick']]);
    plan = T.addSibling(plan, 'main', open.key, move, kindOf);
    const close = T.makeNode('Close');
    plan = T.addSibling(plan, 'main', move.key, close, kindOf);
    plan = T.addChild(plan, 'main', null, T.makeNode('Move', [['waypoint', 'above_pick']]), kindOf);
    expect(mainIds(plan)).toEqual(['Sequence', ['Open', 'Move', 'Close', 'Move']]);
  });

  it('keeps the old plan unchanged (immutable edits)', () => {
    const before = T.emptyPlan();
    const after = T.addChild(before, 'main', rootKey(before), T.makeNode('Open'), kindOf);
    expect(mainIds(before)).toEqual('Sequence');
    expect(mainIds(after)).toEqual(['Sequence', ['Open']]);
  });

  it('refuses children where the node type takes none, and a second child of a decorator', () => {
    let plan = T.emptyPlan();
    const open = T.makeNode('Open');
    plan = T.addChild(plan, 'main', rootKey(plan), open, kindOf);
    expect(() => T.addChild(plan, 'main', open.key, T.makeNode('Close'), kindOf)).toThrow(/takes no children/);
    const repeat = T.makeNode('Repeat', [['num_cycles', '3']]);
    plan = T.addChild(plan, 'main', rootKey(plan), repeat, kindOf);
    plan = T.addChild(plan, 'main', repeat.key, T.makeNode('Close'), kindOf);
    expect(() => T.addChild(plan, 'main', repeat.key, T.makeNode('Open'), kindOf)).toThrow(/exactly one child/);
    expect(() => T.addSibling(plan, 'main', rootKey(plan), T.makeNode('Open'), kindOf)).toThrow(/root has no siblings/);
  });

  it('removes a node with its subtree', () => {
    let plan = T.emptyPlan();
    const fallback = T.makeNode('Fallback', [], [T.makeNode('Open'), T.makeNode('Close')]);
    plan = T.addChild(plan, 'main', rootKey(plan), fallback, kindOf);
    plan = T.addChild(plan, 'main', rootKey(plan), T.makeNode('Move'), kindOf);
    plan = T.removeNode(plan, 'main', fallback.key);
    expect(mainIds(plan)).toEqual(['Sequence', ['Move']]);
    plan = T.removeNode(plan, 'main', rootKey(plan));
    expect(T.findTree(plan, 'main')!.root).toBeNull();
    expect(() => T.toPlanJson(plan)).toThrow(/empty/);
  });

  it('moves nodes before, after and inside others (drag and drop)', () => {
    let plan = T.emptyPlan();
    const a = T.makeNode('Open');
    const b = T.makeNode('Close');
    const c = T.makeNode('Move');
    const f = T.makeNode('Fallback');
    for (const n of [a, b, c, f]) plan = T.addChild(plan, 'main', rootKey(plan), n, kindOf);
    plan = T.moveNode(plan, 'main', c.key, a.key, 'before', kindOf);
    expect(mainIds(plan)).toEqual(['Sequence', ['Move', 'Open', 'Close', 'Fallback']]);
    plan = T.moveNode(plan, 'main', c.key, b.key, 'after', kindOf);
    expect(mainIds(plan)).toEqual(['Sequence', ['Open', 'Close', 'Move', 'Fallback']]);
    plan = T.moveNode(plan, 'main', a.key, f.key, 'inside', kindOf);
    expect(mainIds(plan)).toEqual(['Sequence', ['Close', 'Move', ['Fallback', ['Open']]]]);
    plan = T.moveNode(plan, 'main', a.key, c.key, 'before', kindOf);
    expect(mainIds(plan)).toEqual(['Sequence', ['Close', 'Open', 'Move', 'Fallback']]);
    expect(() => T.moveNode(plan, 'main', rootKey(plan), f.key, 'inside', kindOf)).toThrow(/own subtree/);
    expect(() => T.moveNode(plan, 'main', a.key, c.key, 'inside', kindOf)).toThrow(/cannot take another child/);
    expect(() => T.moveNode(plan, 'main', a.key, rootKey(plan), 'before', kindOf)).toThrow(/beside the root/);
  });

  it('shifts a node among its siblings', () => {
    let plan = T.emptyPlan();
    const a = T.makeNode('Open');
    const b = T.makeNode('Close');
    plan = T.addChild(plan, 'main', rootKey(plan), a, kindOf);
    plan = T.addChild(plan, 'main', rootKey(plan), b, kindOf);
    plan = T.shiftNode(plan, 'main', b.key, -1);
    expect(mainIds(plan)).toEqual(['Sequence', ['Close', 'Open']]);
    expect(T.shiftNode(plan, 'main', b.key, -1)).toBe(plan);
  });

  it('sets attributes in order, puts the name first, removes empty ones', () => {
    let plan = T.emptyPlan();
    const move = T.makeNode('Move');
    plan = T.addChild(plan, 'main', rootKey(plan), move, kindOf);
    plan = T.setAttribute(plan, 'main', move.key, 'waypoint', 'pick');
    plan = T.setAttribute(plan, 'main', move.key, 'speed', '0.2');
    plan = T.setAttribute(plan, 'main', move.key, 'name', 'down');
    expect(T.locate(T.findTree(plan, 'main')!.root, move.key)!.node.attributes).toEqual([
      ['name', 'down'],
      ['waypoint', 'pick'],
      ['speed', '0.2'],
    ]);
    plan = T.setAttribute(plan, 'main', move.key, 'speed', undefined);
    plan = T.setAttribute(plan, 'main', move.key, 'waypoint', 'above_pick');
    expect(T.locate(T.findTree(plan, 'main')!.root, move.key)!.node.attributes).toEqual([
      ['name', 'down'],
      ['waypoint', 'above_pick'],
    ]);
  });

  it('folds a subtree without changing the saved plan', () => {
    let plan = T.emptyPlan();
    plan = T.addChild(plan, 'main', rootKey(plan), T.makeNode('Open'), kindOf);
    const folded = T.toggleCollapsed(plan, 'main', rootKey(plan));
    expect(T.findTree(folded, 'main')!.root!.collapsed).toBe(true);
    expect(T.samePlan(plan, folded)).toBe(true);
  });

  it('finds the node a diagnostic points at', () => {
    const plan = T.fromPlanJson({
      main_tree: 'main',
      trees: [{ id: 'main', root: { id: 'Sequence', children: [{ id: 'Open' }, { id: 'Fallback', children: [{ id: 'Close' }] }] } }],
    });
    expect(T.nodeAtPath(T.findTree(plan, 'main')!.root, [1, 0])!.id).toBe('Close');
    expect(T.nodeAtPath(T.findTree(plan, 'main')!.root, [5])).toBeUndefined();
  });
});

describe('plan JSON (what the server turns into XML)', () => {
  const json: T.PlanJson = {
    main_tree: 'main',
    trees: [
      {
        id: 'main',
        root: {
          id: 'Sequence',
          attributes: [['name', 'pick & place <1>']],
          children: [
            { id: 'Open', attributes: [], children: [] },
            { id: 'SubTree', attributes: [['ID', 'grasp']], children: [] },
          ],
        },
      },
      { id: 'grasp', root: { id: 'Close', attributes: [['speed', '0.05']], children: [] } },
    ],
  };

  it('round-trips exactly, attribute order included', () => {
    expect(T.toPlanJson(T.fromPlanJson(json))).toEqual(json);
  });

  it('copies a subtree with fresh keys', () => {
    const plan = T.fromPlanJson(json);
    const root = T.findTree(plan, 'main')!.root!;
    const copy = T.cloneNode(root);
    expect(copy.key).not.toBe(root.key);
    expect(copy.children[0].key).not.toBe(root.children[0].key);
    expect(T.nodeToJson(copy)).toEqual(T.nodeToJson(root));
  });

  it('adds and removes trees of the file (saved subtrees used by SubTree)', () => {
    let plan = T.emptyPlan();
    plan = T.putTree(plan, { id: 'grasp', root: T.makeNode('Close') });
    expect(plan.trees.map((t) => t.id)).toEqual(['main', 'grasp']);
    plan = T.putTree(plan, { id: 'grasp', root: T.makeNode('Open') });
    expect(plan.trees.length).toBe(2);
    expect(T.findTree(plan, 'grasp')!.root!.id).toBe('Open');
    expect(() => T.removeTree(plan, 'main')).toThrow();
    expect(T.removeTree(plan, 'grasp').trees.length).toBe(1);
  });
});

describe('a node along a path', () => {
  it('goes to each waypoint of the path in turn, its other parameters copied, after it in order', () => {
    let plan = T.emptyPlan();
    const move = T.makeNode('Move', [['waypoint', 'wire_grip'], ['speed', '0.15']]);
    plan = T.addChild(plan, 'main', rootKey(plan), move, kindOf);
    plan = T.addChild(plan, 'main', rootKey(plan), T.makeNode('Open'), kindOf);
    const done = T.alongPath(plan, 'main', move.key, 'waypoint', ['bend_b_10', 'bend_b_20', 'bend_b_over'], kindOf);
    const children = T.findTree(done.plan, 'main')!.root!.children;
    expect(children.map((c) => `${c.id} ${c.attributes.map(([k, v]) => `${k}=${v}`).join(' ')}`)).toEqual([
      'Move waypoint=bend_b_10 speed=0.15',
      'Move waypoint=bend_b_20 speed=0.15',
      'Move waypoint=bend_b_over speed=0.15',
      'Open ',
    ]);
    expect(new Set(children.map((c) => c.key)).size).toBe(4);
    expect(done.last).toBe(children[2].key);
  });
});
