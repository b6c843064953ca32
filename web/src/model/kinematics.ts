// The UR5's forward kinematics (Denavit-Hartenberg, as published by Universal Robots) for
// the 3D view: the frame of every joint, from the joint angles the stream carries.

export type Matrix4 = number[][];

export const UR5_DH = {
  d: [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
  a: [0, -0.425, -0.39225, 0, 0, 0],
  alpha: [Math.PI / 2, 0, 0, Math.PI / 2, -Math.PI / 2, 0],
};

/** The robot's base in the world: turned half a turn about z (as the simulated cell places it). */
export const BASE_IN_WORLD: Matrix4 = [
  [-1, 0, 0, 0],
  [0, -1, 0, 0],
  [0, 0, 1, 0],
  [0, 0, 0, 1],
];

/** The tool centre point in the flange frame: 14 cm along z (between the finger pads). */
export const TCP_OFFSET = 0.14;

export function multiply(a: Matrix4, b: Matrix4): Matrix4 {
  const c: Matrix4 = [];
  for (let i = 0; i < 4; i++) {
    c.push([]);
    for (let j = 0; j < 4; j++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[i][k] * b[k][j];
      c[i].push(s);
    }
  }
  return c;
}

function dh(theta: number, d: number, a: number, alpha: number): Matrix4 {
  const ct = Math.cos(theta);
  const st = Math.sin(theta);
  const ca = Math.cos(alpha);
  const sa = Math.sin(alpha);
  return [
    [ct, -st * ca, st * sa, a * ct],
    [st, ct * ca, -ct * sa, a * st],
    [0, sa, ca, d],
    [0, 0, 0, 1],
  ];
}

/** World frames of the base and of links 1..6 (the flange), then the TCP: 8 matrices. */
export function ur5Frames(joints: number[], base: Matrix4 = BASE_IN_WORLD): Matrix4[] {
  const frames: Matrix4[] = [base];
  let current = base;
  for (let i = 0; i < 6; i++) {
    current = multiply(current, dh(joints[i] ?? 0, UR5_DH.d[i], UR5_DH.a[i], UR5_DH.alpha[i]));
    frames.push(current);
  }
  const tcp: Matrix4 = [
    [1, 0, 0, 0],
    [0, 1, 0, 0],
    [0, 0, 1, TCP_OFFSET],
    [0, 0, 0, 1],
  ];
  frames.push(multiply(current, tcp));
  return frames;
}

export function position(frame: Matrix4): [number, number, number] {
  return [frame[0][3], frame[1][3], frame[2][3]];
}
