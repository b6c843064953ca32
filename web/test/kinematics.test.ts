import { describe, expect, it } from 'vitest';
import { position, ur5Frames } from '../src/model/kinematics';

// Pairs read from `costar serve` on the simulated cell (GET /api/state): the joint angles and
// the endpoint symbol the arm component computes with its own kinematics (URDF / KDL).
const SAMPLES = [
  { joints: [0, -2.3, 1.9, -1.1708, -1.5708, 0], endpoint: [0.17277, 0.10915, 0.33653] }, // home
  { joints: [-0.72075, -1.47198, 1.83636, -1.93517, -1.5708, -2.29155], endpoint: [0.45, -0.25, 0.15] }, // above_pick
];

describe("the 3D view's UR5 kinematics", () => {
  it("puts the tool where the arm component says it is", () => {
    for (const sample of SAMPLES) {
      const frames = ur5Frames(sample.joints);
      expect(frames.length).toBe(8);
      const tcp = position(frames[7]);
      for (let i = 0; i < 3; i++) expect(Math.abs(tcp[i] - sample.endpoint[i])).toBeLessThan(2e-4);
    }
  });

  it('points the tool down at home', () => {
    const tcp = ur5Frames(SAMPLES[0].joints)[7];
    expect(tcp[2][2]).toBeCloseTo(-1, 3); // the tool's z axis along -z of the world
  });
});
