import { describe, expect, it } from 'vitest';
import { controlRefusal, motionRefusal, NOT_CONNECTED, resetRefusal, runRefusal, saveRefusal, SIGN_IN } from '../src/model/controls';

const idle = { connected: true, signedIn: true, activeRun: null, replaying: false };

describe('what the cell would refuse, said before a click', () => {
  it('allows everything but Stop when the cell is idle and the page signed in', () => {
    expect(runRefusal(idle)).toBeNull();
    expect(motionRefusal(idle)).toBeNull();
    expect(saveRefusal(idle)).toBeNull();
    expect(controlRefusal(idle)).toBe('nothing is running');
  });

  it('refuses Run and motions while any run is active, whoever started it, and allows Stop', () => {
    const running = { ...idle, activeRun: 16 };
    expect(runRefusal(running)).toBe('run #16 is active: stop it or wait for it to end');
    expect(motionRefusal(running)).toBe(runRefusal(running));
    expect(controlRefusal(running)).toBeNull();
    expect(resetRefusal(running)).toContain('before resetting the scene');
    expect(motionRefusal({ ...idle, activeRun: -3 })).toContain('an operation is running');
  });

  it('disables everything that talks to the cell while disconnected, and changes without a sign-in', () => {
    const offline = { ...idle, connected: false, activeRun: 4 };
    for (const refusal of [runRefusal, motionRefusal, controlRefusal, saveRefusal]) expect(refusal(offline)).toBe(NOT_CONNECTED);
    const looking = { ...idle, signedIn: false, activeRun: 4 };
    for (const refusal of [runRefusal, motionRefusal, controlRefusal, saveRefusal]) expect(refusal(looking)).toBe(SIGN_IN);
    expect(SIGN_IN).toBe('Sign in to change plans or move the robot');
  });

  it('refuses running while a past run is replayed', () => {
    expect(runRefusal({ ...idle, replaying: true })).toContain('replaying');
    expect(motionRefusal({ ...idle, replaying: true })).toBeNull();
  });
});
