// Poses and offsets as plans write them ("x;y;z" or "x;y;z;roll;pitch;yaw": metres and
// degrees, world/pose.h) and as the editor enters them: labelled fields, x, y, z in millimetres
// and roll, pitch, yaw in degrees.

export interface PoseFields {
  /** Millimetres. */
  x: number;
  y: number;
  z: number;
  /** Degrees. */
  roll: number;
  pitch: number;
  yaw: number;
}

export const POSE_FIELDS: { key: keyof PoseFields; label: string; unit: 'mm' | '°' }[] = [
  { key: 'x', label: 'x', unit: 'mm' },
  { key: 'y', label: 'y', unit: 'mm' },
  { key: 'z', label: 'z', unit: 'mm' },
  { key: 'roll', label: 'roll', unit: '°' },
  { key: 'pitch', label: 'pitch', unit: '°' },
  { key: 'yaw', label: 'yaw', unit: '°' },
];

const ZERO: PoseFields = { x: 0, y: 0, z: 0, roll: 0, pitch: 0, yaw: 0 };

/** The fields of a written pose; null when the text is not one (3 or 6 numbers). */
export function parsePoseText(text: string | undefined): PoseFields | null {
  if (text === undefined || text.trim() === '') return { ...ZERO };
  const parts = text.split(';').map((s) => s.trim());
  if (parts.length !== 3 && parts.length !== 6) return null;
  const numbers = parts.map(Number);
  if (numbers.some((n) => !Number.isFinite(n)) || parts.some((s) => s === '')) return null;
  const [x, y, z, roll = 0, pitch = 0, yaw = 0] = numbers;
  return { x: x * 1000, y: y * 1000, z: z * 1000, roll, pitch, yaw };
}

/** Rounds away float noise (0.1 mm and 0.001 degree are finer than any taught pose). */
function round(value: number, digits: number) {
  const scale = 10 ** digits;
  return Math.round(value * scale) / scale;
}

/** The text a plan writes: metres and degrees, the rotation only when there is one. */
export function formatPoseText(fields: PoseFields): string {
  const metres = [fields.x, fields.y, fields.z].map((v) => String(round(v / 1000, 6)));
  const rotation = [fields.roll, fields.pitch, fields.yaw].map((v) => round(v, 4));
  if (rotation.every((v) => v === 0)) return metres.join(';');
  return [...metres, ...rotation.map(String)].join(';');
}

/** A readout's number to `digits` decimals, never "-0.0" (a value that rounds to zero is 0). */
export function readoutNumber(value: number, digits = 1): string {
  const text = value.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}
