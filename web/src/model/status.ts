// Live execution and replay: the server numbers the nodes of a built tree (uid = pre-order
// index, SubTrees expanded); the page maps them onto its own nodes and keeps each node's
// last status.

import { EditorNode, EditorPlan, attribute, findTree } from './tree';

export type Status = 'IDLE' | 'RUNNING' | 'SUCCESS' | 'FAILURE';
/** Last status shown on a node: HALTED when it was stopped while running. */
export type LastStatus = Status | 'HALTED';

export interface RunNode {
  uid: number;
  parent: number;
  id: string;
  name: string;
  path: string;
}

export interface NodeStatus {
  uid: number;
  status: Status;
  last: LastStatus;
  reason?: string;
  origin?: string;
  data?: unknown;
}

export interface Transition {
  seq: number;
  t: number;
  uid: number;
  from: Status;
  to: Status;
  reason?: string;
  origin?: string;
  data?: unknown;
}

/** Where a run's node is in the editor: tree and node key. */
export interface NodeRef {
  tree: string;
  key: string;
}

/**
 * Maps the run's uids onto the plan's nodes by walking both trees in step from the main
 * tree's root (a SubTree's child is the root of the subtree it names). Stops where the
 * node types differ (the plan was edited since the run started).
 */
export function mapRun(plan: EditorPlan, nodes: RunNode[]): Map<number, NodeRef> {
  const map = new Map<number, NodeRef>();
  const children = new Map<number, number[]>();
  const byUid = new Map<number, RunNode>();
  for (const node of nodes) {
    byUid.set(node.uid, node);
    if (node.parent >= 0) {
      const list = children.get(node.parent) ?? [];
      list.push(node.uid);
      children.set(node.parent, list);
    }
  }
  for (const list of children.values()) list.sort((a, b) => a - b);

  const walk = (editor: EditorNode, treeId: string, uid: number, depth: number) => {
    const run = byUid.get(uid);
    if (!run || run.id !== editor.id || depth > 200) return;
    map.set(uid, { tree: treeId, key: editor.key });
    const kids = children.get(uid) ?? [];
    if (editor.id === 'SubTree') {
      const subtreeId = attribute(editor, 'ID');
      const subtree = subtreeId ? findTree(plan, subtreeId) : undefined;
      if (subtree?.root && kids.length === 1) walk(subtree.root, subtree.id, kids[0], depth + 1);
      return;
    }
    editor.children.forEach((child, i) => {
      if (i < kids.length) walk(child, treeId, kids[i], depth + 1);
    });
  };
  const main = findTree(plan, plan.mainTree);
  if (main?.root && byUid.has(0)) walk(main.root, main.id, 0, 0);
  return map;
}

/** Applies one transition to the statuses (as the server does for the live stream). */
export function applyTransition(statuses: Map<number, NodeStatus>, t: Transition): void {
  const previous = statuses.get(t.uid);
  const next: NodeStatus = previous ? { ...previous } : { uid: t.uid, status: 'IDLE', last: 'IDLE' };
  next.status = t.to;
  if (t.to === 'IDLE') {
    if (t.from === 'RUNNING') next.last = 'HALTED';
  } else {
    next.last = t.to;
  }
  if (t.to === 'RUNNING') {
    delete next.reason;
    delete next.origin;
  } else if (t.to === 'FAILURE') {
    next.reason = t.reason;
    next.origin = t.origin;
  }
  if (t.data !== undefined && t.data !== null) next.data = t.data;
  statuses.set(t.uid, next);
}

/** The statuses after the first `count` transitions of a recorded run (replay). */
export function statusesAt(transitions: Transition[], count: number): Map<number, NodeStatus> {
  const statuses = new Map<number, NodeStatus>();
  const end = Math.max(0, Math.min(count, transitions.length));
  for (let i = 0; i < end; i++) applyTransition(statuses, transitions[i]);
  return statuses;
}

/** Statuses per editor node key (for the nodes of `tree`). */
export function statusesByKey(
  statuses: Map<number, NodeStatus>,
  mapping: Map<number, NodeRef>,
  tree: string,
): Map<string, NodeStatus> {
  const out = new Map<string, NodeStatus>();
  for (const [uid, status] of statuses) {
    const ref = mapping.get(uid);
    if (ref && ref.tree === tree) out.set(ref.key, status);
  }
  return out;
}

/** Merges a "statuses" message (absolute values per node) into the live statuses. */
export function mergeStatuses(statuses: Map<number, NodeStatus>, update: NodeStatus[]): Map<number, NodeStatus> {
  const next = new Map(statuses);
  for (const status of update) next.set(status.uid, status);
  return next;
}

/** A run's node mapped onto the editor, with what the node was when it was mapped. */
export interface MappedRef extends NodeRef {
  signature: string;
}

/** What a node is, for telling whether it was edited: its type, attributes and children's keys. */
export function nodeSignature(node: EditorNode): string {
  return JSON.stringify([node.id, node.attributes, node.children.map((c) => c.key)]);
}

/**
 * mapRun, keeping each node's signature as it was then: a node edited since (an attribute
 * changed, a child added, removed or moved) no longer shows the run's status.
 */
export function mapRunSigned(plan: EditorPlan, nodes: RunNode[]): Map<number, MappedRef> {
  const signed = new Map<number, MappedRef>();
  for (const [uid, ref] of mapRun(plan, nodes)) {
    const node = findNode(plan, ref);
    if (node) signed.set(uid, { ...ref, signature: nodeSignature(node) });
  }
  return signed;
}

function findNode(plan: EditorPlan, ref: NodeRef): EditorNode | undefined {
  const walk = (node: EditorNode | null): EditorNode | undefined => {
    if (!node) return undefined;
    if (node.key === ref.key) return node;
    for (const child of node.children) {
      const found = walk(child);
      if (found) return found;
    }
    return undefined;
  };
  return walk(findTree(plan, ref.tree)?.root ?? null);
}

/** statusesByKey for the nodes of `tree` not edited since they were mapped. */
export function unchangedStatusesByKey(
  statuses: Map<number, NodeStatus>,
  mapping: Map<number, MappedRef>,
  plan: EditorPlan,
  tree: string,
): Map<string, NodeStatus> {
  const current = new Map<string, string>();
  const walk = (node: EditorNode | null) => {
    if (!node) return;
    current.set(node.key, nodeSignature(node));
    node.children.forEach(walk);
  };
  walk(findTree(plan, tree)?.root ?? null);
  const out = new Map<string, NodeStatus>();
  for (const [uid, status] of statuses) {
    const ref = mapping.get(uid);
    if (ref && ref.tree === tree && current.get(ref.key) === ref.signature) out.set(ref.key, status);
  }
  return out;
}

/** The node that runs now: the deepest one RUNNING (the operation under its parents), if any. */
export function runningNode(statuses: Map<number, NodeStatus>, nodes: RunNode[]): RunNode | undefined {
  const byUid = new Map(nodes.map((n) => [n.uid, n]));
  const depth = (uid: number) => {
    let d = 0;
    for (let n = byUid.get(uid); n && n.parent >= 0 && d < 1000; n = byUid.get(n.parent)) d++;
    return d;
  };
  let best: RunNode | undefined;
  let bestDepth = -1;
  for (const [uid, status] of statuses) {
    if (status.status !== 'RUNNING') continue;
    const d = depth(uid);
    if (d > bestDepth && byUid.has(uid)) {
      best = byUid.get(uid);
      bestDepth = d;
    }
  }
  return best;
}

/**
 * A run mapped onto the plan open in the editor: only the nodes that are still what ran (the
 * same type and attributes as in the run's own plan, `ran`), each with its signature now, so
 * that later edits clear their statuses (unchangedStatusesByKey). Without `ran` (an old server),
 * every node mapRun finds.
 */
export function mapRunOnto(plan: EditorPlan, nodes: RunNode[], ran?: EditorPlan): Map<number, MappedRef> {
  const ours = mapRunSigned(plan, nodes);
  if (!ran) return ours;
  const theirs = mapRun(ran, nodes);
  const same = (a: EditorNode | undefined, b: EditorNode | undefined) =>
    !!a && !!b && a.id === b.id && JSON.stringify(a.attributes) === JSON.stringify(b.attributes) && a.children.length === b.children.length;
  const out = new Map<number, MappedRef>();
  for (const [uid, ref] of ours) {
    const theirRef = theirs.get(uid);
    if (theirRef && same(findNode(plan, ref), findNode(ran, theirRef))) out.set(uid, ref);
  }
  return out;
}
