// How a part is drawn: the boxes of its class (the class file the simulator builds bodies from
// and perception samples its models from) in the colour perception saw on it (DetectObjects
// reports each object's mean colour), named after the nearest of its class's colours. A part
// reported without a colour is drawn in its class's first colour (the server lists them by
// name: a node blue, a link grey); a class the server did not describe is a 4 cm cube.

import type { ObjectShape } from '../api';

export interface PartBox {
  center: [number, number, number];
  size: [number, number, number];
}

export type Rgb = [number, number, number];

export interface PartLook {
  boxes: PartBox[];
  /** RGB in [0, 1] and its name in the class file ('' when the class has none). */
  rgb: Rgb;
  colorName: string;
  /** Where rgb comes from: what perception saw on the part, the class's first colour, or a
   *  grey for a class the server did not describe. */
  colorFrom: 'seen' | 'class' | 'unknown';
  /** Every colour the class comes in. */
  colorNames: string[];
}

export const UNKNOWN_CLASS: PartLook = {
  boxes: [{ center: [0, 0, 0], size: [0.04, 0.04, 0.04] }],
  rgb: [0.6, 0.6, 0.6],
  colorName: '',
  colorFrom: 'unknown',
  colorNames: [],
};

/** A colour the server sent, if it is one: three finite numbers, clamped to [0, 1]. */
function validRgb(rgb: unknown): Rgb | null {
  if (!Array.isArray(rgb) || rgb.length !== 3 || !rgb.every((v) => typeof v === 'number' && Number.isFinite(v))) return null;
  return rgb.map((v: number) => Math.min(1, Math.max(0, v))) as Rgb;
}

/** The name of the class colour nearest to `rgb` (Euclidean in RGB), '' when there is none. */
export function nearestColorName(rgb: Rgb, colors: { name: string; rgb: Rgb }[]): string {
  let best = '';
  let bestDistance = Infinity;
  for (const c of colors) {
    const d = (c.rgb[0] - rgb[0]) ** 2 + (c.rgb[1] - rgb[1]) ** 2 + (c.rgb[2] - rgb[2]) ** 2;
    if (d < bestDistance) {
      bestDistance = d;
      best = c.name;
    }
  }
  return best;
}

/** How to draw a part of `objectClass`; `seen` is the colour perception reported for it. */
export function partLook(objectClass: string, shapes: Record<string, ObjectShape> | undefined, seen?: unknown): PartLook {
  const shape = shapes?.[objectClass];
  const rgb = validRgb(seen);
  if (!shape || shape.boxes.length === 0) {
    return rgb ? { ...UNKNOWN_CLASS, rgb, colorFrom: 'seen' } : UNKNOWN_CLASS;
  }
  const color = shape.colors[0];
  return {
    boxes: shape.boxes.map((b) => ({ center: b.center, size: [2 * b.half_size[0], 2 * b.half_size[1], 2 * b.half_size[2]] })),
    rgb: rgb ?? color?.rgb ?? UNKNOWN_CLASS.rgb,
    colorName: rgb ? nearestColorName(rgb, shape.colors) : (color?.name ?? ''),
    colorFrom: rgb ? 'seen' : color ? 'class' : 'unknown',
    colorNames: shape.colors.map((c) => c.name),
  };
}

/** '#rrggbb' for CSS. */
export function cssColour(rgb: Rgb): string {
  return `#${rgb.map((v) => Math.round(Math.min(1, Math.max(0, v)) * 255).toString(16).padStart(2, '0')).join('')}`;
}
