// @vitest-environment happy-dom
// urdf-loader reads the URDF with the browser's DOMParser: happy-dom stands in for the browser.
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { Color, Mesh, MeshLambertMaterial, MeshPhongMaterial, Quaternion, Vector3 } from 'three';
import { describe, expect, it } from 'vitest';
import { DrawnRobot } from '../src/model/drawnRobot';
import type { FingerReading, RobotDescription } from '../src/model/robot';

interface Fixture {
  robot: RobotDescription;
  samples: { joints: number[]; endpoint: { p: [number, number, number]; q: [number, number, number, number] }; gripper: { mode?: string; reading?: FingerReading } }[];
}
// Recorded from `costar serve` (the note in each file says how).
const fixture = (cell: string) => JSON.parse(readFileSync(path.join(__dirname, 'fixtures', `robot_${cell}.json`), 'utf8')) as Fixture;

describe("the robot drawn from the planner's URDF", () => {
  for (const cell of ['ur5-sim', 'iiwa-3f-sim']) {
    it(`puts the tool centre point and its orientation where the arm's endpoint symbol says (${cell})`, () => {
      const { robot, samples } = fixture(cell);
      const drawn = new DrawnRobot(robot);
      for (const sample of samples) {
        drawn.update(sample.joints, sample.gripper.reading, sample.gripper.mode);
        const tool = drawn.toolPosition();
        const error = Math.hypot(tool.x - sample.endpoint.p[0], tool.y - sample.endpoint.p[1], tool.z - sample.endpoint.p[2]);
        expect(error).toBeLessThan(1e-4); // 0.1 mm: the same model, rounded on the stream
        // The tool's orientation too (the stream's quaternion is rounded: normalised first).
        const { quaternion } = drawn.toolPose();
        const angle = (quaternion.angleTo(new Quaternion(...sample.endpoint.q).normalize()) * 180) / Math.PI;
        expect(angle).toBeLessThan(0.01);
      }
      drawn.dispose();
    });
  }

  it("draws the 3-finger gripper's phalanges and the 2-finger gripper's fingers, not the planner's boxes over their travel", () => {
    const three = fixture('iiwa-3f-sim');
    const drawn = new DrawnRobot(three.robot);
    drawn.update(three.samples[1].joints, three.samples[1].gripper.reading, three.samples[1].gripper.mode);
    expect(drawn.fingerBoxes()).toBe(9);
    let hidden = 0;
    drawn.object.traverse((o) => {
      const collider = o as typeof o & { isURDFCollider?: boolean };
      if (collider.isURDFCollider && !collider.visible) hidden++;
    });
    expect(hidden).toBeGreaterThan(0);
    const two = fixture('ur5-sim');
    const parallel = new DrawnRobot(two.robot);
    parallel.update(two.samples[0].joints, two.samples[0].gripper.reading, two.samples[0].gripper.mode);
    expect(parallel.fingerBoxes()).toBe(4);
  });

  it('draws the power tool in the gripper, where its grasp puts it, while the tool reads held', () => {
    const { robot, samples } = fixture('iiwa-3f-sim');
    // GET /api/robot's power_tool on iiwa-3f-sim with sim/scenes/polishing.json (server test
    // PolishingCell.TheRobotDescriptionCarriesThePowerToolAndWhereItSitsInTheHand): the sander's pad, housing and
    // knob, held by the knob 10.7 cm above the pad, the tool's z (up through the knob) back up the arm.
    const sander: RobotDescription['power_tool'] = {
      name: 'orbital_sander',
      label: 'orbital palm sander / polisher',
      boxes: [
        { centre: [0, 0, 0.006], size: [0.1, 0.1, 0.012] },
        { centre: [0, 0, 0.042], size: [0.08, 0.08, 0.06] },
        { centre: [0, 0, 0.107], size: [0.036, 0.036, 0.07] },
      ],
      rgb: [0.9, 0.45, 0.1],
      grasp: 'knob',
      held_in_tcp: { p: [0, 0, 0.107], q: [1, 0, 0, 0] },
    };
    const drawn = new DrawnRobot({ ...robot, power_tool: sander });
    for (const sample of samples) {
      drawn.update(sample.joints, sample.gripper.reading, sample.gripper.mode, true);
      const held = drawn.heldToolPose();
      expect(held).not.toBeNull();
      const tcp = drawn.toolPose();
      const along = new Vector3(0, 0, 1).applyQuaternion(tcp.quaternion);
      // The pad's face 10.7 cm beyond the tool centre point along its axis, the tool turned to face back up the arm.
      expect(held!.position.distanceTo(tcp.position.clone().addScaledVector(along, 0.107))).toBeLessThan(1e-9);
      expect(new Vector3(0, 0, 1).applyQuaternion(held!.quaternion).dot(along)).toBeCloseTo(-1, 9);
      drawn.update(sample.joints, sample.gripper.reading, sample.gripper.mode, false);
      expect(drawn.heldToolPose()).toBeNull(); // on its stand, or taken away: not in the hand
    }
    drawn.dispose();
    // A cell without a power tool draws none, whatever the state says.
    const plain = new DrawnRobot(robot);
    plain.update(samples[0].joints, samples[0].gripper.reading, samples[0].gripper.mode, true);
    expect(plain.heldToolPose()).toBeNull();
    plain.dispose();
  });

  it("draws each arm in its description's colours (robots/ROBOT/ROBOT.json's rgba), once, and the gripper in grey", () => {
    const colours = (cell: string) => {
      const drawn = new DrawnRobot(fixture(cell).robot);
      drawn.update(fixture(cell).samples[0].joints, undefined, undefined);
      const seen = new Set<string>();
      let drawnTwice = 0;
      drawn.object.traverse((o) => {
        const shape = o as typeof o & { isURDFVisual?: boolean; isURDFCollider?: boolean };
        const besideVisuals = shape.parent?.children.some((c) => (c as { isURDFVisual?: boolean }).isURDFVisual);
        if (shape.isURDFCollider && shape.visible && besideVisuals) drawnTwice++;
        if (!shape.isURDFVisual || !shape.visible) return;
        shape.traverse((m) => {
          const mesh = m as Mesh;
          if (mesh.isMesh) seen.add((mesh.material as MeshPhongMaterial).color.getHexString());
        });
      });
      const grey = new Set<string>();
      drawn.object.traverse((o) => {
        const mesh = o as Mesh;
        if (mesh.isMesh && mesh.visible && mesh.parent?.visible && !(mesh.parent as { isURDFVisual?: boolean }).isURDFVisual) {
          grey.add((mesh.material as MeshLambertMaterial).color.getHexString());
        }
      });
      drawn.dispose();
      return { seen, drawnTwice, grey };
    };
    const hex = (r: number, g: number, b: number) => new Color(r, g, b).getHexString();
    const ur5 = colours('ur5-sim');
    // UR's light grey links and dark blue joint covers.
    expect([...ur5.seen].sort()).toEqual([hex(0.2, 0.25, 0.33), hex(0.7, 0.72, 0.75)].sort());
    const iiwa = colours('iiwa-3f-sim');
    expect([...iiwa.seen]).toEqual([hex(0.93, 0.55, 0.13)]); // KUKA orange
    for (const cell of [ur5, iiwa]) {
      // The arm's collision solids are not drawn over its visuals; the gripper (no visuals) is drawn in grey.
      expect(cell.drawnTwice).toBe(0);
      expect(cell.grey.has(new Color(0x55595f).getHexString())).toBe(true);
    }
  });
});
