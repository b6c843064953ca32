// Free-drive from the 3D view (docs/TEACHING.md): the user grabs the tool's handle and drags; the
// page turns the drag into the push of a hand on the tool, a spring from the tool to where the
// pointer holds it, and sends it to the server every 50 ms while the pointer is held (the
// dead-man). Each push acts for 0.25 s and holds the dead-man for 2 s: when the stream stops the
// arm stands within 0.25 s, and free-drive ends 2 s later; a page late by less keeps it.

export type Vec3 = [number, number, number];

/** How the page's hand pulls: N per metre between the tool and the pointer, at most `max` N. */
export const HAND_STIFFNESS = 300;
export const HAND_MAX_FORCE = 40;
/** Milliseconds between two pushes while the pointer is held (the server's kDragPeriodSeconds). */
export const HAND_PERIOD_MS = 50;
/** Seconds the dead-man is held after each push, and at FreeDrive's start (kDragLeaseSeconds). */
export const HAND_LEASE_SECONDS = 2;

/** The hand's push on the tool at `tool` held at `target`: a spring, capped at `max` N. */
export function handForce(tool: Vec3, target: Vec3, stiffness = HAND_STIFFNESS, max = HAND_MAX_FORCE): Vec3 {
  const d: Vec3 = [target[0] - tool[0], target[1] - tool[1], target[2] - tool[2]];
  const force: Vec3 = [d[0] * stiffness, d[1] * stiffness, d[2] * stiffness];
  const size = Math.hypot(...force);
  return size > max ? [(force[0] * max) / size, (force[1] * max) / size, (force[2] * max) / size] : force;
}

/** The guiding mode as FreeDrive's parameters (Franka's modes: free, translation, rotation, axes locked). */
export interface Guiding {
  mode: 'free' | 'translation' | 'rotation';
  /** Axes locked besides, e.g. ['z']. */
  locked: string[];
  /** Record the guided path under this name (empty: no recording), relative to `recordFrame`. */
  record: string;
  recordFrame: string;
}

export function freeDriveAttributes(guiding: Guiding): Record<string, string> {
  const attributes: Record<string, string> = { mode: guiding.mode, hold: String(HAND_LEASE_SECONDS) };
  if (guiding.locked.length > 0) attributes.locked = guiding.locked.join(',');
  if (guiding.record) {
    attributes.record = guiding.record;
    attributes.record_frame = guiding.recordFrame || 'world';
  }
  return attributes;
}
