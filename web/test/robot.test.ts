import { readFileSync } from 'node:fs';
import { describe, expect, it } from 'vitest';
import { Vector3 } from 'three';
import { adaptiveFingerBoxes, AdaptiveDescription, jointValues, parallelFingerBoxes, phalanxAngles, poseReadout, RobotDescription } from '../src/model/robot';

// The gripper descriptions the simulator and the planner use.
const robotiq3f = JSON.parse(readFileSync(new URL('../../robots/grippers/robotiq3f.json', import.meta.url), 'utf8')) as AdaptiveDescription;
const parallel = {
  joints: [
    { name: 'a1', label: 'A1', lower: -1, upper: 1 },
    { name: 'a2', label: 'A2', lower: -1, upper: 1 },
  ],
  gripper: {
    key: 'parallel-2f',
    kind: 'parallel',
    finger_links: ['fingers'],
    max_opening: 0.085,
    // gripper/finger_geometry.cpp, twoFingerGripper(): the +y finger closed.
    finger_boxes: [
      { centre: [0, 0.012, 0.12], size: [0.022, 0.016, 0.02] },
      { centre: [0, 0.004, 0.14], size: [0.026, 0.008, 0.04] },
    ],
  },
} as unknown as RobotDescription;

const centre = (m: { matrix: { elements: number[] } }) => new Vector3(m.matrix.elements[12], m.matrix.elements[13], m.matrix.elements[14]);

describe("the robot drawn from the cell's description", () => {
  it('sets the joints by their URDF names, in the order the stream sends them', () => {
    expect(jointValues(parallel, [0.5, -0.25])).toEqual({ a1: 0.5, a2: -0.25 });
    expect(jointValues(parallel, undefined)).toEqual({});
  });

  it("puts a 2-finger gripper's pads the reading's opening apart", () => {
    const open = parallelFingerBoxes(parallel, 0.05);
    expect(open).toHaveLength(4);
    const pads = [centre(open[1]), centre(open[3])];
    // The pads' inner faces are the opening apart: centres 0.05 + 2 x 4 mm (half a pad) apart.
    expect(pads[0].y - pads[1].y).toBeCloseTo(0.05 + 0.008, 9);
    expect(pads[0].z).toBeCloseTo(0.14, 9);
    // Beyond the stroke it draws the stroke.
    expect(centre(parallelFingerBoxes(parallel, 0.2)[1]).y).toBeCloseTo(0.004 + 0.0425, 9);
  });

  it('bends a 3-finger gripper finger as its tendon pulls: the proximal joint first, then the medial', () => {
    expect(phalanxAngles(robotiq3f, false, 0)).toEqual([-15, 0, 0]); // open: leaning out on its lower limit
    const half = phalanxAngles(robotiq3f, false, 0.5);
    expect(half[0]).toBeCloseTo(-15 + 62.5, 9);
    expect(half[1]).toBe(0);
    const closed = phalanxAngles(robotiq3f, false, 1);
    expect(closed[0]).toBe(70); // its upper limit
    expect(closed[1]).toBe(40); // the rest of the closing angle: 110 - 70
    expect(phalanxAngles(robotiq3f, true, 1)).toEqual([70, 0, 0]); // fingertip mode: straight
  });

  it('turns fingers 1 and 2 on the scissor axis by the mode, and closes each by its reading', () => {
    const reading = { names: ['finger_middle', 'finger_1', 'finger_2'], positions: [0, 0, 0] };
    const basic = adaptiveFingerBoxes(robotiq3f, 'basic', reading);
    expect(basic).toHaveLength(9); // 3 fingers x 3 phalanges
    // finger_1's distal phalanx: in basic mode it closes along +y (toward finger_middle); in
    // scissor mode it is turned 90 degrees to face finger_2 and closes along -x.
    const tipBasic = centre(basic[5]);
    expect(tipBasic.x).toBeCloseTo(0.028, 2);
    const basicClosed = centre(adaptiveFingerBoxes(robotiq3f, 'basic', { ...reading, positions: [0, 1, 1] })[5]);
    expect(basicClosed.y).toBeGreaterThan(tipBasic.y + 0.05);
    expect(basicClosed.x).toBeCloseTo(tipBasic.x, 9);
    const scissorOpen = centre(adaptiveFingerBoxes(robotiq3f, 'scissor', reading)[5]);
    const scissorClosed = centre(adaptiveFingerBoxes(robotiq3f, 'scissor', { ...reading, positions: [0, 1, 1] })[5]);
    expect(scissorClosed.x).toBeLessThan(scissorOpen.x - 0.05);
    expect(scissorClosed.y).toBeCloseTo(scissorOpen.y, 9);
    // Closing finger_middle moves its tip toward the others (-y: it stands at +y facing them).
    const closed = adaptiveFingerBoxes(robotiq3f, 'basic', { ...reading, positions: [1, 0, 0] });
    expect(centre(closed[2]).y).toBeLessThan(centre(basic[2]).y - 0.03);
    expect(centre(closed[5]).y).toBeCloseTo(centre(basic[5]).y, 9); // finger_1 untouched
  });

  it('reads a quaternion out as roll, pitch, yaw in degrees', () => {
    const down = poseReadout([0.4, 0, 0.3], [1, 0, 0, 0]); // half a turn about x: the tool points down
    expect(down.roll).toBeCloseTo(180, 6);
    expect(down.pitch).toBeCloseTo(0, 6);
    expect(down.yaw).toBeCloseTo(0, 6);
    const s = Math.SQRT1_2;
    expect(poseReadout([0, 0, 0], [0, 0, s, s]).yaw).toBeCloseTo(90, 6);
  });
});
