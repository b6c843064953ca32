import { describe, expect, it } from 'vitest';
import type { CellState } from '../src/api';
import { safetyReadout } from '../src/model/safetyReadout';

const base = { type: 'state', t: 1, run: 0, mode: 'running', arm: {}, gripper: { open: true, closed: false, holding: false }, objects: [], waypoints: [], frames: [], predicates: [] };
const withSafety = (safety: NonNullable<CellState['safety']>) => ({ ...base, safety }) as unknown as CellState;

describe('the speed and separation strip', () => {
  it('shows the separation, the protective distance and the speed scale', () => {
    const free = safetyReadout(withSafety({ separation: 1.234, protective_distance: 0.501, speed_scale: 1, slowed: false, stopped: false, collaborative: false }));
    expect(free.shown).toBe(true);
    expect(free.state).toBe('free');
    expect(free.scalePercent).toBe(100);
    expect(free.text).toBe('person 123 cm away, protective distance 50 cm, speed 100 %, full speed');
  });
  it('says when the monitor slows or stops the arm, a stop before collaborative mode', () => {
    const slowed = safetyReadout(withSafety({ separation: 0.83, protective_distance: 0.6, speed_scale: 0.426, slowed: true, stopped: false, collaborative: false }));
    expect(slowed.state).toBe('slowed');
    expect(slowed.scalePercent).toBe(43);
    expect(slowed.text).toContain('speed 43 %, slowed for the person');
    const stopped = safetyReadout(withSafety({ separation: 0.42, protective_distance: 0.5, speed_scale: 0, slowed: false, stopped: true, collaborative: true }));
    expect(stopped.state).toBe('stopped');
    expect(stopped.text).toContain('speed 0 %, stopped for the person');
    const handOver = safetyReadout(withSafety({ separation: -0.016, protective_distance: 0.5, speed_scale: 1, slowed: false, stopped: false, collaborative: true }));
    expect(handOver.state).toBe('collaborative');
    expect(handOver.text).toBe('person 0 cm away, protective distance 50 cm, speed 100 %, hand-over mode: at most 0.2 m/s');
  });
  it('is not shown without a person in the cell, and keeps the scale within 0-100 %', () => {
    expect(safetyReadout(base as unknown as CellState).shown).toBe(false);
    expect(safetyReadout(null).shown).toBe(false);
    expect(safetyReadout(withSafety({ separation: 2, protective_distance: 0.5, speed_scale: 1.2, slowed: false, stopped: false, collaborative: false })).scalePercent).toBe(100);
  });
});
