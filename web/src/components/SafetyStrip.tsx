// The speed and separation strip over the 3D view, on a cell whose scene has a person: the
// separation the monitor senses, the protective distance, and the speed scale as a bar, live
// (or as a replayed run logged them).

import type { CellState } from '../api';
import { safetyReadout } from '../model/safetyReadout';

export function SafetyStrip({ state }: { state: CellState | null }) {
  const readout = safetyReadout(state);
  if (!readout.shown) return null;
  return (
    <div
      className={`safety-strip ${readout.state}`}
      role="status"
      aria-label="speed and separation"
      data-state={readout.state}
      data-speed-scale={readout.scalePercent}
      data-separation={state?.safety?.separation}
      title="The cell controller's speed and separation monitoring (ISO/TS 15066): the arm slows as the person comes nearer and stops within the protective distance"
    >
      <span className="safety-scale" aria-hidden="true">
        <span className="safety-scale-fill" style={{ width: `${readout.scalePercent}%` }} />
      </span>
      <span className="safety-text">{readout.text}</span>
    </div>
  );
}
