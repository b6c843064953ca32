// A grasp drawn on the parts in the 3D view (docs/TEACHING.md): SmartGrasp holds a part of the
// grasp's class with the tool centre point at the grasp's pose in the part's frame (GET
// /api/choices: grasp_pose), so the view draws the open gripper there on every part of that class
// the system believes in. Poses are {p: [x, y, z], q: [x, y, z, w]} as the server sends them.

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

function multiply(a: Quat, b: Quat): Quat {
  const [ax, ay, az, aw] = a;
  const [bx, by, bz, bw] = b;
  return [
    aw * bx + ax * bw + ay * bz - az * by,
    aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw,
    aw * bw - ax * bx - ay * by - az * bz,
  ];
}

/** `v` turned by the unit quaternion `q`. */
export function rotate(q: Quat, v: Vec3): Vec3 {
  const [x, y, z, w] = multiply(multiply(q, [v[0], v[1], v[2], 0]), [-q[0], -q[1], -q[2], q[3]]);
  void w;
  return [x, y, z];
}

/** Where the tool centre point is when `grasp` holds each part of `objectClass` (a part's pose
 *  times the grasp's), in the order of `parts`. */
export function graspOnParts(parts: PartPose[], objectClass: string, grasp: GraspPose): PlacedGrasp[] {
  return parts
    .filter((part) => part.class === objectClass)
    .map((part) => {
      const offset = rotate(part.q, grasp.p);
      return {
        part: part.name,
        p: [part.p[0] + offset[0], part.p[1] + offset[1], part.p[2] + offset[2]] as Vec3,
        q: multiply(part.q, grasp.q),
      };
    });
}

/** The 3D view's caption: "grasp 'guided' (pinch mode) on node_1, node_3". */
export function graspCaption(name: string, grasp: GraspPose, placed: PlacedGrasp[]): string {
  const mode = grasp.mode ? ` (${grasp.mode} mode)` : '';
  const on = placed.length > 0 ? `on ${placed.map((g) => g.part).join(', ')}` : 'on no part detected';
  return `grasp '${name}'${mode} ${on}`;
}
