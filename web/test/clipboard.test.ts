import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import type { NodeKind } from '../src/model/tree';

const KINDS: Record<string, NodeKind> = { Sequence: 'Control', Inverter: 'Decorator', Open: 'Action', Home: 'Action', Move: 'Action' };
const kindOf = (id: string) => KINDS[id];
const ids = (plan: T.EditorPlan) => T.findTree(plan, 'main')!.root!.children.map((n) => n.id + (T.attribute(n, 'waypoint') ?? ''));

function flat(...types: string[]) {
  let plan = T.emptyPlan();
  const root = T.findTree(plan, 'main')!.root!.key;
  const nodes = types.map((t) => T.makeNode(t.replace(/\d+$/, ''), /\d$/.test(t) ? [['waypoint', t.slice(-1)]] : []));
  plan = T.insertAt(plan, 'main', root, nodes, kindOf);
  return { plan, nodes, root };
}

describe('inserting where the selection is', () => {
  it('adds inside a selected Sequence, after a selected action', () => {
    const { plan, nodes, root } = flat('Open', 'Home');
    expect(ids(plan)).toEqual(['Open', 'Home']);
    const afterOpen = T.insertAt(plan, 'main', nodes[0].key, [T.makeNode('Move')], kindOf);
    expect(ids(afterOpen)).toEqual(['Open', 'Move', 'Home']);
    const inRoot = T.insertAt(plan, 'main', root, [T.makeNode('Move')], kindOf);
    expect(ids(inRoot)).toEqual(['Open', 'Home', 'Move']);
  });

  it('refuses two nodes under a decorator and a second root', () => {
    let { plan, nodes } = flat('Open');
    const inverter = T.makeNode('Inverter');
    plan = T.insertAt(plan, 'main', nodes[0].key, [inverter], kindOf);
    expect(() => T.insertAt(plan, 'main', inverter.key, [T.makeNode('Open'), T.makeNode('Home')], kindOf)).toThrow(/exactly one/);
    const empty: T.EditorPlan = { mainTree: 'main', trees: [{ id: 'main', root: null }] };
    expect(() => T.insertAt(empty, 'main', null, [T.makeNode('Open'), T.makeNode('Home')], kindOf)).toThrow(/one root/);
  });
});

describe('copy, cut and paste', () => {
  it('copies a range of siblings and pastes fresh copies after the selection', () => {
    const { plan, nodes } = flat('Open', 'Move1', 'Move2', 'Home');
    const root = T.findTree(plan, 'main')!.root;
    const range = T.siblingRange(root, nodes[1].key, nodes[2].key);
    expect(range).toEqual([nodes[1].key, nodes[2].key]);
    const copied = T.topmostSelected(root, range).map(T.cloneNode);
    const pasted = T.insertAt(plan, 'main', nodes[3].key, copied, kindOf);
    expect(ids(pasted)).toEqual(['Open', 'Move1', 'Move2', 'Home', 'Move1', 'Move2']);
    const keys = T.findTree(pasted, 'main')!.root!.children.map((n) => n.key);
    expect(new Set(keys).size).toBe(keys.length); // fresh keys: each copy is its own node
  });

  it('cuts the topmost selected nodes but never the root', () => {
    const { plan, nodes, root } = flat('Open', 'Move1', 'Home');
    expect(ids(T.removeNodes(plan, 'main', [nodes[0].key, nodes[2].key]))).toEqual(['Move1']);
    expect(() => T.removeNodes(plan, 'main', [root])).toThrow(/root/);
    // A node inside a selected node is not copied twice.
    expect(T.topmostSelected(T.findTree(plan, 'main')!.root, [root, nodes[1].key]).map((n) => n.id)).toEqual(['Sequence']);
  });

  it('shift-select across different parents selects only the clicked node', () => {
    const { plan, nodes, root } = flat('Open', 'Home');
    expect(T.siblingRange(T.findTree(plan, 'main')!.root, root, nodes[1].key)).toEqual([nodes[1].key]);
  });
});

describe('keyboard navigation', () => {
  it('goes to the parent, the first child and the siblings', () => {
    const { plan, nodes, root } = flat('Open', 'Home');
    const tree = T.findTree(plan, 'main')!.root;
    expect(T.neighbour(tree, root, 'child')).toBe(nodes[0].key);
    expect(T.neighbour(tree, nodes[0].key, 'next')).toBe(nodes[1].key);
    expect(T.neighbour(tree, nodes[1].key, 'next')).toBeNull();
    expect(T.neighbour(tree, nodes[1].key, 'previous')).toBe(nodes[0].key);
    expect(T.neighbour(tree, nodes[1].key, 'parent')).toBe(root);
  });
});
