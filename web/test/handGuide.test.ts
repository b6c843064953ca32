import { describe, expect, it } from 'vitest';
import { freeDriveAttributes, handForce, HAND_MAX_FORCE } from '../src/model/handGuide';

describe('the hand on the tool', () => {
  it('pulls the tool toward the pointer as a spring, capped', () => {
    expect(handForce([0, 0, 0], [0.01, 0, 0], 300)).toEqual([3, 0, 0]);
    const far = handForce([0, 0, 0], [1, 1, 0]);
    expect(Math.hypot(...far)).toBeCloseTo(HAND_MAX_FORCE, 9);
    expect(far[0]).toBeCloseTo(far[1], 9);
    expect(handForce([0.2, 0.1, 0.3], [0.2, 0.1, 0.3])).toEqual([0, 0, 0]);
  });
  it('asks FreeDrive for the guiding mode, the locked axes and the recording', () => {
    expect(freeDriveAttributes({ mode: 'translation', locked: [], record: '', recordFrame: 'world' })).toEqual({ mode: 'translation', hold: '2' });
    expect(freeDriveAttributes({ mode: 'free', locked: ['z', 'rx'], record: 'stroke', recordFrame: 'node_2' })).toEqual({
      mode: 'free',
      hold: '2',
      locked: 'z,rx',
      record: 'stroke',
      record_frame: 'node_2',
    });
  });
});
