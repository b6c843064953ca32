// Pane 4 and pane 7: the behavior tree as boxes and edges (the paper's Fig. 5, Groot2), with
// each node's live (or replayed) status. The canvas is React Flow (@xyflow/react: zoom, pan,
// fit, minimap); the layout is d3-hierarchy's tidy tree, recomputed from the plan on every
// change, so nodes are never placed by hand. Click selects, Shift+click selects a range of
// siblings, Ctrl+click adds to the selection, ▾ folds a subtree, dragging a box onto another
// moves it (onto its leading or trailing edge: before or after it; onto its middle: inside).

import { memo, useEffect, useMemo, useRef, useState } from 'react';
import {
  Background,
  Controls,
  Edge,
  Handle,
  MiniMap,
  Node,
  NodeProps,
  Position,
  ReactFlow,
  ReactFlowProvider,
  useReactFlow,
  useStore,
} from '@xyflow/react';
import '@xyflow/react/dist/style.css';
import type { NodeInfo } from '../api';
import type { DropPosition, EditorNode } from '../model/tree';
import { BOX, fitViewport, layout, Orientation } from '../model/layout';
import type { NodeStatus } from '../model/status';
import { parsePoseText } from '../model/poseText';

export type { Orientation };
export type SelectMode = 'single' | 'range' | 'toggle';

interface Props {
  root: EditorNode | null;
  nodeInfo: (id: string) => NodeInfo | undefined;
  selectedKey: string | null;
  selectedKeys: Set<string>;
  statuses: Map<string, NodeStatus>;
  problems: Map<string, string>;
  readOnly: boolean;
  orientation: Orientation;
  /** The run is paused: its running nodes show PAUSED, not RUNNING. */
  paused?: boolean;
  /** The node that runs now (kept in view while the run goes on), if it is in this tree. */
  runningKey?: string | null;
  /** A version comparison: added or changed nodes of this tree. */
  changes?: Map<string, 'added' | 'changed'>;
  onSelect: (key: string, mode: SelectMode) => void;
  onToggle: (key: string) => void;
  onMove: (key: string, target: string, position: DropPosition) => void;
  onDropNew: (id: string, target: string, position: DropPosition) => void;
  /** Changes when the whole tree should be fitted into the pane (the F key). */
  fitRequest?: number;
}



// The parameters that tell nodes of one type apart, in the order they are shown.
const SUMMARY_PORTS = ['waypoint', 'path', 'direction', 'force', 'object_class', 'target_class', 'target', 'predicates', 'grasp', 'predicate', 'args',
  'expected', 'num_cycles', 'num_attempts', 'num_resets', 'msec', 'ID', 'offset', 'pose', 'speed', 'mode', 'frame', 'joint', 'axis', 'amount', 'degrees', 'message'];

export function summary(node: EditorNode): string {
  const shown = node.attributes.filter(([k]) => k !== 'name' && SUMMARY_PORTS.includes(k));
  shown.sort((a, b) => SUMMARY_PORTS.indexOf(a[0]) - SUMMARY_PORTS.indexOf(b[0]));
  // The values alone where the type says what they are: a class, where it goes, the conditions.
  const bare = ['waypoint', 'object_class', 'predicates', 'direction'];
  const pose = (k: string, v: string) => {
    const f = parsePoseText(v);
    if (!f) return `${k}=${v}`;
    const turn = f.roll || f.pitch || f.yaw ? ` ${[f.roll, f.pitch, f.yaw].map((a) => Number(a.toFixed(1))).join(', ')}°` : '';
    return `${k} ${[f.x, f.y, f.z].map((a) => Number(a.toFixed(1))).join(', ')} mm${turn}`;
  };
  return shown
    .map(([k, v]) =>
      k === 'path' ? v.split(';').join(' → ') : k === 'force' ? `${v} N` : k === 'target_class' ? `on ${v}` : k === 'target' ? `at ${v}` : k === 'offset' || k === 'pose' ? pose(k, v) : bare.includes(k) ? v : `${k}=${v}`,
    )
    .join('  ');
}

interface BoxData extends Record<string, unknown> {
  node: EditorNode;
  info?: NodeInfo;
  status?: NodeStatus;
  problem?: string;
  selected: boolean;
  root: boolean;
  props: Props;
}

function dropPosition(e: React.DragEvent, orientation: Orientation, isRoot: boolean): DropPosition {
  const box = e.currentTarget.getBoundingClientRect();
  // Siblings stand below one another (left to right layout) or side by side (top down).
  const f = orientation === 'LR' ? (e.clientY - box.top) / box.height : (e.clientX - box.left) / box.width;
  if (isRoot) return 'inside';
  return f < 0.28 ? 'before' : f > 0.72 ? 'after' : 'inside';
}

const TreeBox = memo(function TreeBox({ data }: NodeProps<Node<BoxData>>) {
  const { node, info, status, problem, selected, root, props } = data;
  const [drop, setDrop] = useState<DropPosition | null>(null);
  const category = info?.category ?? 'unknown';
  const last = status?.last ?? 'IDLE';
  const running = status?.status === 'RUNNING';
  const name = node.attributes.find(([k]) => k === 'name')?.[1];
  const reason = last === 'FAILURE' ? status?.reason : undefined;
  const text = summary(node);
  const lr = props.orientation === 'LR';
  const paused = running && !!props.paused;
  const change = props.changes?.get(node.key);
  return (
    <div
      className={`tree-node cat-${category} status-${last.toLowerCase()} ${running ? (paused ? 'paused' : 'running') : ''} ${selected ? 'selected' : ''} ${
        props.selectedKey === node.key ? 'primary' : ''
      } ${problem ? 'problem' : ''} ${change ? `diff-${change}` : ''} ${drop ? `drop-${drop}-${props.orientation}` : ''} nopan`}
      style={{ width: BOX.width, height: BOX.height }}
      data-key={node.key}
      data-node-type={node.id}
      data-status={last}
      data-running={running ? 'true' : 'false'}
      data-paused={paused ? 'true' : 'false'}
      data-change={change ?? ''}
      title={[info?.description, reason && `FAILURE: ${reason}`, problem && `Check: ${problem}`].filter(Boolean).join('\n')}
      draggable={!props.readOnly && !root}
      onClick={(e) => props.onSelect(node.key, e.shiftKey ? 'range' : e.ctrlKey || e.metaKey ? 'toggle' : 'single')}
      onDragStart={(e) => {
        e.dataTransfer.setData('application/x-costar-move', node.key);
        e.dataTransfer.effectAllowed = 'move';
        e.stopPropagation();
      }}
      onDragOver={(e) => {
        if (props.readOnly) return;
        e.preventDefault();
        const position = dropPosition(e, props.orientation, root);
        if (position !== drop) setDrop(position);
      }}
      onDragLeave={() => setDrop(null)}
      onDrop={(e) => {
        e.preventDefault();
        e.stopPropagation();
        // Where the drop lands, not where the last drag-over said (its state may not have
        // been rendered yet when the drop follows it at once).
        const position = dropPosition(e, props.orientation, root);
        setDrop(null);
        const moving = e.dataTransfer.getData('application/x-costar-move');
        const fresh = e.dataTransfer.getData('application/x-costar-new');
        if (moving) props.onMove(moving, node.key, position);
        else if (fresh) props.onDropNew(fresh, node.key, position);
      }}
    >
      {!root && <Handle type="target" position={lr ? Position.Left : Position.Top} isConnectable={false} />}
      <div className="node-head">
        {node.children.length > 0 && (
          <button
            type="button"
            className="fold nodrag"
            aria-label={node.collapsed ? 'Unfold' : 'Fold'}
            title={node.collapsed ? 'Unfold' : 'Fold'}
            onClick={(e) => {
              e.stopPropagation();
              props.onToggle(node.key);
            }}
          >
            {node.collapsed ? '▸' : '▾'}
          </button>
        )}
        <span className="node-type">{node.id}</span>
        {name && <span className="node-name">“{name}”</span>}
        {node.collapsed && <span className="folded">+{node.children.length}</span>}
        {change && <span className={`badge badge-${change}`}>{change === 'added' ? 'NEW' : 'CHANGED'}</span>}
        {last !== 'IDLE' && (
          <span className={`badge badge-${running ? (paused ? 'paused' : 'running') : last.toLowerCase()}`}>
            {running ? (paused ? 'PAUSED' : 'RUNNING') : last}
          </span>
        )}
      </div>
      {reason ? (
        <div className="reason node-line">{reason}</div>
      ) : problem ? (
        <div className="reason node-line">{problem.startsWith(`${node.id}: `) ? problem.slice(node.id.length + 2) : problem}</div>
      ) : (
        text && <div className="node-summary node-line">{text}</div>
      )}
      {node.children.length > 0 && !node.collapsed && (
        <Handle type="source" position={lr ? Position.Right : Position.Bottom} isConnectable={false} />
      )}
    </div>
  );
});

const NODE_TYPES = { bt: TreeBox };

function Canvas(props: Props) {
  const flow = useReactFlow();
  const width = useStore((s) => s.width);
  const height = useStore((s) => s.height);
  const placed = useMemo(() => (props.root ? layout(props.root, props.orientation) : []), [props.root, props.orientation]);
  const nodes: Node<BoxData>[] = useMemo(
    () =>
      placed.map(({ node, x, y, parent }) => ({
        id: node.key,
        type: 'bt',
        position: { x, y },
        width: BOX.width,
        height: BOX.height,
        draggable: false,
        selectable: false,
        connectable: false,
        data: {
          node,
          info: props.nodeInfo(node.id),
          status: props.statuses.get(node.key),
          problem: props.problems.get(node.key),
          selected: props.selectedKeys.has(node.key) || props.selectedKey === node.key,
          root: parent === null,
          props,
        },
      })),
    [placed, props],
  );
  const edges: Edge[] = useMemo(
    () =>
      placed
        .filter((p) => p.parent)
        .map((p) => {
          const last = props.statuses.get(p.node.key)?.last;
          const running = props.statuses.get(p.node.key)?.status === 'RUNNING';
          return {
            id: `${p.parent}-${p.node.key}`,
            source: p.parent!,
            target: p.node.key,
            type: 'smoothstep',
            animated: running && !props.paused,
            className: running ? (props.paused ? 'edge-paused' : 'edge-running') : last ? `edge-${last.toLowerCase()}` : '',
          };
        }),
    [placed, props.statuses, props.paused],
  );

  // Fit the tree when it is shown, its shape or the pane's size changes, never below
  // MIN_FIT_ZOOM (the rest is a wheel away); then bring the selected node into view (new
  // nodes, keyboard).
  const rootKey = props.root?.key;
  const fitted = useRef<string>('');
  useEffect(() => {
    if (!width || !height || placed.length === 0) return;
    const id = `${rootKey}/${props.orientation}/${placed.length}/${width}x${height}`;
    if (fitted.current === id) return;
    fitted.current = id;
    void flow.setViewport(fitViewport(placed, width, height));
  }, [width, height, placed, rootKey, props.orientation, flow]);

  // The F key: the whole tree, however small.
  useEffect(() => {
    if (props.fitRequest) void flow.fitView({ padding: 0.04, duration: 150 });
  }, [props.fitRequest, flow]);

  // Bring a node into view (the selected one: new nodes, keyboard; the running one while a run
  // goes on), moving the view as little as needed.
  const bringIntoView = (key: string | null | undefined) => {
    if (!key || !width || !height) return;
    const p = placed.find((q) => q.node.key === key);
    if (!p) return;
    const { x, y, zoom } = flow.getViewport();
    const sx = p.x * zoom + x;
    const sy = p.y * zoom + y;
    const margin = 30;
    let nx = x;
    let ny = y;
    if (sx < margin) nx = x + (margin - sx);
    if (sx + BOX.width * zoom > width - margin) nx = x - (sx + BOX.width * zoom - (width - margin));
    if (sy < margin) ny = y + (margin - sy);
    if (sy + BOX.height * zoom > height - margin) ny = y - (sy + BOX.height * zoom - (height - margin));
    if (nx !== x || ny !== y) void flow.setViewport({ x: nx, y: ny, zoom }, { duration: 150 });
  };
  useEffect(() => {
    bringIntoView(props.selectedKey);
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [props.selectedKey, placed, width, height, flow]);
  useEffect(() => {
    bringIntoView(props.runningKey);
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [props.runningKey, placed, width, height, flow]);

  return (
    <ReactFlow
      nodes={nodes}
      edges={edges}
      nodeTypes={NODE_TYPES}
      nodesDraggable={false}
      nodesConnectable={false}
      elementsSelectable={false}
      panOnScroll
      zoomOnScroll={false}
      zoomOnPinch
      zoomOnDoubleClick={false}
      minZoom={0.2}
      maxZoom={2}
      deleteKeyCode={null}
      selectionKeyCode={null}
      multiSelectionKeyCode={null}
      proOptions={{ hideAttribution: true }}
      onDragOver={(e) => {
        if (!props.readOnly) e.preventDefault();
      }}
      onDrop={(e) => {
        // A new operation dropped on the empty canvas: into the root.
        e.preventDefault();
        const fresh = e.dataTransfer.getData('application/x-costar-new');
        if (fresh && props.root) props.onDropNew(fresh, props.root.key, 'inside');
      }}
    >
      <Background gap={24} size={1} />
      <Controls showInteractive={false} position="bottom-right" />
      <MiniMap pannable zoomable position="bottom-left" style={{ width: 130, height: 90 }} nodeStrokeWidth={2} nodeColor={(n) => minimapColour(n as Node<BoxData>)} />
    </ReactFlow>
  );
}

function minimapColour(n: Node<BoxData>): string {
  const status = n.data.status;
  if (status?.status === 'RUNNING') return n.data.props.paused ? '#5b7a99' : '#f0a500';
  if (status?.last === 'SUCCESS') return '#1f8f3a';
  if (status?.last === 'FAILURE') return '#c9302c';
  return { internal: '#3b73d1', robot_action: '#2f9e52', knowledge: '#8e55c9' }[n.data.info?.category ?? 'internal'] ?? '#999';
}

export function TreeCanvas(props: Props) {
  if (!props.root) return <p className="empty">This tree is empty: add an operation from the list.</p>;
  return (
    <ReactFlowProvider>
      <Canvas {...props} />
    </ReactFlowProvider>
  );
}
