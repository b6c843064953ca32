// Numbers as a technician states them: a parameter's unit is the one its description names in
// parentheses ("the force (N) ...", "how fast the tool approaches (m/s)"), the plan keeps the
// cell's units (metres, m/s, N) and the editor shows lengths and speeds in millimetres and mm/s,
// as it shows poses. A value out of the parameter's range (GET /api/nodes: min, max), or not below
// the number of the node it must stay below (less_than: a force below max_force), is refused with
// the reason before anything is saved or run, as costar validate refuses it.

import type { NodeInfo, PortInfo } from '../api';
import type { EditorNode } from './tree';

export interface Unit {
  /** As the plan writes it (the cell's unit). */
  plan: string;
  /** As the editor shows it. */
  shown: string;
  /** Shown value = plan value × scale. */
  scale: number;
}

/** Units the cell's descriptions name, and how the editor shows them. */
const UNITS: Record<string, Unit> = {
  'm/s': { plan: 'm/s', shown: 'mm/s', scale: 1000 },
  m: { plan: 'm', shown: 'mm', scale: 1000 },
  N: { plan: 'N', shown: 'N', scale: 1 },
  'N/m': { plan: 'N/m', shown: 'N/m', scale: 1 },
  opm: { plan: 'opm', shown: 'per minute', scale: 1 },
  rpm: { plan: 'rpm', shown: 'rpm', scale: 1 },
};

/** The unit a number parameter's description names, or null (a count, a fraction, text). */
export function unitOf(port: Pick<PortInfo, 'type' | 'description'>): Unit | null {
  if (port.type !== 'double' && port.type !== 'int') return null;
  // "(N)", "(m/s)", "(opm, orbital sander ...)": the first word inside parentheses.
  for (const match of port.description.matchAll(/\(([^()\s,;]+)[,)]/g)) {
    const unit = UNITS[match[1]];
    if (unit) return unit;
  }
  return null;
}

/** Shown numbers keep 4 significant digits' worth and no float noise (0.03 m/s → 30). */
function tidy(value: number): string {
  return String(Number(value.toPrecision(10)));
}

/** The plan's text as the editor shows it ('' when absent or not a number). */
export function toShown(unit: Unit | null, text: string | undefined): string {
  if (text === undefined || text.trim() === '') return '';
  const value = Number(text);
  if (!Number.isFinite(value)) return text;
  return unit ? tidy(value * unit.scale) : text;
}

/** What the editor's field holds, written in the plan's unit (undefined when empty). */
export function toPlan(unit: Unit | null, shown: string): string | undefined {
  if (shown.trim() === '') return undefined;
  const value = Number(shown);
  if (!Number.isFinite(value)) return shown;
  return unit ? tidy(value / unit.scale) : tidy(value);
}

/** "from 5 to 200 mm/s": the range as shown, or '' when the port has none. */
export function rangeText(port: PortInfo): string {
  if (port.min === undefined && port.max === undefined) return '';
  const unit = unitOf(port);
  const shown = (v: number) => (unit ? tidy(v * unit.scale) : tidy(v));
  const suffix = unit ? ` ${unit.shown}` : '';
  if (port.min !== undefined && port.max !== undefined) return `from ${shown(port.min)} to ${shown(port.max)}${suffix}`;
  return port.min !== undefined ? `at least ${shown(port.min)}${suffix}` : `at most ${shown(port.max!)}${suffix}`;
}

/** Why a written number is refused (not a number, not whole, out of range), in the shown unit, or null. */
export function rangeProblem(port: PortInfo, text: string | undefined): string | null {
  if (text === undefined || (port.type !== 'double' && port.type !== 'int')) return null;
  const value = Number(text);
  const unit = unitOf(port);
  if (text.trim() === '' || !Number.isFinite(value)) return `${port.name}: '${text}' is not a number`;
  if (port.type === 'int' && !Number.isInteger(value)) return `${port.name}: ${text} is not a whole number`;
  const below = port.min !== undefined && value < port.min;
  const above = port.max !== undefined && value > port.max;
  if (!below && !above) return null;
  return `${port.name} ${toShown(unit, text)}${unit ? ` ${unit.shown}` : ''} is out of range: ${rangeText(port)}`;
}

/** A node's number as it stands: written in the plan, else its port's default (undefined: neither). */
function numberOf(ports: PortInfo[], attributes: [string, string][], name: string): { port: PortInfo; text: string } | undefined {
  const port = ports.find((p) => p.name === name);
  const text = attributes.find(([k]) => k === name)?.[1] ?? port?.default;
  return port && text !== undefined && text.trim() !== '' ? { port, text } : undefined;
}

/** "below max_force (40 N)": the number a parameter must stay below, as the node has it now, or ''. */
export function boundText(port: PortInfo, ports: PortInfo[], attributes: [string, string][]): string {
  if (!port.less_than) return '';
  const bound = numberOf(ports, attributes, port.less_than);
  if (!bound || !Number.isFinite(Number(bound.text))) return `below ${port.less_than}`;
  const unit = unitOf(bound.port);
  return `below ${port.less_than} (${toShown(unit, bound.text)}${unit ? ` ${unit.shown}` : ''})`;
}

/** Why a number at or above the one it must stay below (less_than) is refused, in the shown unit, or null. */
export function boundProblem(port: PortInfo, ports: PortInfo[], attributes: [string, string][]): string | null {
  if (!port.less_than) return null;
  const own = numberOf(ports, attributes, port.name);
  const bound = numberOf(ports, attributes, port.less_than);
  if (!own || !bound) return null;
  const value = Number(own.text);
  const limit = Number(bound.text);
  if (!Number.isFinite(value) || !Number.isFinite(limit) || value < limit) return null;
  const unit = unitOf(port);
  const shown = (text: string) => `${toShown(unit, text)}${unit ? ` ${unit.shown}` : ''}`;
  return `${port.name} ${shown(own.text)} must be below ${port.less_than} (${shown(bound.text)})`;
}

/** Every parameter of the tree refused by its range or its bound, with its node's key: the first per node. */
export function rangeProblems(root: EditorNode | null, nodeInfo: (id: string) => NodeInfo | undefined): { key: string; id: string; message: string }[] {
  const found: { key: string; id: string; message: string }[] = [];
  const walk = (node: EditorNode) => {
    const info = nodeInfo(node.id);
    const ports = info?.ports ?? [];
    for (const port of ports) {
      const problem = rangeProblem(port, node.attributes.find(([k]) => k === port.name)?.[1]) ?? boundProblem(port, ports, node.attributes);
      if (problem) {
        found.push({ key: node.key, id: node.id, message: problem });
        break;
      }
    }
    node.children.forEach(walk);
  };
  if (root) walk(root);
  return found;
}
