// Edits the editor offers where Check finds a problem it knows the cure for, and where the
// cell changed under the plan (a waypoint renamed).

import { EditorNode, EditorPlan, makeNode } from './tree';

/** A cure for one of Check's problems: a button's label and the edit it makes. */
export interface Fix {
  label: string;
  apply: (plan: EditorPlan) => EditorPlan;
}

function editAt(plan: EditorPlan, treeId: string, key: string, change: (node: EditorNode) => EditorNode): EditorPlan {
  const walk = (node: EditorNode): EditorNode => {
    if (node.key === key) return change(node);
    let changed = false;
    const children = node.children.map((child) => {
      const next = walk(child);
      if (next !== child) changed = true;
      return next;
    });
    return changed ? { ...node, children } : node;
  };
  return { ...plan, trees: plan.trees.map((t) => (t.id === treeId && t.root ? { ...t, root: walk(t.root) } : t)) };
}

/**
 * The cure for a structural problem on `node` (Check's message), if there is one:
 * "X needs exactly one child, has N" (N > 1): wrap the children in a Sequence;
 * "X is a leaf and cannot have children": take them out, after it.
 */
export function fixFor(message: string, treeId: string, node: EditorNode, parent: EditorNode | null): Fix | null {
  const many = /needs exactly one child, has (\d+)/.exec(message);
  if (many && Number(many[1]) > 1) {
    return {
      label: `Wrap the ${many[1]} children in a Sequence`,
      apply: (plan) => editAt(plan, treeId, node.key, (n) => ({ ...n, children: [makeNode('Sequence', [], n.children)] })),
    };
  }
  if (/is a leaf and cannot have children/.test(message) && parent) {
    return {
      label: `Move the ${node.children.length} children out, after ${node.id}`,
      apply: (plan) =>
        editAt(plan, treeId, parent.key, (p) => {
          const index = p.children.findIndex((c) => c.key === node.key);
          const children = [...p.children];
          children.splice(index, 1, { ...node, children: [] }, ...node.children);
          return { ...p, children };
        }),
    };
  }
  return null;
}

/** The parameters whose value is a waypoint's name (ports with choices_from "waypoint"). */
export type WaypointPorts = (nodeType: string) => string[];

/** How many nodes of the plan name waypoint `name` (in any tree). */
export function waypointUses(plan: EditorPlan, name: string, ports: WaypointPorts): number {
  let count = 0;
  const walk = (node: EditorNode) => {
    if (ports(node.id).some((port) => node.attributes.some(([k, v]) => k === port && v === name))) count++;
    node.children.forEach(walk);
  };
  plan.trees.forEach((t) => t.root && walk(t.root));
  return count;
}

/** The plan with every use of waypoint `from` renamed to `to`. */
export function renameWaypoint(plan: EditorPlan, from: string, to: string, ports: WaypointPorts): EditorPlan {
  const walk = (node: EditorNode): EditorNode => {
    const names = ports(node.id);
    let changed = false;
    const attributes = node.attributes.map(([k, v]): [string, string] => {
      if (names.includes(k) && v === from) {
        changed = true;
        return [k, to];
      }
      return [k, v];
    });
    let childChanged = false;
    const children = node.children.map((child) => {
      const next = walk(child);
      if (next !== child) childChanged = true;
      return next;
    });
    return changed || childChanged ? { ...node, attributes: changed ? attributes : node.attributes, children } : node;
  };
  return { ...plan, trees: plan.trees.map((t) => (t.root ? { ...t, root: walk(t.root) } : t)) };
}
