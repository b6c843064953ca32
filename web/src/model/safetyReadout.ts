// What the operator watches while a person works beside the arm: the cell controller's speed and
// separation monitor (docs/PERSON.md), from the cell's live snapshot (or a replayed run's): the
// separation it senses, the protective distance at the arm's present speed, the speed override
// it applies, and whether it holds or slows the arm, or runs collaborative mode for a hand-over.

import type { CellState } from '../api';

export type SafetyState = 'free' | 'slowed' | 'stopped' | 'collaborative';

export interface SafetyReadout {
  /** Shown on a cell whose scene has a person; the rest is meaningless otherwise. */
  shown: boolean;
  state: SafetyState;
  /** The speed override in percent, 0 (held still) to 100 (full speed). */
  scalePercent: number;
  /** The line: the separation, the protective distance, the speed scale and the state. */
  text: string;
}

export function safetyReadout(state: CellState | null): SafetyReadout {
  const safety = state?.safety;
  if (!safety) return { shown: false, state: 'free', scalePercent: 100, text: '' };
  const scalePercent = Math.round(Math.min(1, Math.max(0, safety.speed_scale)) * 100);
  // A stop is what matters most; collaborative mode (power and force limiting) otherwise.
  const mode: SafetyState = safety.stopped ? 'stopped' : safety.collaborative ? 'collaborative' : safety.slowed ? 'slowed' : 'free';
  const words: Record<SafetyState, string> = {
    free: 'full speed',
    slowed: 'slowed for the person',
    stopped: 'stopped for the person',
    collaborative: 'hand-over mode: at most 0.2 m/s',
  };
  const cm = (m: number) => `${(m * 100).toFixed(0)} cm`;
  return {
    shown: true,
    state: mode,
    scalePercent,
    // The monitor's capsules enclose the geometry: in a hand-over they overlap (below 0).
    text: `person ${cm(Math.max(0, safety.separation))} away, protective distance ${cm(safety.protective_distance)}, speed ${scalePercent} %, ${words[mode]}`,
  };
}
