// Pane 1: the objects the system knows (detected parts), and for a selected SmartMove node the
// candidates it considered: each part x symmetry with its cost, or why it was rejected.

import type { CellState, ObjectShape } from '../api';
import { cssColour, PartLook, partLook } from '../model/parts';
import { Believed, whereFrom } from '../model/belief';

export interface Candidate {
  object: string;
  symmetry: number;
  goal: [number, number, number];
  cost?: number;
  rejected?: string;
  chosen: boolean;
}

export interface SmartMoveData {
  candidates?: Candidate[];
  chosen?: string;
  failure?: string;
  seconds?: number;
}

export function candidatesOf(data: unknown): SmartMoveData | null {
  if (!data || typeof data !== 'object') return null;
  const d = data as SmartMoveData;
  return Array.isArray(d.candidates) ? d : null;
}

interface Props {
  state: CellState | null;
  selectedType: string | null;
  data: SmartMoveData | null;
  shapes?: Record<string, ObjectShape>;
  believed?: Believed;
}

/** Feasible candidates by cost, the chosen one first; rejected ones grouped by their reason. */
export function groupCandidates(candidates: Candidate[]) {
  const feasible = candidates
    .filter((c) => !c.rejected)
    .sort((a, b) => Number(b.chosen) - Number(a.chosen) || (a.cost ?? Infinity) - (b.cost ?? Infinity));
  const groups = new Map<string, Candidate[]>();
  for (const c of candidates) {
    if (!c.rejected) continue;
    const list = groups.get(c.rejected) ?? [];
    list.push(c);
    groups.set(c.rejected, list);
  }
  const rejected = [...groups.entries()]
    .map(([reason, list]) => ({ reason, candidates: list }))
    .sort((a, b) => b.candidates.length - a.candidates.length);
  return { feasible, rejected };
}

function CandidateTable({ data, known }: { data: SmartMoveData; known: Set<string> }) {
  const { feasible, rejected } = groupCandidates(data.candidates ?? []);
  const label = (c: Candidate) => `${c.object}${c.symmetry ? ` ↻${c.symmetry}` : ''}`;
  const gone = (c: Candidate) => !known.has(c.object) && !c.object.startsWith('table(') && known.size > 0;
  return (
    <>
      <table>
        <thead>
          <tr>
            <th>candidate</th>
            <th>cost</th>
            <th></th>
          </tr>
        </thead>
        <tbody>
          {feasible.map((c, i) => (
            <tr key={i} className={c.chosen ? 'chosen' : ''}>
              <td>
                {label(c)}
                {gone(c) && <span className="dim"> (not known now)</span>}
              </td>
              <td>{c.cost !== undefined ? c.cost.toFixed(3) : ''}</td>
              <td>{c.chosen ? '✓ chosen' : 'feasible'}</td>
            </tr>
          ))}
        </tbody>
      </table>
      {rejected.map((group) => (
        <details key={group.reason} className="rejected-group">
          <summary className="group">
            {group.candidates.length} rejected: {group.reason}
          </summary>
          <p className="dim">{[...new Set(group.candidates.map((c) => c.object))].join(', ')}</p>
        </details>
      ))}
    </>
  );
}

/** The colour a part is drawn in (pane 2): the one perception saw on it, else its class's. */
function Swatch({ look }: { look: PartLook }) {
  const title =
    look.colorFrom === 'seen'
      ? `the colour DetectObjects saw on it${look.colorName ? ` (nearest of the class's colours: ${look.colorName})` : ''}`
      : look.colorFrom === 'class'
        ? `drawn in the class's colour ${look.colorName} (the class comes in ${look.colorNames.join(', ')}; no colour was reported for this part)`
        : 'the server did not describe this class: drawn grey';
  return <span className="swatch" style={{ background: cssColour(look.rgb) }} title={title} />;
}

export function ObjectsPane({ state, selectedType, data, shapes, believed }: Props) {
  const objects = state?.objects ?? [];
  const smart = selectedType !== null && selectedType.startsWith('Smart');
  return (
    <section className="pane objects" aria-label="Objects and SmartMoves">
      <h2>
        <span className="pane-number">1</span> Objects{smart ? ` · ${selectedType} candidates` : ''}
      </h2>
      {objects.length === 0 ? (
        <p className="empty">No objects known yet{state ? '' : ' (not connected)'}: run DetectObjects to see the parts.</p>
      ) : (
        <table className="objects-table">
          <thead>
            <tr>
              <th>object</th>
              <th>class</th>
              <th>x, y, z (m)</th>
            </tr>
          </thead>
          <tbody>
            {objects.map((o) => (
              <tr key={o.name}>
                <td>{o.name}</td>
                <td>
                  <Swatch look={partLook(o.class, shapes, o.color)} />
                  {o.class}
                </td>
                <td>
                  {(believed?.poses.get(o.name) ?? o).p.map((v) => v.toFixed(3)).join(', ')}
                  {believed && whereFrom(believed, o.name) !== 'detected' && (
                    <span className="dim" title="where the system believes it is: it moves with the tool while held, and stays where it was put until a detection sees it again">
                      {' '}
                      ({whereFrom(believed, o.name)})
                    </span>
                  )}
                </td>
              </tr>
            ))}
          </tbody>
        </table>
      )}
      {smart && !data && <p className="empty">Run the plan to see this SmartMove's candidates.</p>}
      {smart && data && (
        <div className="candidates">
          <p>
            {data.chosen ? (
              <>
                chose <b>{data.chosen}</b>
              </>
            ) : (
              <span className="reason">{data.failure ?? 'no candidate chosen'}</span>
            )}
            {data.seconds !== undefined && ` in ${(data.seconds * 1000).toFixed(1)} ms`}
          </p>
          <CandidateTable data={data} known={new Set(objects.map((o) => o.name))} />
        </div>
      )}
      {state && state.predicates.length > 0 && (
        <details className="predicates">
          <summary>{state.predicates.length} predicate(s) hold</summary>
          <ul>
            {state.predicates.slice(0, 300).map((p) => (
              <li key={p}>{p}</li>
            ))}
          </ul>
        </details>
      )}
    </section>
  );
}
