import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import { BOX, fitViewport, layout, MIN_FIT_ZOOM } from '../src/model/layout';

// The structure assembly (examples/ur5/assemble_structure.xml): a Sequence of 14 operations.
function assembly(): T.EditorNode {
  const step = () => [T.makeNode('Home'), T.makeNode('DetectObjects'), T.makeNode('SmartGrasp'), T.makeNode('SmartRelease')];
  return T.makeNode('Sequence', [], [T.makeNode('Open'), ...step(), ...step(), ...step(), T.makeNode('Home')]);
}

/** How many boxes a pane of this size shows whole in the first view. */
function wholeInView(root: T.EditorNode, width: number, height: number) {
  const placed = layout(root, 'LR');
  const { x, y, zoom } = fitViewport(placed, width, height);
  const shown = placed.filter((p) => {
    const left = p.x * zoom + x;
    const top = p.y * zoom + y;
    return left >= 0 && top >= 0 && left + BOX.width * zoom <= width && top + BOX.height * zoom <= height;
  });
  return { shown: shown.length, zoom, of: placed.length };
}

describe('the tree in its pane', () => {
  it('lays out boxes that never overlap, children right of their parent', () => {
    const placed = layout(assembly(), 'LR');
    expect(placed).toHaveLength(15);
    const children = placed.filter((p) => p.parent);
    expect(new Set(children.map((p) => p.x)).size).toBe(1);
    expect(children[0].x).toBeGreaterThanOrEqual(placed[0].x + BOX.width);
    const ys = children.map((p) => p.y).sort((a, b) => a - b);
    ys.slice(1).forEach((v, i) => expect(v - ys[i]).toBeGreaterThanOrEqual(BOX.height));
    const down = layout(assembly(), 'TB');
    const xs = down.filter((p) => p.parent).map((p) => p.x).sort((a, b) => a - b);
    xs.slice(1).forEach((v, i) => expect(v - xs[i]).toBeGreaterThanOrEqual(BOX.width));
  });

  // Pane sizes measured in Chromium: the canvas at 1600x1000, at 1280x800, and at 1280x800 with
  // the larger tree (M).
  it('never zooms a first view out below where its smallest text (11 px) reads at 11 px', () => {
    expect(MIN_FIT_ZOOM).toBe(1);
  });

  it('shows the whole structure assembly at 1600x1000, readable', () => {
    const view = wholeInView(assembly(), 1048, 558);
    expect(view.shown).toBe(15);
    expect(view.zoom).toBe(1);
  });

  it('at 1280x800 shows most of it readable, and all of it with the larger tree', () => {
    const view = wholeInView(assembly(), 796, 463);
    expect(view.zoom).toBe(1);
    expect(view.shown).toBeGreaterThanOrEqual(11);
    const large = wholeInView(assembly(), 796, 638);
    expect(large.shown).toBe(15);
    expect(large.zoom).toBe(1);
  });

  it('starts a tree too big to show readable at its top left, never below the minimum zoom', () => {
    const big = T.makeNode('Sequence', [], Array.from({ length: 60 }, () => T.makeNode('Home')));
    const placed = layout(big, 'LR');
    const view = fitViewport(placed, 796, 463);
    expect(view.zoom).toBe(MIN_FIT_ZOOM);
    const top = Math.min(...placed.map((p) => p.y));
    expect(top * view.zoom + view.y).toBeGreaterThan(0);
    expect(top * view.zoom + view.y).toBeLessThan(20);
    // Folded, the same tree is one box, centred at zoom 1.
    const folded = { ...big, collapsed: true };
    const one = fitViewport(layout(folded, 'LR'), 796, 463);
    expect(one.zoom).toBe(1);
    expect(one.x).toBeCloseTo((796 - BOX.width) / 2, 6);
  });
});
