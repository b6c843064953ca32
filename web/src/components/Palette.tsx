// Pane 6: the operations the system offers (GET /api/nodes, the same list as `costar nodes`),
// grouped by colour: internal nodes blue, robot actions green, knowledge purple. A click
// inserts the operation at the selection; dragging it onto a node puts it before, after or in it.

import { useMemo, useState } from 'react';
import type { NodeInfo } from '../api';

const GROUPS: { category: NodeInfo['category']; title: string }[] = [
  { category: 'internal', title: 'Control flow' },
  { category: 'robot_action', title: 'Robot actions' },
  { category: 'knowledge', title: 'Knowledge' },
];

interface Props {
  nodes: NodeInfo[];
  disabled: boolean;
  /** Inserts the operation at the selection (after the selected node, or inside it). */
  onAdd: (id: string) => void;
}

export function Palette({ nodes, disabled, onAdd }: Props) {
  const [filter, setFilter] = useState('');
  const shown = useMemo(() => {
    const f = filter.trim().toLowerCase();
    return nodes.filter((n) => !f || n.id.toLowerCase().includes(f) || n.description.toLowerCase().includes(f));
  }, [nodes, filter]);
  return (
    <section className="pane palette" aria-label="Operations">
      <h2>
        <span className="pane-number">6</span> Operations
      </h2>
      <input
        className="filter"
        placeholder="Filter…"
        value={filter}
        onChange={(e) => setFilter(e.target.value)}
        aria-label="Filter operations"
      />
      <div className="palette-list">
        {GROUPS.map(({ category, title }) => {
          const items = shown.filter((n) => n.category === category);
          if (items.length === 0) return null;
          return (
            <div key={category}>
              <h3>{title}</h3>
              {items.map((n) => (
                <button
                  key={n.id}
                  type="button"
                  className={`palette-item cat-${n.category}`}
                  disabled={disabled}
                  data-node-type={n.id}
                  title={n.description}
                  draggable
                  onDragStart={(e) => {
                    e.dataTransfer.setData('application/x-costar-new', n.id);
                    e.dataTransfer.effectAllowed = 'copy';
                  }}
                  onClick={() => onAdd(n.id)}
                >
                  {n.id}
                </button>
              ))}
            </div>
          );
        })}
      </div>
    </section>
  );
}
