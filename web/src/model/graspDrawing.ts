// A grasp drawn on the parts in the 3D view (docs/TEACHING.md): SmartGrasp holds a part of the
// grasp's class with the tool centre point at the grasp's pose in the part's frame (GET
// /api/choices: grasp_pose), so the view draws the open gripper there on every part of that class
// the system believes in. Poses are {p: [x, y, z], q: [x, y, z, w]} as the server sends them.

import { compose, rotate } from './belief';

export type Vec3 = [number, number, number];
export type Quat = [number, number, number, number]; // x, y, z, w

export interface GraspPose {
  p: Vec3;
  q: Quat;
  /** The gripper mode the grasp needs (the 3-finger gripper's basic, pinch, wide, scissor); '' none. */
  mode: string;
}

export interface PartPose {
  name: string;
  class: string;
  p: Vec3;
  q: Quat;
}

export interface PlacedGrasp {
  part: string;
  /** The tool centre point in the world: the tool's z along the approach, its y where the fingers close. */
  p: Vec3;
  q: Quat;
}

export { rotate };

/** Where the tool centre point is when `grasp` holds each part of `objectClass` (a part's pose
 *  times the grasp's), in the order of `parts`. */
export function graspOnParts(parts: PartPose[], objectClass: string, grasp: GraspPose): PlacedGrasp[] {
  return parts
    .filter((part) => part.class === objectClass)
    .map((part) => {
      const { p, q } = compose(part, grasp);
      return { part: part.name, p: p as Vec3, q: q as Quat };
    });
}

/** The 3D view's caption: "grasp 'guided' (pinch mode) on node_1, node_3". */
export function graspCaption(name: string, grasp: GraspPose, placed: PlacedGrasp[]): string {
  const mode = grasp.mode ? ` (${grasp.mode} mode)` : '';
  const on = placed.length > 0 ? `on ${placed.map((g) => g.part).join(', ')}` : 'on no part detected';
  return `grasp '${name}'${mode} ${on}`;
}
