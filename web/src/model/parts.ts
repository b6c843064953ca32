// How a part is drawn: the boxes of its class (the class file the simulator builds bodies from
// and perception samples its models from) in the class's colour. Perception reports a part's
// class and pose, not its own colour, so a part is drawn in its class's first colour (the
// server lists them by name: a node blue, a link grey); a class the server did not describe
// is a grey 4 cm cube.

import type { ObjectShape } from '../api';

export interface PartBox {
  center: [number, number, number];
  size: [number, number, number];
}

export interface PartLook {
  boxes: PartBox[];
  /** RGB in [0, 1] and its name in the class file ('' for the fallback). */
  rgb: [number, number, number];
  colorName: string;
  /** Every colour the class comes in. */
  colorNames: string[];
}

export const UNKNOWN_CLASS: PartLook = { boxes: [{ center: [0, 0, 0], size: [0.04, 0.04, 0.04] }], rgb: [0.6, 0.6, 0.6], colorName: '', colorNames: [] };

export function partLook(objectClass: string, shapes: Record<string, ObjectShape> | undefined): PartLook {
  const shape = shapes?.[objectClass];
  if (!shape || shape.boxes.length === 0) return UNKNOWN_CLASS;
  const color = shape.colors[0];
  return {
    boxes: shape.boxes.map((b) => ({ center: b.center, size: [2 * b.half_size[0], 2 * b.half_size[1], 2 * b.half_size[2]] })),
    rgb: color?.rgb ?? UNKNOWN_CLASS.rgb,
    colorName: color?.name ?? '',
    colorNames: shape.colors.map((c) => c.name),
  };
}

/** '#rrggbb' for CSS. */
export function cssColour(rgb: [number, number, number]): string {
  return `#${rgb.map((v) => Math.round(Math.min(1, Math.max(0, v)) * 255).toString(16).padStart(2, '0')).join('')}`;
}
