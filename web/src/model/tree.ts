// The editor's model of a task plan: the trees of one BehaviorTree.CPP v4 file, edited as
// immutable values (every edit returns a new plan, so undo/redo keeps old ones). The server
// turns the JSON form (toPlanJson) into the XML file that `costar run` reads.

export type Attribute = [string, string];

export interface EditorNode {
  /** Stable identity in the editor (not saved). */
  key: string;
  /** Node type, e.g. "Sequence", "Move". */
  id: string;
  attributes: Attribute[];
  children: EditorNode[];
  /** Shown folded in the workspace (not saved). */
  collapsed?: boolean;
}

export interface EditorTree {
  id: string;
  root: EditorNode | null;
}

export interface EditorPlan {
  mainTree: string;
  trees: EditorTree[];
}

/** The server's JSON form (server/plan_json.h). */
export interface PlanNodeJson {
  id: string;
  attributes?: Attribute[];
  children?: PlanNodeJson[];
}
export interface PlanJson {
  main_tree: string;
  trees: { id: string; root: PlanNodeJson }[];
}

/** What the workspace needs to know of a node type (from GET /api/nodes). */
export type NodeKind = 'Control' | 'Decorator' | 'Action' | 'Condition' | 'SubTree';
export interface KindLookup {
  (id: string): NodeKind | undefined;
}

let counter = 0;
export function newKey(): string {
  counter += 1;
  return `n${counter}`;
}

export function makeNode(id: string, attributes: Attribute[] = [], children: EditorNode[] = []): EditorNode {
  return { key: newKey(), id, attributes, children };
}

export function emptyPlan(mainTree = 'main'): EditorPlan {
  return { mainTree, trees: [{ id: mainTree, root: makeNode('Sequence') }] };
}

export function nodeFromJson(json: PlanNodeJson): EditorNode {
  return makeNode(
    json.id,
    (json.attributes ?? []).map(([k, v]) => [k, v] as Attribute),
    (json.children ?? []).map(nodeFromJson),
  );
}

export function fromPlanJson(json: PlanJson): EditorPlan {
  const trees = json.trees.map((tree) => ({ id: tree.id, root: nodeFromJson(tree.root) }));
  return { mainTree: json.main_tree || trees[0]?.id || 'main', trees };
}

export function nodeToJson(node: EditorNode): PlanNodeJson {
  return { id: node.id, attributes: node.attributes.map(([k, v]) => [k, v]), children: node.children.map(nodeToJson) };
}

/** The JSON the server saves and runs. @throws Error naming an empty tree. */
export function toPlanJson(plan: EditorPlan): PlanJson {
  return {
    main_tree: plan.mainTree,
    trees: plan.trees.map((tree) => {
      if (!tree.root) throw new Error(`tree '${tree.id}' is empty: add a node to it`);
      return { id: tree.id, root: nodeToJson(tree.root) };
    }),
  };
}

// --- queries ---------------------------------------------------------------------------------

export function findTree(plan: EditorPlan, treeId: string): EditorTree | undefined {
  return plan.trees.find((tree) => tree.id === treeId);
}

export interface Located {
  node: EditorNode;
  parent: EditorNode | null;
  index: number; // in parent.children; 0 for the root
  depth: number;
}

export function locate(root: EditorNode | null, key: string): Located | undefined {
  if (!root) return undefined;
  const walk = (node: EditorNode, parent: EditorNode | null, index: number, depth: number): Located | undefined => {
    if (node.key === key) return { node, parent, index, depth };
    for (let i = 0; i < node.children.length; i++) {
      const found = walk(node.children[i], node, i, depth + 1);
      if (found) return found;
    }
    return undefined;
  };
  return walk(root, null, 0, 0);
}

export function attribute(node: EditorNode, name: string): string | undefined {
  return node.attributes.find(([k]) => k === name)?.[1];
}

/** The node in `tree` at a path of child indices (the server's diagnostics point this way). */
export function nodeAtPath(root: EditorNode | null, path: number[]): EditorNode | undefined {
  let node = root ?? undefined;
  for (const index of path) {
    node = node?.children[index];
  }
  return node;
}

/** Whether `node` can take one more child. */
export function acceptsChild(node: EditorNode, kindOf: KindLookup): boolean {
  const kind = kindOf(node.id);
  if (kind === 'Control') return true;
  if (kind === 'Decorator') return node.children.length === 0;
  return false;
}

function contains(node: EditorNode, key: string): boolean {
  return node.key === key || node.children.some((child) => contains(child, key));
}

// --- edits (each returns a new plan; the old one is untouched) ----------------------------------

/** Replaces the node with `key` in `root` by what `change` returns (null removes it). */
function replaceNode(
  root: EditorNode,
  key: string,
  change: (node: EditorNode) => EditorNode | null,
): EditorNode | null {
  if (root.key === key) return change(root);
  let changed = false;
  const children: EditorNode[] = [];
  for (const child of root.children) {
    const next = replaceNode(child, key, change);
    if (next !== child) changed = true;
    if (next) children.push(next);
  }
  return changed ? { ...root, children } : root;
}

function withTree(plan: EditorPlan, treeId: string, change: (root: EditorNode | null) => EditorNode | null): EditorPlan {
  const tree = findTree(plan, treeId);
  if (!tree) throw new Error(`no tree '${treeId}'`);
  const root = change(tree.root);
  if (root === tree.root) return plan;
  return { ...plan, trees: plan.trees.map((t) => (t.id === treeId ? { ...t, root } : t)) };
}

function editNode(plan: EditorPlan, treeId: string, key: string, change: (node: EditorNode) => EditorNode | null) {
  return withTree(plan, treeId, (root) => {
    if (!root || !locate(root, key)) throw new Error('that node is not in this tree');
    return replaceNode(root, key, change);
  });
}

/** Adds `child` under `parentKey` (at `index`, default last); into an empty tree as its root. */
export function addChild(
  plan: EditorPlan,
  treeId: string,
  parentKey: string | null,
  child: EditorNode,
  kindOf: KindLookup,
  index?: number,
): EditorPlan {
  const tree = findTree(plan, treeId);
  if (!tree) throw new Error(`no tree '${treeId}'`);
  if (!tree.root) return withTree(plan, treeId, () => child);
  const key = parentKey ?? tree.root.key;
  const parent = locate(tree.root, key)?.node;
  if (!parent) throw new Error('that node is not in this tree');
  if (!acceptsChild(parent, kindOf)) {
    const kind = kindOf(parent.id);
    throw new Error(
      kind === 'Decorator' ? `${parent.id} takes exactly one child` : `${parent.id} takes no children (add a sibling)`,
    );
  }
  return editNode(plan, treeId, key, (node) => {
    const children = [...node.children];
    children.splice(index ?? children.length, 0, child);
    return { ...node, children, collapsed: false };
  });
}

/** Adds `sibling` right after the node with `key`. */
export function addSibling(
  plan: EditorPlan,
  treeId: string,
  key: string,
  sibling: EditorNode,
  kindOf: KindLookup,
): EditorPlan {
  const tree = findTree(plan, treeId);
  const at = locate(tree?.root ?? null, key);
  if (!at) throw new Error('that node is not in this tree');
  if (!at.parent) throw new Error('the root has no siblings: add a child instead');
  if (kindOf(at.parent.id) === 'Decorator') throw new Error(`${at.parent.id} takes exactly one child`);
  return editNode(plan, treeId, at.parent.key, (parent) => {
    const children = [...parent.children];
    children.splice(at.index + 1, 0, sibling);
    return { ...parent, children };
  });
}

/** Removes a node and everything under it. */
export function removeNode(plan: EditorPlan, treeId: string, key: string): EditorPlan {
  return editNode(plan, treeId, key, () => null);
}

export type DropPosition = 'before' | 'after' | 'inside';

/** Moves a node (with its subtree) before, after or inside (last child of) `targetKey`. */
export function moveNode(
  plan: EditorPlan,
  treeId: string,
  key: string,
  targetKey: string,
  position: DropPosition,
  kindOf: KindLookup,
): EditorPlan {
  const tree = findTree(plan, treeId);
  const root = tree?.root ?? null;
  const moving = locate(root, key);
  const target = locate(root, targetKey);
  if (!moving || !target) throw new Error('that node is not in this tree');
  if (key === targetKey) return plan;
  if (contains(moving.node, targetKey)) throw new Error('a node cannot move into its own subtree');
  if (position === 'inside') {
    const capacity = acceptsChild(target.node, kindOf);
    if (!capacity) throw new Error(`${target.node.id} cannot take another child`);
  } else {
    if (!target.parent) throw new Error('nothing can stand beside the root');
    if (kindOf(target.parent.id) === 'Decorator' && target.parent.key !== moving.parent?.key) {
      throw new Error(`${target.parent.id} takes exactly one child`);
    }
  }
  const without = removeNode(plan, treeId, key);
  if (position === 'inside') return addChild(without, treeId, targetKey, moving.node, kindOf);
  const after = locate(findTree(without, treeId)!.root, targetKey)!;
  return editNode(without, treeId, after.parent!.key, (parent) => {
    const children = [...parent.children];
    children.splice(after.index + (position === 'after' ? 1 : 0), 0, moving.node);
    return { ...parent, children };
  });
}

/** Moves a node one place up or down among its siblings. */
export function shiftNode(plan: EditorPlan, treeId: string, key: string, delta: -1 | 1): EditorPlan {
  const at = locate(findTree(plan, treeId)?.root ?? null, key);
  if (!at?.parent) return plan;
  const to = at.index + delta;
  if (to < 0 || to >= at.parent.children.length) return plan;
  return editNode(plan, treeId, at.parent.key, (parent) => {
    const children = [...parent.children];
    const [node] = children.splice(at.index, 1);
    children.splice(to, 0, node);
    return { ...parent, children };
  });
}

/** Sets (or, with undefined or '', removes) an attribute, keeping the order of the others. */
export function setAttribute(
  plan: EditorPlan,
  treeId: string,
  key: string,
  name: string,
  value: string | undefined,
): EditorPlan {
  return editNode(plan, treeId, key, (node) => {
    const index = node.attributes.findIndex(([k]) => k === name);
    const attributes = [...node.attributes];
    if (value === undefined || value === '') {
      if (index < 0) return node;
      attributes.splice(index, 1);
    } else if (index >= 0) {
      if (attributes[index][1] === value) return node;
      attributes[index] = [name, value];
    } else if (name === 'name') {
      attributes.unshift([name, value]);
    } else {
      attributes.push([name, value]);
    }
    return { ...node, attributes };
  });
}

export function toggleCollapsed(plan: EditorPlan, treeId: string, key: string): EditorPlan {
  return editNode(plan, treeId, key, (node) => ({ ...node, collapsed: !node.collapsed }));
}

/** A deep copy with fresh keys (pasting, inserting a saved subtree). */
export function cloneNode(node: EditorNode): EditorNode {
  return { ...node, key: newKey(), attributes: node.attributes.map(([k, v]) => [k, v]), children: node.children.map(cloneNode) };
}

/** Adds a BehaviorTree to the plan (e.g. a saved subtree used by a SubTree node); replaces one with the same ID. */
export function putTree(plan: EditorPlan, tree: EditorTree): EditorPlan {
  const exists = plan.trees.some((t) => t.id === tree.id);
  return { ...plan, trees: exists ? plan.trees.map((t) => (t.id === tree.id ? tree : t)) : [...plan.trees, tree] };
}

export function removeTree(plan: EditorPlan, treeId: string): EditorPlan {
  if (treeId === plan.mainTree) throw new Error('the main tree cannot be removed');
  return { ...plan, trees: plan.trees.filter((t) => t.id !== treeId) };
}

/** Number of nodes in the plan (all trees). */
export function countNodes(plan: EditorPlan): number {
  const count = (node: EditorNode | null): number => (node ? 1 + node.children.reduce((s, c) => s + count(c), 0) : 0);
  return plan.trees.reduce((sum, tree) => sum + count(tree.root), 0);
}

/** Structural equality (keys and folding ignored): did the plan change? */
export function samePlan(a: EditorPlan, b: EditorPlan): boolean {
  try {
    return JSON.stringify(toPlanJson(a)) === JSON.stringify(toPlanJson(b));
  } catch {
    return false;
  }
}

// --- clipboard and insertion (Ctrl+C/X/V/D, the palette) ------------------------------------------

/** Whether `key` is a node that takes children (a control node, or a decorator without one). */
export function isContainer(root: EditorNode | null, key: string, kindOf: KindLookup): boolean {
  const node = locate(root, key)?.node;
  return !!node && acceptsChild(node, kindOf);
}

/**
 * Inserts `nodes` where a technician expects after selecting `key`: inside it as its last
 * children when it takes children (a Sequence, an empty decorator), else right after it. Into
 * an empty tree the first node becomes the root.
 */
export function insertAt(
  plan: EditorPlan,
  treeId: string,
  key: string | null,
  nodes: EditorNode[],
  kindOf: KindLookup,
): EditorPlan {
  const tree = findTree(plan, treeId);
  if (!tree) throw new Error(`no tree '${treeId}'`);
  if (nodes.length === 0) return plan;
  if (!tree.root) {
    if (nodes.length > 1) throw new Error('an empty tree takes one root node: paste into it one by one');
    return withTree(plan, treeId, () => nodes[0]);
  }
  const at = key ?? tree.root.key;
  if (isContainer(tree.root, at, kindOf)) {
    const target = locate(tree.root, at)!.node;
    if (kindOf(target.id) === 'Decorator' && nodes.length > 1) throw new Error(`${target.id} takes exactly one child`);
    let next = plan;
    for (const node of nodes) next = addChild(next, treeId, at, node, kindOf);
    return next;
  }
  let next = plan;
  let after = at;
  for (const node of nodes) {
    next = addSibling(next, treeId, after, node, kindOf);
    after = node.key;
  }
  return next;
}

/** The selected nodes to copy: in tree order, without those inside another selected node. */
export function topmostSelected(root: EditorNode | null, keys: Iterable<string>): EditorNode[] {
  const wanted = new Set(keys);
  const out: EditorNode[] = [];
  const walk = (node: EditorNode) => {
    if (wanted.has(node.key)) {
      out.push(node);
      return;
    }
    node.children.forEach(walk);
  };
  if (root) walk(root);
  return out;
}

/** Removes every node with one of `keys` (and its subtree); the root cannot be cut. */
export function removeNodes(plan: EditorPlan, treeId: string, keys: Iterable<string>): EditorPlan {
  const tree = findTree(plan, treeId);
  let next = plan;
  for (const node of topmostSelected(tree?.root ?? null, keys)) {
    if (node.key === tree?.root?.key) throw new Error('the root cannot be removed: delete its children, or start a new plan');
    next = removeNode(next, treeId, node.key);
  }
  return next;
}

/** Keys of the siblings from `from` to `to` (inclusive, either order), or [to] if they are not siblings. */
export function siblingRange(root: EditorNode | null, from: string, to: string): string[] {
  const a = locate(root, from);
  const b = locate(root, to);
  if (!a || !b || !a.parent || a.parent.key !== b.parent?.key) return [to];
  const [lo, hi] = a.index <= b.index ? [a.index, b.index] : [b.index, a.index];
  return a.parent.children.slice(lo, hi + 1).map((n) => n.key);
}

/** For keyboard navigation: the parent, first child, previous or next sibling of `key`. */
export function neighbour(root: EditorNode | null, key: string, direction: 'parent' | 'child' | 'previous' | 'next'): string | null {
  const at = locate(root, key);
  if (!at) return null;
  if (direction === 'parent') return at.parent?.key ?? null;
  if (direction === 'child') return at.node.collapsed ? null : at.node.children[0]?.key ?? null;
  if (!at.parent) return null;
  const index = at.index + (direction === 'next' ? 1 : -1);
  return at.parent.children[index]?.key ?? null;
}

/**
 * The node to each waypoint of a path in turn: it takes the first, copies of it (its other
 * attributes, fresh keys) follow it for the others. Returns the plan and the last copy's key.
 */
export function alongPath(
  plan: EditorPlan,
  treeId: string,
  key: string,
  port: string,
  waypoints: string[],
  kindOf: KindLookup,
): { plan: EditorPlan; last: string } {
  if (waypoints.length === 0) return { plan, last: key };
  let next = setAttribute(plan, treeId, key, port, waypoints[0]);
  const node = locate(findTree(next, treeId)?.root ?? null, key)?.node;
  if (!node) throw new Error('that node is not in this tree');
  let after = key;
  for (const waypoint of waypoints.slice(1)) {
    const copy = cloneNode(node);
    copy.attributes = copy.attributes.map(([k, v]) => [k, k === port ? waypoint : v]);
    next = addSibling(next, treeId, after, copy, kindOf);
    after = copy.key;
  }
  return { plan: next, last: after };
}
