// Pane 6: the operations the system offers (GET /api/nodes, the same list as `costar nodes`).
// It opens on what the robot does (robot actions green, knowledge purple); control flow (blue)
// comes after, its everyday nodes in view and the rest folded in groups that say what they are
// for. A click inserts the operation at the selection; dragging it onto a node puts it before,
// after or in it. Every entry's tooltip is its description.

import { Fragment, useMemo, useState } from 'react';
import type { NodeInfo } from '../api';

/**
 * Control flow a plan uses most, and the paper's own (CoSTAR's Iterator and RESET, the guard a
 * RESET watches: a ReactiveSequence): always in view.
 */
const EVERYDAY = ['Sequence', 'Fallback', 'ReactiveSequence', 'Iterator', 'Reset', 'Repeat', 'RetryUntilSuccessful'];

/** The rest of the control flow, by what it is for. */
const CONTROL_GROUPS: { title: string; about: string; kinds: NodeInfo['kind'][] }[] = [
  { title: 'Order and choice', about: 'children one after another, side by side, or the first that works', kinds: ['Control'] },
  { title: 'Loops, retries, timing', about: 'one child: repeat it, retry it, limit or delay it, change its result', kinds: ['Decorator'] },
  { title: 'Other', about: 'subtrees, waits, fixed results', kinds: ['Action', 'Condition', 'SubTree'] },
];

/** A CamelCase name that may wrap between its words (never clipped). */
function wrappable(id: string) {
  const words = id.split(/(?=[A-Z][a-z])/);
  return words.map((word, i) => (
    <Fragment key={i}>
      {i > 0 && <wbr />}
      {word}
    </Fragment>
  ));
}

interface Props {
  nodes: NodeInfo[];
  /** Why nothing can be inserted now (replaying a run), or null. */
  disabledReason: string | null;
  /** Inserts the operation at the selection (after the selected node, or inside it). */
  onAdd: (id: string) => void;
}

export function Palette({ nodes, disabledReason, onAdd }: Props) {
  const [filter, setFilter] = useState('');
  const shown = useMemo(() => {
    const f = filter.trim().toLowerCase();
    return nodes.filter((n) => !n.unavailable && (!f || n.id.toLowerCase().includes(f) || n.description.toLowerCase().includes(f)));
  }, [nodes, filter]);
  // What the cell's own components refuse whatever the plan (its gripper's modes): named apart.
  const unavailable = nodes.filter((n) => n.unavailable);
  const item = (n: NodeInfo) => (
    <button
      key={n.id}
      type="button"
      className={`palette-item cat-${n.category}`}
      disabled={disabledReason !== null}
      data-node-type={n.id}
      title={disabledReason ?? n.description}
      draggable
      onDragStart={(e) => {
        e.dataTransfer.setData('application/x-costar-new', n.id);
        e.dataTransfer.effectAllowed = 'copy';
      }}
      onClick={() => onAdd(n.id)}
    >
      {wrappable(n.id)}
    </button>
  );
  const robot = shown.filter((n) => n.category === 'robot_action');
  const knowledge = shown.filter((n) => n.category === 'knowledge');
  const control = shown.filter((n) => n.category === 'internal');
  const everyday = EVERYDAY.map((id) => control.find((n) => n.id === id)).filter((n): n is NodeInfo => !!n);
  const searching = filter.trim() !== '';
  return (
    <section className="pane palette" aria-label="Operations">
      <h2>
        <span className="pane-number">6</span> Operations
      </h2>
      <input className="filter" placeholder="Filter…" value={filter} onChange={(e) => setFilter(e.target.value)} aria-label="Filter operations" />
      <div className="palette-list">
        {robot.length > 0 && (
          <div>
            <h3 title="what the arm and the gripper do">Robot actions</h3>
            {robot.map(item)}
            {unavailable.length > 0 && (
              <p className="hint unavailable" title={[...new Set(unavailable.map((n) => n.unavailable))].join('\n')}>
                Not on this cell: {unavailable.map((n) => n.id).join(', ')} ({unavailable[0].unavailable})
              </p>
            )}
          </div>
        )}
        {knowledge.length > 0 && (
          <div>
            <h3 title="look at the table, check what holds, remember">Knowledge</h3>
            {knowledge.map(item)}
          </div>
        )}
        {control.length > 0 && (
          <div>
            <h3 title="how the steps are put together">Control flow</h3>
            {everyday.map(item)}
            {CONTROL_GROUPS.map((group) => {
              const items = control.filter((n) => group.kinds.includes(n.kind) && !EVERYDAY.includes(n.id));
              if (items.length === 0) return null;
              return (
                <details key={group.title} className="palette-group" open={searching}>
                  <summary title={group.about}>
                    {group.title} <span className="count">{items.length}</span>
                    <span className="about">{group.about}</span>
                  </summary>
                  {items.map(item)}
                </details>
              );
            })}
          </div>
        )}
      </div>
    </section>
  );
}
