import { describe, expect, it } from 'vitest';
import { graspCaption, graspOnParts, rotate, type GraspPose, type PartPose } from '../src/model/graspDrawing';

const s = Math.SQRT1_2;
// data/grasps.json's top grasp of a node: 5 mm above its centre, the tool pointing down (180 degrees about x).
const top: GraspPose = { p: [0, 0, 0.005], q: [1, 0, 0, 0], mode: '' };

describe('a grasp drawn on the parts', () => {
  it('turns a vector by a quaternion', () => {
    const quarter: [number, number, number, number] = [0, 0, s, s]; // 90 degrees about z
    const turned = rotate(quarter, [1, 0, 0]);
    expect(turned[0]).toBeCloseTo(0, 12);
    expect(turned[1]).toBeCloseTo(1, 12);
  });
  it('puts the tool centre point at the grasp in each part of its class, turned with the part', () => {
    const parts: PartPose[] = [
      { name: 'node_1', class: 'node', p: [0.5, 0.1, 0.025], q: [0, 0, 0, 1] },
      { name: 'link_1', class: 'link', p: [0.4, 0, 0.01], q: [0, 0, 0, 1] },
      // on its side: its z along the world's -y
      { name: 'node_2', class: 'node', p: [0.6, -0.1, 0.025], q: [s, 0, 0, s] },
    ];
    const wide: GraspPose = { p: [0, -0.006, 0], q: [1, 0, 0, 0], mode: 'wide' };
    const placed = graspOnParts(parts, 'node', top);
    expect(placed.map((g) => g.part)).toEqual(['node_1', 'node_2']);
    expect(placed[0].p[2]).toBeCloseTo(0.03, 12);
    // 90 degrees about x: the part's z is the world's -y
    expect(placed[1].p[1]).toBeCloseTo(-0.1 - 0.005, 12);
    expect(placed[1].p[2]).toBeCloseTo(0.025, 12);
    // the tool's z (its approach) points along the part's -z: the world's +y there
    const approach = rotate(placed[1].q, [0, 0, 1]);
    expect(approach[1]).toBeCloseTo(1, 12);
    expect(graspOnParts(parts, 'node', wide)[0].p[1]).toBeCloseTo(0.094, 12);
  });
  it('names the grasp, its mode and the parts it is drawn on', () => {
    const parts: PartPose[] = [{ name: 'node_1', class: 'node', p: [0.5, 0.1, 0.025], q: [0, 0, 0, 1] }];
    expect(graspCaption('guided', { ...top, mode: 'pinch' }, graspOnParts(parts, 'node', top))).toBe("grasp 'guided' (pinch mode) on node_1");
    expect(graspCaption('top', top, [])).toBe("grasp 'top' on no part detected");
  });
});
