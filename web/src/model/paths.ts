// Paths offered whole: waypoints taught as one path share a name up to their last '_' (row1_start,
// row1_end; bend_b_10 … bend_b_90, bend_b_over, bend_b_done). The cell lists its waypoints by
// name, so a path's order is read from the names: start first, then the numbered ones in number
// order, the other names as they sort, end and done last.

export interface WaypointPath {
  /** The shared prefix with its '_': 'row1_'. */
  prefix: string;
  waypoints: string[];
}

const FIRST = ['start', 'begin', 'first'];
const LAST = ['end', 'done', 'finish', 'last'];

function rank(suffix: string): [number, number, string] {
  if (FIRST.includes(suffix)) return [0, 0, suffix];
  if (LAST.includes(suffix)) return [3, LAST.indexOf(suffix), suffix];
  if (/^\d+$/.test(suffix)) return [1, Number(suffix), suffix];
  return [2, 0, suffix];
}

function compare(a: string, b: string): number {
  const [ra, rb] = [rank(a), rank(b)];
  return ra[0] - rb[0] || ra[1] - rb[1] || (ra[2] < rb[2] ? -1 : ra[2] > rb[2] ? 1 : 0);
}

/** The paths among these waypoint names: two or more sharing a prefix, each in path order. */
export function waypointPaths(names: string[]): WaypointPath[] {
  const groups = new Map<string, string[]>();
  for (const name of names) {
    const cut = name.lastIndexOf('_');
    if (cut <= 0 || cut === name.length - 1) continue;
    const prefix = name.slice(0, cut + 1);
    groups.set(prefix, [...(groups.get(prefix) ?? []), name]);
  }
  return [...groups.entries()]
    .filter(([, members]) => members.length >= 2)
    .map(([prefix, members]) => ({
      prefix,
      waypoints: [...members].sort((a, b) => compare(a.slice(prefix.length), b.slice(prefix.length))),
    }))
    .sort((a, b) => (a.prefix < b.prefix ? -1 : a.prefix > b.prefix ? 1 : 0));
}

/** The kinds of a predicate's arguments, from its description's signature ("force_above(N): …"). */
export type ArgumentKind = 'number' | 'waypoint' | 'reference';

export function argumentKinds(description: string, arity: number): ArgumentKind[] {
  const names = /^\s*\w+\(([^)]*)\)/.exec(description)?.[1].split(',').map((a) => a.trim()) ?? [];
  return Array.from({ length: arity }, (_, i) => {
    const name = names[i] ?? '';
    if (name === 'N') return 'number';
    if (name === 'w') return 'waypoint';
    return 'reference';
  });
}

/**
 * The words each argument takes when the description's signature quotes them ('a'|'b'):
 * gesture('hand_1', 'offer'), in_zone('hand_1', 'handover'). null: any reference.
 */
export function argumentWords(description: string, arity: number): (string[] | null)[] {
  const names = /^\s*\w+\(([^)]*)\)/.exec(description)?.[1].split(',').map((a) => a.trim()) ?? [];
  return Array.from({ length: arity }, (_, i) => {
    const words = (names[i] ?? '').split('|').map((w) => /^'([^']+)'$/.exec(w.trim())?.[1]);
    return words.length > 0 && words.every((w) => w !== undefined) ? (words as string[]) : null;
  });
}
