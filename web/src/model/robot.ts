// The cell's robot as the 3D view draws it (GET /api/robot): the arm from the URDF the planner
// reads (drawn by urdf-loader, components/robotModel.ts), the fingers from the gripper's reading
// (the `gripper_fingers` symbol on the stream), never from a robot's numbers kept in the page.

import { Matrix4, Quaternion, Vector3 } from 'three';

export interface RobotJoint {
  name: string;
  label: string;
  lower: number;
  upper: number;
}

export interface FingerBoxJson {
  centre: [number, number, number];
  size: [number, number, number];
}

export interface AdaptiveDescription {
  fingers: { name: string; base: [number, number, number]; yaw_deg: number; scissor_sign: number }[];
  phalanges: { name: string; length: number; width: number; thickness: number; lower_deg: number; upper_deg: number }[];
  actuation: { closed_deg: number };
  modes: { name: string; scissor_deg: number; closing: string[]; fingertip?: boolean }[];
}

export interface RobotDescription {
  urdf: string;
  name: string;
  label: string;
  base_link: string;
  flange_link: string;
  tcp_link: string;
  base_in_world: { p: [number, number, number]; q: [number, number, number, number] };
  joints: RobotJoint[];
  gripper: {
    key: string;
    kind: 'parallel' | 'adaptive';
    finger_links: string[];
    max_opening?: number;
    finger_boxes?: FingerBoxJson[];
    description?: AdaptiveDescription;
  };
  table?: { centre: [number, number, number]; size: [number, number, number] };
  /** What the scene fixes on the table (a workpiece and its marked area, a tool stand): boxes in the world. */
  fixtures?: { name: string; p: [number, number, number]; q: [number, number, number, number]; size: [number, number, number]; rgb: [number, number, number] }[];
  /** The cell's power tool, when it has one: its boxes in the tool frame, and the tool frame in the tool centre
   * point's while it is held (from the grasp SmartGrasp takes it by). */
  power_tool?: {
    name: string;
    label: string;
    boxes: { centre: [number, number, number]; size: [number, number, number] }[];
    rgb: [number, number, number];
    grasp: string;
    held_in_tcp: { p: [number, number, number]; q: [number, number, number, number] };
  };
}

/** The gripper's reading as the stream carries it (the `gripper_fingers` symbol). */
export interface FingerReading {
  names: string[];
  positions: number[];
}

/** A box to draw in the flange frame: its pose (column-major 4x4, three.js order) and sides (m). */
export interface DrawnBox {
  matrix: Matrix4;
  size: [number, number, number];
}

const DEG = Math.PI / 180;

/** The joint values by URDF joint name, from the stream's joint angles (the description's order). */
export function jointValues(robot: RobotDescription, joints: number[] | undefined): Record<string, number> {
  const values: Record<string, number> = {};
  robot.joints.forEach((joint, i) => {
    const q = joints?.[i];
    if (q !== undefined && Number.isFinite(q)) values[joint.name] = q;
  });
  return values;
}

/** A parallel gripper's two fingers at `opening` (m, clamped to its stroke): the +y finger first. */
export function parallelFingerBoxes(robot: RobotDescription, opening: number): DrawnBox[] {
  const boxes = robot.gripper.finger_boxes ?? [];
  const max = robot.gripper.max_opening ?? 0;
  const half = 0.5 * Math.min(Math.max(Number.isFinite(opening) ? opening : max, 0), max);
  const out: DrawnBox[] = [];
  for (const side of [1, -1]) {
    for (const box of boxes) {
      out.push({
        matrix: new Matrix4().makeTranslation(box.centre[0], side * (box.centre[1] + half), box.centre[2]),
        size: box.size,
      });
    }
  }
  return out;
}

/**
 * The phalanges' angles (degrees; proximal, medial, distal) of a finger at tendon position
 * `position` (0 open .. 1 closed). The tendon pulls the proximal and medial joints together:
 * open, the proximal leans out on its lower limit; closing, the weak proximal spring gives
 * first up to its upper limit, then the medial. In a fingertip mode the medial and distal stay
 * straight and the proximal turns alone (as the planner models it, gripper/adaptive_gripper_description.h).
 */
export function phalanxAngles(description: AdaptiveDescription, fingertip: boolean, position: number): [number, number, number] {
  const [proximal, medial] = description.phalanges;
  const p = Math.min(Math.max(Number.isFinite(position) ? position : 0, 0), 1);
  if (fingertip) return [proximal.lower_deg + p * (proximal.upper_deg - proximal.lower_deg), 0, 0];
  const open = proximal.lower_deg + medial.lower_deg;
  const total = open + p * (description.actuation.closed_deg - open);
  const first = Math.min(total - medial.lower_deg, proximal.upper_deg);
  const second = Math.min(Math.max(total - first, medial.lower_deg), medial.upper_deg);
  return [first, second, 0];
}

/**
 * The 3-finger gripper's phalanges in `mode` with each finger at its reading (flange frame):
 * knuckle on the scissor axis, each phalanx a box along its finger, bending toward the finger's +y.
 */
export function adaptiveFingerBoxes(description: AdaptiveDescription, mode: string | undefined, reading: FingerReading | undefined): DrawnBox[] {
  const modeDescription = description.modes.find((m) => m.name === mode) ?? description.modes[0];
  const scissor = (modeDescription?.scissor_deg ?? 0) * DEG;
  const out: DrawnBox[] = [];
  for (const finger of description.fingers) {
    const index = reading?.names.indexOf(finger.name) ?? -1;
    const position = index >= 0 ? reading!.positions[index] : 0;
    const angles = phalanxAngles(description, !!modeDescription?.fingertip, position);
    const frame = new Matrix4()
      .makeTranslation(finger.base[0], finger.base[1], finger.base[2])
      .multiply(new Matrix4().makeRotationZ(finger.yaw_deg * DEG + finger.scissor_sign * scissor));
    description.phalanges.forEach((phalanx, i) => {
      // Turning about the finger's -x closes it toward its +y.
      frame.multiply(new Matrix4().makeRotationX(-angles[i] * DEG));
      out.push({
        matrix: frame.clone().multiply(new Matrix4().makeTranslation(0, 0, phalanx.length / 2)),
        size: [phalanx.width, phalanx.thickness, phalanx.length],
      });
      frame.multiply(new Matrix4().makeTranslation(0, 0, phalanx.length));
    });
  }
  return out;
}

/** The base's pose in the world as a matrix. */
export function baseMatrix(robot: RobotDescription): Matrix4 {
  const { p, q } = robot.base_in_world;
  return new Matrix4().compose(new Vector3(...p), new Quaternion(...q), new Vector3(1, 1, 1));
}

/** Position (m) and roll, pitch, yaw (degrees, about fixed x, y, z) of a pose, for the readout. */
export function poseReadout(p: [number, number, number], q: [number, number, number, number]) {
  const [x, y, z, w] = q;
  const roll = Math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  const pitch = Math.asin(Math.min(1, Math.max(-1, 2 * (w * y - z * x))));
  const yaw = Math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  return { x: p[0], y: p[1], z: p[2], roll: roll / DEG, pitch: pitch / DEG, yaw: yaw / DEG };
}
