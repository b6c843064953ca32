// The tree's layout (pane 4): d3-hierarchy's tidy tree places the boxes, depth along the main
// axis (left to right, or top down) and siblings across it, recomputed from the plan on every
// change so that nodes are never placed by hand; and the first view of a tree in its pane.

import { hierarchy, tree as tidyTree } from 'd3-hierarchy';
import type { EditorNode } from './tree';

export type Orientation = 'LR' | 'TB';

// Compact boxes (two lines: type and name, then what tells it apart or what went wrong), so
// that as much of a tree as can be shows at a zoom where its smallest text (11 px) stays
// readable: the structure assembly's 15 nodes whole at 1600x1000, and with the larger tree (M)
// at 1280x800.
export const BOX = { width: 260, height: 34 };
export const GAP = { sibling: 4, level: 44 };
/**
 * The first view of a tree never zooms out further than this: the boxes' smallest text is
 * 11 px at zoom 1, the least a person reads at arm's length; the rest is a scroll away, and the
 * running node is kept in view.
 */
export const MIN_FIT_ZOOM = 1;
const FIT_MARGIN = 8;

/**
 * The viewport that shows the whole tree in a pane of this size, centred, at zoom 1 at most
 * and `MIN_FIT_ZOOM` at least; a tree bigger than that starts at its top left corner (the
 * root's side) and the rest is a scroll away.
 */
export function fitViewport(placed: { x: number; y: number }[], width: number, height: number) {
  const xs = placed.map((p) => p.x);
  const ys = placed.map((p) => p.y);
  const w = Math.max(...xs) - Math.min(...xs) + BOX.width + 2 * FIT_MARGIN;
  const h = Math.max(...ys) - Math.min(...ys) + BOX.height + 2 * FIT_MARGIN;
  const zoom = Math.max(MIN_FIT_ZOOM, Math.min(1, width / w, height / h));
  const left = Math.min(...xs) - FIT_MARGIN;
  const top = Math.min(...ys) - FIT_MARGIN;
  return {
    x: w * zoom <= width ? (width - w * zoom) / 2 - left * zoom : -left * zoom,
    y: h * zoom <= height ? (height - h * zoom) / 2 - top * zoom : -top * zoom,
    zoom,
  };
}

/** Positions from d3-hierarchy's tidy tree: depth along the main axis, siblings across it. */
export function layout(root: EditorNode, orientation: Orientation) {
  const h = hierarchy(root, (n) => (n.collapsed ? [] : n.children));
  const across = orientation === 'LR' ? BOX.height + GAP.sibling : BOX.width + GAP.sibling;
  const along = orientation === 'LR' ? BOX.width + GAP.level : BOX.height + GAP.level;
  tidyTree<EditorNode>().nodeSize([across, along]).separation((a, b) => (a.parent === b.parent ? 1 : 1.15))(h);
  return h.descendants().map((d) => ({
    node: d.data,
    parent: d.parent?.data.key ?? null,
    x: orientation === 'LR' ? (d.y ?? 0) : (d.x ?? 0),
    y: orientation === 'LR' ? (d.x ?? 0) : (d.y ?? 0),
  }));
}
