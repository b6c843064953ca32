import { describe, expect, it } from 'vitest';
import type { ObjectShape } from '../src/api';
import { cssColour, nearestColorName, partLook, UNKNOWN_CLASS } from '../src/model/parts';

// As the server sends them (GET /api/choices, object_shape), from data/objects/*.json.
const shapes: Record<string, ObjectShape> = {
  link: {
    boxes: [{ center: [0, 0, 0], half_size: [0.075, 0.0125, 0.0125] }],
    colors: [{ name: 'grey', rgb: [0.5, 0.5, 0.5] }, { name: 'wood', rgb: [0.72, 0.52, 0.3] }],
  },
  node: {
    boxes: [
      { center: [0, 0, 0.0125], half_size: [0.025, 0.025, 0.0025] },
      { center: [0.0175, 0, 0.02], half_size: [0.0075, 0.025, 0.005] },
    ],
    colors: [{ name: 'blue', rgb: [0.1, 0.25, 0.8] }, { name: 'red', rgb: [0.8, 0.1, 0.1] }],
  },
};

describe('how parts are drawn', () => {
  it('uses the class file: its boxes (full sizes) and, with no colour reported, its first colour', () => {
    const link = partLook('link', shapes);
    expect(link.boxes).toEqual([{ center: [0, 0, 0], size: [0.15, 0.025, 0.025] }]);
    expect(link.colorName).toBe('grey');
    expect(link.colorNames).toEqual(['grey', 'wood']);
    expect(link.colorFrom).toBe('class');
    expect(cssColour(link.rgb)).toBe('#808080');
    expect(cssColour([0.72, 0.52, 0.3])).toBe('#b8854d');
    const node = partLook('node', shapes);
    expect(node.boxes).toHaveLength(2);
    expect(node.boxes[1]).toEqual({ center: [0.0175, 0, 0.02], size: [0.015, 0.05, 0.01] });
    expect(cssColour(node.rgb)).toBe('#1a40cc');
  });

  it('draws a class it was not told about as a grey cube', () => {
    expect(partLook('gear', shapes)).toBe(UNKNOWN_CLASS);
    expect(partLook('node', undefined)).toBe(UNKNOWN_CLASS);
    expect(cssColour(UNKNOWN_CLASS.rgb)).toBe('#999999');
  });

  it('draws a part in the colour perception saw on it, named after the nearest class colour', () => {
    // A red node as DetectObjects reports it in the simulated cell: brighter than the material (lit).
    const seen: [number, number, number] = [0.93, 0.16, 0.15];
    const node = partLook('node', shapes, seen);
    expect(node.rgb).toEqual(seen);
    expect(node.colorFrom).toBe('seen');
    expect(node.colorName).toBe('red');
    expect(node.boxes).toHaveLength(2); // still the class's shape
    expect(partLook('link', shapes, [0.8, 0.6, 0.35]).colorName).toBe('wood');
    expect(partLook('link', shapes, [0.45, 0.46, 0.5]).colorName).toBe('grey');
    // A class the server did not describe: the grey cube's shape, the colour seen.
    const gear = partLook('gear', shapes, seen);
    expect(gear.boxes).toEqual(UNKNOWN_CLASS.boxes);
    expect(gear.rgb).toEqual(seen);
    expect(gear.colorFrom).toBe('seen');
  });

  it('ignores a colour that is not three finite numbers and clamps one out of range', () => {
    for (const bad of [null, undefined, 'red', [1, 0], [0.5, Number.NaN, 0.5], [0.5, '0.5', 0.5]]) {
      const look = partLook('node', shapes, bad);
      expect(look.colorFrom).toBe('class');
      expect(look.colorName).toBe('blue');
    }
    expect(partLook('node', shapes, [1.4, -0.2, 0.1]).rgb).toEqual([1, 0, 0.1]);
  });

  it('names no colour for a class without colours', () => {
    expect(nearestColorName([0.5, 0.5, 0.5], [])).toBe('');
  });
});
