// What a technician watches while the arm presses: the wrist sensor's force (its size, and
// along the tool's axis: the press) and the power tool's state, from the cell's live snapshot
// (or a replayed run's).

import type { CellState } from '../api';

export interface ForceReadout {
  /** The force's size (N); null when the cell has no force sensor. */
  magnitude: number | null;
  /** Along the tool's axis (its z, N): what a press pushes with. */
  along: number | null;
  inContact: boolean;
  /** The tool's line, or null when the cell has no power tool. */
  tool: string | null;
  toolOn: boolean;
}

const UNIT_NAMES: Record<string, string> = { opm: 'per minute' };

export function forceReadout(state: CellState | null): ForceReadout {
  const force = state?.arm.wrench?.force;
  const tool = state?.tool;
  let toolLine: string | null = null;
  if (tool) {
    const where = tool.held ? 'in the gripper' : tool.docked ? 'on its stand' : 'not in position';
    const speed = `${Math.round(tool.speed)} ${UNIT_NAMES[tool.unit] ?? tool.unit}`;
    toolLine = `tool ${tool.on ? `on, ${speed}${tool.at_speed ? '' : ' (speeding up)'}` : tool.speed > 0 ? `off, ${speed} (stopping)` : 'off'}, ${where}`;
  }
  return {
    magnitude: force ? Math.hypot(...force) : null,
    along: force ? force[2] : null,
    inContact: !!state?.arm.in_contact,
    tool: toolLine,
    toolOn: !!tool?.on,
  };
}
