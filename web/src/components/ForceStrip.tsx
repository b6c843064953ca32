// The force and tool strip over the 3D view: the wrist sensor's force and the power tool's
// state, live (or as a replayed run logged them). Shown on cells with a force sensor or a tool.

import type { CellState } from '../api';
import { forceReadout } from '../model/forceReadout';

export function ForceStrip({ state }: { state: CellState | null }) {
  const readout = forceReadout(state);
  if (readout.magnitude === null && readout.tool === null) return null;
  return (
    <div className="force-strip" role="status" aria-label="force and tool" data-in-contact={String(readout.inContact)} data-tool-on={String(readout.toolOn)}>
      {readout.magnitude !== null && (
        <span className={readout.inContact ? 'force contact' : 'force'} title="the wrist sensor: the force's size, and along the tool's axis (what a press pushes with)">
          force {readout.magnitude.toFixed(1)} N, along the tool {readout.along!.toFixed(1)} N{readout.inContact ? ', in contact' : ''}
        </span>
      )}
      {readout.tool && <span className={readout.toolOn ? 'tool on' : 'tool'}>{readout.tool}</span>}
    </div>
  );
}
