// The world the system believes, drawn as it changes: object symbols come from the last
// DetectObjects, but a part the gripper holds (the predicate holding(part)) moves with the
// tool, and a part put down stays where it was put until the next detection sees it again.

import type { CellState, Pose } from '../api';

type Vec3 = [number, number, number];
type Quat = [number, number, number, number]; // x, y, z, w

function qmul(a: Quat, b: Quat): Quat {
  const [ax, ay, az, aw] = a;
  const [bx, by, bz, bw] = b;
  return [
    aw * bx + ax * bw + ay * bz - az * by,
    aw * by - ax * bz + ay * bw + az * bx,
    aw * bz + ax * by - ay * bx + az * bw,
    aw * bw - ax * bx - ay * by - az * bz,
  ];
}
const qinv = (q: Quat): Quat => [-q[0], -q[1], -q[2], q[3]];
/** `v` turned by the unit quaternion `q`. */
export function rotate(q: Quat, v: Vec3): Vec3 {
  const r = qmul(qmul(q, [v[0], v[1], v[2], 0]), qinv(q));
  return [r[0], r[1], r[2]];
}
/** a * b for poses. */
export function compose(a: Pose, b: Pose): Pose {
  const p = rotate(a.q, b.p);
  return { p: [a.p[0] + p[0], a.p[1] + p[1], a.p[2] + p[2]], q: qmul(a.q, b.q) };
}
/** a^-1 * b. */
export function relative(a: Pose, b: Pose): Pose {
  const qi = qinv(a.q);
  const d: Vec3 = [b.p[0] - a.p[0], b.p[1] - a.p[1], b.p[2] - a.p[2]];
  return { p: rotate(qi, d), q: qmul(qi, b.q) };
}

const same = (a: Pose, b: Pose) => a.p.every((v, i) => Math.abs(v - b.p[i]) < 1e-6);

export interface Belief {
  /** The part held and its pose in the tool frame (taken when the hold began). */
  held?: { name: string; inTool: Pose; at: Pose };
  /** The tool's pose in the previous snapshot (snapshots are sparse on a loaded machine). */
  tool?: Pose;
  /** Parts put down since their last detection: where they were put, and the detected pose then. */
  placed: Map<string, { pose: Pose; detected: Pose }>;
}

export const emptyBelief = (): Belief => ({ placed: new Map() });

export function heldPart(state: CellState): string | undefined {
  for (const p of state.predicates) {
    const match = /^holding\(([^,()]+)\)$/.exec(p);
    if (match) return match[1];
  }
  return undefined;
}

export interface Believed {
  belief: Belief;
  /** Each part's pose to draw. */
  poses: Map<string, Pose>;
}

/** What a part's believed pose rests on: the last detection, the tool, or where it was put. */
export function whereFrom(believed: Believed, name: string): 'detected' | 'held' | 'put down' {
  if (believed.belief.held?.name === name) return 'held';
  return believed.belief.placed.has(name) ? 'put down' : 'detected';
}

/** The next belief after a snapshot, and each part's pose to draw. */
export function believe(previous: Belief, state: CellState): Believed {
  const tool = state.arm.endpoint;
  const held = heldPart(state);
  const belief: Belief = { held: undefined, placed: new Map(previous.placed), tool: tool ?? previous.tool };
  const poses = new Map<string, Pose>();
  for (const o of state.objects) {
    const detected: Pose = { p: o.p, q: o.q };
    const put = belief.placed.get(o.name);
    if (put && !same(put.detected, detected)) belief.placed.delete(o.name); // seen again since
    poses.set(o.name, belief.placed.get(o.name)?.pose ?? detected);
  }
  if (held && tool) {
    const before = previous.held?.name === held ? previous.held.inTool : undefined;
    const where = poses.get(held);
    // The grasp: the part where it was seen, the tool where it closed. By the first snapshot with
    // the hold the arm may be lifting already; of this tool pose and the previous one, the one
    // nearer the part is nearer the grasp.
    const near = (t: Pose) => (where ? Math.hypot(...t.p.map((v, i) => v - where.p[i])) : 0);
    const grasping = previous.tool && near(previous.tool) < near(tool) ? previous.tool : tool;
    const inTool = before ?? (where ? relative(grasping, where) : undefined);
    if (inTool) {
      const at = compose(tool, inTool);
      belief.held = { name: held, inTool, at };
      poses.set(held, at);
    }
  }
  if (previous.held && previous.held.name !== held && tool) {
    // Let go: the part stays where the tool left it until a detection sees it.
    const detected = state.objects.find((o) => o.name === previous.held!.name);
    if (detected) {
      // Where it was last drawn held: the fingers open with the arm at rest, and by the first
      // snapshot without the hold the tool may already be retreating (sparse snapshots under load).
      const pose = previous.held.at;
      belief.placed.set(detected.name, { pose, detected: { p: detected.p, q: detected.q } });
      poses.set(detected.name, pose);
    }
  }
  return { belief, poses };
}
