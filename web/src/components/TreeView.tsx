// Pane 4 and pane 7: the behavior tree being edited, with each node's live (or replayed) status.
// Click selects, the triangle folds a subtree, drag moves a node (drop on the top or bottom
// edge of another node: before or after it; on its middle: inside it).

import { useState } from 'react';
import type { NodeInfo } from '../api';
import type { DropPosition, EditorNode } from '../model/tree';
import type { NodeStatus } from '../model/status';

interface Props {
  root: EditorNode | null;
  nodeInfo: (id: string) => NodeInfo | undefined;
  selectedKey: string | null;
  statuses: Map<string, NodeStatus>;
  problems: Map<string, string>;
  readOnly: boolean;
  onSelect: (key: string) => void;
  onToggle: (key: string) => void;
  onMove: (key: string, target: string, position: DropPosition) => void;
  onDropNew: (id: string, target: string, position: DropPosition) => void;
}

const SUMMARY_PORTS = ['waypoint', 'object_class', 'predicate', 'predicates', 'target', 'grasp', 'num_cycles',
  'num_resets', 'num_attempts', 'msec', 'ID', 'args', 'speed', 'mode', 'joint', 'axis', 'amount', 'degrees'];

function summary(node: EditorNode): string {
  return node.attributes
    .filter(([k]) => k !== 'name' && SUMMARY_PORTS.includes(k))
    .map(([k, v]) => `${k}=${v}`)
    .join('  ');
}

export function TreeView(props: Props) {
  const [drop, setDrop] = useState<{ key: string; position: DropPosition } | null>(null);
  if (!props.root) return <p className="empty">This tree is empty: add an operation from the list.</p>;

  const render = (node: EditorNode, depth: number) => {
    const info = props.nodeInfo(node.id);
    const category = info?.category ?? 'unknown';
    const status = props.statuses.get(node.key);
    const last = status?.last ?? 'IDLE';
    const running = status?.status === 'RUNNING';
    const problem = props.problems.get(node.key);
    const name = node.attributes.find(([k]) => k === 'name')?.[1];
    const dropHere = drop?.key === node.key ? `drop-${drop.position}` : '';
    return (
      <li key={node.key}>
        <div
          className={`tree-node cat-${category} status-${last.toLowerCase()} ${running ? 'running' : ''} ${
            props.selectedKey === node.key ? 'selected' : ''
          } ${problem ? 'problem' : ''} ${dropHere}`}
          data-key={node.key}
          data-node-type={node.id}
          data-status={last}
          data-running={running ? 'true' : 'false'}
          draggable={!props.readOnly && depth > 0}
          onClick={() => props.onSelect(node.key)}
          onDragStart={(e) => {
            e.dataTransfer.setData('application/x-costar-move', node.key);
            e.dataTransfer.effectAllowed = 'move';
            e.stopPropagation();
          }}
          onDragOver={(e) => {
            if (props.readOnly) return;
            e.preventDefault();
            const box = e.currentTarget.getBoundingClientRect();
            const y = (e.clientY - box.top) / box.height;
            const position: DropPosition = y < 0.3 && depth > 0 ? 'before' : y > 0.7 && depth > 0 ? 'after' : 'inside';
            if (drop?.key !== node.key || drop.position !== position) setDrop({ key: node.key, position });
          }}
          onDragLeave={() => setDrop(null)}
          onDrop={(e) => {
            e.preventDefault();
            const position = drop?.position ?? 'inside';
            setDrop(null);
            const moving = e.dataTransfer.getData('application/x-costar-move');
            const fresh = e.dataTransfer.getData('application/x-costar-new');
            if (moving) props.onMove(moving, node.key, position);
            else if (fresh) props.onDropNew(fresh, node.key, position);
          }}
        >
          {node.children.length > 0 ? (
            <button
              type="button"
              className="fold"
              aria-label={node.collapsed ? 'Unfold' : 'Fold'}
              onClick={(e) => {
                e.stopPropagation();
                props.onToggle(node.key);
              }}
            >
              {node.collapsed ? '▸' : '▾'}
            </button>
          ) : (
            <span className="fold-space" />
          )}
          <span className="node-type">{node.id}</span>
          {name && <span className="node-name">“{name}”</span>}
          <span className="node-summary">{summary(node)}</span>
          {node.collapsed && <span className="folded">({node.children.length} hidden)</span>}
          {last !== 'IDLE' && <span className={`badge badge-${last.toLowerCase()}`}>{running ? 'RUNNING' : last}</span>}
          {status?.status === 'FAILURE' || (last === 'FAILURE' && status?.reason) ? (
            <span className="reason" title={status?.origin}>
              {status?.reason}
            </span>
          ) : null}
          {problem && <span className="reason">{problem}</span>}
        </div>
        {node.children.length > 0 && !node.collapsed && (
          <ul>{node.children.map((child) => render(child, depth + 1))}</ul>
        )}
      </li>
    );
  };
  return <ul className="tree-root">{render(props.root, 0)}</ul>;
}
