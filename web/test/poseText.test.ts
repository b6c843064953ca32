import { describe, expect, it } from 'vitest';
import { formatPoseText, parsePoseText, readoutNumber } from '../src/model/poseText';

describe('poses entered in labelled fields', () => {
  it('reads a plan offset in metres as millimetres, and writes it back in metres', () => {
    expect(parsePoseText('0;0;0.15')).toEqual({ x: 0, y: 0, z: 150, roll: 0, pitch: 0, yaw: 0 });
    const fields = parsePoseText('0.45;-0.25;0.15;180;0;90')!;
    expect(fields).toEqual({ x: 450, y: -250, z: 150, roll: 180, pitch: 0, yaw: 90 });
    expect(formatPoseText(fields)).toBe('0.45;-0.25;0.15;180;0;90');
    expect(formatPoseText({ ...fields, roll: 0, yaw: 0 })).toBe('0.45;-0.25;0.15');
  });

  it('starts an empty offset at zero and refuses what is not a pose', () => {
    expect(parsePoseText(undefined)).toEqual({ x: 0, y: 0, z: 0, roll: 0, pitch: 0, yaw: 0 });
    expect(parsePoseText('0;0')).toBeNull();
    expect(parsePoseText('a;b;c')).toBeNull();
    expect(parsePoseText('1;;2')).toBeNull();
  });

  it('keeps a tenth of a millimetre and writes no float noise', () => {
    expect(formatPoseText({ x: 100.1, y: 0.3, z: -0.2, roll: 0, pitch: 0, yaw: 0 })).toBe('0.1001;0.0003;-0.0002');
  });
});

describe('the readout', () => {
  it('shows a value that rounds to zero as 0.0, never -0.0', () => {
    expect(readoutNumber(-0.04)).toBe('0.0');
    expect(readoutNumber(-0.05)).toBe('-0.1');
    expect(readoutNumber(-1e-12, 3)).toBe('0.000');
    expect(readoutNumber(426.94)).toBe('426.9');
  });
});
