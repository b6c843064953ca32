// The task editor (the paper's Fig. 5): 1 objects and SmartMove candidates, 2 the cell in 3D,
// 3 waypoints, 4 the tree workspace, 5 customise the selected operation, 6 the operations,
// 7 live execution and replay, 8 the menu of quick actions.

import { useCallback, useEffect, useMemo, useRef, useState } from 'react';
import { Api, ApiError, CellState, Choices, Diagnostic, Info, NodeInfo, RunInfo, RunLog } from './api';
import { Stream, StreamMessage } from './stream';
import { readToken, storeToken } from './token';
import * as T from './model/tree';
import { EditorPlan } from './model/tree';
import { canRedo, canUndo, History, push, redo, replace, startHistory, undo } from './model/history';
import { mapRun, mergeStatuses, NodeRef, NodeStatus, statusesAt, statusesByKey } from './model/status';
import { Palette } from './components/Palette';
import { TreeView } from './components/TreeView';
import { NodeEditor } from './components/NodeEditor';
import { candidatesOf, ObjectsPane } from './components/ObjectsPane';
import { Waypoints } from './components/Waypoints';
import { View3D } from './components/View3D';
import { Replay } from './components/Replay';

interface LiveRun {
  run: RunInfo;
  statuses: Map<number, NodeStatus>;
  mapping: Map<number, NodeRef>;
}

interface OperationState {
  id: number;
  label: string;
  active: boolean;
  result?: string;
  reason?: string;
}

interface ReplayState {
  log: RunLog;
  plan: EditorPlan;
  mapping: Map<number, NodeRef>;
  index: number;
}

type Message = { text: string; kind: 'info' | 'error' } | null;

const NAME_PATTERN = /^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$/;

export function App() {
  const [token, setToken] = useState(readToken);
  const api = useMemo(() => new Api(token), [token]);
  const [info, setInfo] = useState<Info | null>(null);
  const [nodes, setNodes] = useState<NodeInfo[]>([]);
  const [choices, setChoices] = useState<Choices | null>(null);
  const [cell, setCell] = useState<CellState | null>(null);
  const [connected, setConnected] = useState(false);

  const [history, setHistory] = useState<History<EditorPlan>>(() => startHistory(T.emptyPlan()));
  const plan = history.present;
  const [treeId, setTreeId] = useState('main');
  const [selectedKey, setSelectedKey] = useState<string | null>(() => plan.trees[0].root?.key ?? null);
  const [paletteType, setPaletteType] = useState<string | null>(null);
  const [planName, setPlanName] = useState('');
  const [saved, setSaved] = useState<{ name: string; plan: EditorPlan; version: number } | null>(null);
  const [savedPlans, setSavedPlans] = useState<{ name: string; latest_version: number }[]>([]);
  const [savedSubtrees, setSavedSubtrees] = useState<{ name: string }[]>([]);
  const [subtreeChoice, setSubtreeChoice] = useState('');
  const [diagnostics, setDiagnostics] = useState<Diagnostic[]>([]);
  const [message, setMessage] = useState<Message>(null);

  const [live, setLive] = useState<LiveRun | null>(null);
  const [operation, setOperation] = useState<OperationState | null>(null);
  const [replay, setReplay] = useState<ReplayState | null>(null);
  const [runsRefresh, setRunsRefresh] = useState(0);

  const planRef = useRef(plan);
  planRef.current = plan;
  const nodeInfo = useCallback((id: string) => nodes.find((n) => n.id === id), [nodes]);
  const kindOf = useCallback((id: string) => nodeInfo(id)?.kind, [nodeInfo]);

  const fail = (e: unknown) => {
    const error = e as ApiError;
    setMessage({ text: error.message, kind: 'error' });
    if (error.diagnostics?.length) setDiagnostics(error.diagnostics);
  };

  const refreshLists = useCallback(() => {
    api.choices().then(setChoices, () => undefined);
    api.plans().then(setSavedPlans, () => undefined);
    api.subtrees().then(setSavedSubtrees, () => undefined);
  }, [api]);

  // --- connection --------------------------------------------------------------------------
  useEffect(() => {
    api.info().then(setInfo, fail);
    api.nodes().then(setNodes, fail);
    refreshLists();
    const stream = new Stream(token, {
      onConnection: setConnected,
      onMessage: (m: StreamMessage) => {
        switch (m.type) {
          case 'hello':
            setInfo(m.info);
            setCell(m.state);
            if (m.run && m.run.kind === 'plan' && m.run.nodes) {
              setLive({
                run: m.run,
                statuses: new Map((m.run.statuses ?? []).map((s) => [s.uid, s])),
                mapping: mapRun(planRef.current, m.run.nodes),
              });
            }
            break;
          case 'state':
            setCell(m as CellState);
            break;
          case 'run_started':
            if (m.run.kind === 'plan') {
              setLive({ run: m.run, statuses: new Map(), mapping: mapRun(planRef.current, m.run.nodes ?? []) });
            } else {
              setOperation({ id: m.run.id, label: m.run.label, active: true });
            }
            break;
          case 'statuses':
            setLive((l) => (l && l.run.id === m.run ? { ...l, statuses: mergeStatuses(l.statuses, m.nodes) } : l));
            break;
          case 'run_ended':
            setLive((l) => (l && l.run.id === m.run.id ? { ...l, run: { ...l.run, ...m.run, active: false } } : l));
            setOperation((o) =>
              o && o.id === m.run.id ? { ...o, active: false, result: m.run.result, reason: m.run.failure_reason } : o,
            );
            if (m.run.kind === 'plan') setRunsRefresh((x) => x + 1);
            else api.choices().then(setChoices, () => undefined);
            break;
          default:
            break;
        }
      },
    });
    return () => stream.close();
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [api, token]);

  // --- editing -------------------------------------------------------------------------------
  const edit = (change: (p: EditorPlan) => EditorPlan, select?: string | null) => {
    try {
      const next = change(plan);
      setHistory(push(history, next));
      if (select !== undefined) setSelectedKey(select);
      setMessage(null);
    } catch (e) {
      setMessage({ text: (e as Error).message, kind: 'error' });
    }
  };

  const addNode = (type: string | null, mode: 'child' | 'sibling') => {
    if (!type) {
      setMessage({ text: 'Choose an operation in the list first.', kind: 'error' });
      return;
    }
    const node = T.makeNode(type);
    const tree = T.findTree(plan, treeId);
    if (mode === 'sibling' && selectedKey && tree?.root?.key !== selectedKey) {
      edit((p) => T.addSibling(p, treeId, selectedKey, node, kindOf), node.key);
    } else {
      edit((p) => T.addChild(p, treeId, selectedKey, node, kindOf), node.key);
    }
  };

  const tree = T.findTree(replay ? replay.plan : plan, treeId) ?? T.findTree(replay ? replay.plan : plan, (replay ? replay.plan : plan).mainTree);
  const selected = tree && selectedKey ? T.locate(tree.root, selectedKey)?.node ?? null : null;
  const dirty = !saved || saved.name !== planName || !T.samePlan(saved.plan, plan);
  const running = (live?.run.active ?? false) || (operation?.active ?? false);
  const paused = cell?.mode === 'paused';

  useEffect(() => {
    const onKey = (e: KeyboardEvent) => {
      const target = e.target as HTMLElement;
      if (target && ['INPUT', 'SELECT', 'TEXTAREA'].includes(target.tagName)) return;
      if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'z') {
        e.preventDefault();
        setHistory(e.shiftKey ? redo(history) : undo(history));
      } else if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'y') {
        e.preventDefault();
        setHistory(redo(history));
      } else if (e.key === 'Delete' && selectedKey && !replay) {
        edit((p) => T.removeNode(p, treeId, selectedKey), null);
      }
    };
    window.addEventListener('keydown', onKey);
    return () => window.removeEventListener('keydown', onKey);
  });

  // --- files ---------------------------------------------------------------------------------
  const loadPlan = (json: ReturnType<typeof T.toPlanJson>, name: string, version?: number) => {
    const next = T.fromPlanJson(json);
    setHistory(startHistory(next));
    setTreeId(next.mainTree);
    setSelectedKey(T.findTree(next, next.mainTree)?.root?.key ?? null);
    setPlanName(name);
    setSaved(version ? { name, plan: next, version } : null);
    setDiagnostics([]);
    setReplay(null);
  };

  const save = async (): Promise<{ name: string; version: number } | null> => {
    if (!NAME_PATTERN.test(planName)) {
      setMessage({ text: 'Give the plan a name: letters, digits, _ and - (it is not a path).', kind: 'error' });
      return null;
    }
    try {
      const result = await api.savePlan(planName, T.toPlanJson(plan));
      setSaved({ name: planName, plan, version: result.version });
      setDiagnostics([]);
      setMessage({ text: `Saved ${result.name} version ${result.version}.`, kind: 'info' });
      refreshLists();
      return result;
    } catch (e) {
      fail(e);
      return null;
    }
  };

  const run = async (startPaused = false) => {
    setReplay(null);
    try {
      let started: { run: number };
      if (planName) {
        let version = saved?.version;
        if (dirty) {
          const result = await save();
          if (!result) return;
          version = result.version;
        }
        started = await api.runSaved(planName, version, startPaused);
      } else {
        started = await api.runPlan(T.toPlanJson(plan), startPaused);
      }
      setMessage({ text: `Run #${started.run} started.`, kind: 'info' });
      setDiagnostics([]);
    } catch (e) {
      fail(e);
    }
  };

  const runOperation = async (node: string, attributes: Record<string, string> = {}) => {
    try {
      const started = await api.operation(node, attributes);
      // The stream may have reported its start and end already: keep what it said.
      setOperation((o) => (o && o.id === started.run ? o : { id: started.run, label: node, active: true }));
    } catch (e) {
      fail(e);
    }
  };

  const control = (action: 'pause' | 'resume' | 'step' | 'stop') => api.control(action).catch(fail);

  const exportXml = async () => {
    try {
      const result = await api.validate(T.toPlanJson(plan));
      const blob = new Blob([result.xml], { type: 'application/xml' });
      const link = document.createElement('a');
      link.href = URL.createObjectURL(blob);
      link.download = `${planName || 'plan'}.xml`;
      link.click();
      URL.revokeObjectURL(link.href);
    } catch (e) {
      fail(e);
    }
  };

  const importXml = async (file: File) => {
    try {
      const text = await file.text();
      const result = await api.convertXml(text);
      const name = file.name.replace(/\.xml$/i, '').replace(/[^A-Za-z0-9_-]/g, '_').slice(0, 64);
      loadPlan(result.plan, name);
      setDiagnostics(result.diagnostics);
      setMessage({
        text: result.valid ? `Imported ${file.name} (not saved yet).` : `Imported ${file.name}: ${result.diagnostics.length} problem(s).`,
        kind: result.valid ? 'info' : 'error',
      });
    } catch (e) {
      fail(e);
    }
  };

  const saveSubtree = async () => {
    if (!selected) return;
    const name = prompt('Save the selected subtree as (letters, digits, _ and -):', T.attribute(selected, 'name')?.replace(/[^A-Za-z0-9_-]/g, '_') ?? '');
    if (!name) return;
    try {
      const result = await api.saveSubtree(name, { main_tree: name, trees: [{ id: name, root: T.nodeToJson(selected) }] });
      setMessage({ text: `Saved subtree ${name} version ${result.version}.`, kind: 'info' });
      refreshLists();
    } catch (e) {
      fail(e);
    }
  };

  const insertSubtree = async (asReference: boolean) => {
    if (!subtreeChoice) return;
    try {
      const doc = await api.subtree(subtreeChoice);
      const root = T.nodeFromJson(doc.plan.trees[0].root);
      if (asReference) {
        const node = T.makeNode('SubTree', [['ID', subtreeChoice]]);
        edit((p) => T.addChild(T.putTree(p, { id: subtreeChoice, root }), treeId, selectedKey, node, kindOf), node.key);
      } else {
        edit((p) => T.addChild(p, treeId, selectedKey, root, kindOf), root.key);
      }
    } catch (e) {
      fail(e);
    }
  };

  // --- what the panes show ---------------------------------------------------------------------
  const replayStatuses = useMemo(
    () => (replay ? statusesAt(replay.log.transition_list, replay.index) : null),
    [replay],
  );
  const shownStatuses = useMemo(() => {
    if (replay && replayStatuses) return statusesByKey(replayStatuses, replay.mapping, tree?.id ?? treeId);
    if (live) return statusesByKey(live.statuses, live.mapping, tree?.id ?? treeId);
    return new Map<string, NodeStatus>();
  }, [replay, replayStatuses, live, tree, treeId]);
  const problems = useMemo(() => {
    const map = new Map<string, string>();
    for (const d of diagnostics) {
      if (d.node && d.node.tree === tree?.id) {
        const node = T.nodeAtPath(tree.root, d.node.path);
        if (node) map.set(node.key, d.message);
      }
    }
    return map;
  }, [diagnostics, tree]);
  const selectedData = selected ? candidatesOf(shownStatuses.get(selected.key)?.data) : null;
  const waypointChoices = useMemo(() => {
    const names = new Set([...(choices?.waypoint ?? []), ...(cell?.waypoints.map((w) => w.name) ?? [])]);
    return choices ? { ...choices, waypoint: [...names].sort() } : null;
  }, [choices, cell]);

  const runLabel = live
    ? `Run #${live.run.id}${live.run.plan ? ` (${live.run.plan}${live.run.version ? ` v${live.run.version}` : ''})` : ''}: ${
        live.run.active ? (paused ? 'PAUSED' : 'RUNNING') : live.run.result
      }${live.run.failure_reason ? ` at ${live.run.failure_path}: ${live.run.failure_reason}` : ''}`
    : 'Nothing has run yet.';

  return (
    <div className="app">
      {/* 8: the menu, with plan files and the run controls (7) */}
      <header className="menu" aria-label="Menu">
        <span className="brand">costar</span>
        <span className="pane-number">8</span>
        {info?.features.detect && (
          <button type="button" disabled={running} onClick={() => runOperation(info.features.detect_node)}>
            Detect objects
          </button>
        )}
        {info?.features.calibrate && (
          <button type="button" disabled={running} onClick={() => runOperation(info.features.calibrate_node)}>
            Calibrate
          </button>
        )}
        <button type="button" disabled={running} onClick={() => runOperation('Home')}>
          Home
        </button>
        <button type="button" disabled={running} onClick={() => runOperation('Open')}>
          Open gripper
        </button>
        <button type="button" disabled={running} onClick={() => runOperation('Close')}>
          Close gripper
        </button>
        <span className="separator" />
        <input
          className="plan-name"
          aria-label="plan name"
          placeholder="plan name"
          value={planName}
          onChange={(e) => setPlanName(e.target.value)}
        />
        <button type="button" onClick={save} disabled={!!replay}>
          Save{dirty && planName ? ' *' : ''}
        </button>
        <select
          aria-label="load plan"
          value=""
          onChange={async (e) => {
            const name = e.target.value;
            if (!name) return;
            if (dirty && T.countNodes(plan) > 1 && !confirm('Discard the changes to this plan?')) return;
            try {
              const doc = await api.plan(name);
              loadPlan(doc.plan, doc.name, doc.version);
              setMessage({ text: `Loaded ${doc.name} version ${doc.version}.`, kind: 'info' });
            } catch (err) {
              fail(err);
            }
          }}
          onFocus={refreshLists}
        >
          <option value="">Load…</option>
          {savedPlans.map((p) => (
            <option key={p.name} value={p.name}>
              {p.name} (v{p.latest_version})
            </option>
          ))}
        </select>
        <button
          type="button"
          onClick={() => {
            if (dirty && T.countNodes(plan) > 1 && !confirm('Discard the changes to this plan?')) return;
            const next = T.emptyPlan();
            setHistory(startHistory(next));
            setTreeId(next.mainTree);
            setSelectedKey(next.trees[0].root?.key ?? null);
            setPlanName('');
            setSaved(null);
            setDiagnostics([]);
          }}
        >
          New
        </button>
        <label className="file-button">
          Import XML
          <input type="file" accept=".xml,application/xml" onChange={(e) => e.target.files?.[0] && importXml(e.target.files[0])} />
        </label>
        <button type="button" onClick={exportXml}>
          Export XML
        </button>
        <button
          type="button"
          onClick={async () => {
            try {
              const result = await api.validate(T.toPlanJson(plan));
              setDiagnostics(result.diagnostics);
              setMessage(
                result.valid
                  ? { text: 'The plan is valid for this workcell.', kind: 'info' }
                  : { text: `${result.diagnostics.length} problem(s): ${result.diagnostics[0].message}`, kind: 'error' },
              );
            } catch (e) {
              fail(e);
            }
          }}
        >
          Check
        </button>
        <span className="separator" />
        <button type="button" className="run" disabled={running || !!replay} onClick={() => run(false)}>
          ▶ Run
        </button>
        <button type="button" disabled={!running} onClick={() => control(paused ? 'resume' : 'pause')}>
          {paused ? 'Resume' : 'Pause'}
        </button>
        <button type="button" disabled={!!replay || (running && !live?.run.active)} onClick={() => (running ? control('step') : run(true))}>
          Step
        </button>
        <button type="button" className="stop" disabled={!running} onClick={() => control('stop')}>
          ■ Stop
        </button>
        <span className={`connection ${connected ? 'on' : 'off'}`}>{connected ? info?.workcell ?? 'connected' : 'disconnected'}</span>
      </header>

      {!token && (
        <div className="banner">
          Changes need the token that <code>costar serve</code> printed:{' '}
          <input
            aria-label="token"
            placeholder="paste the token"
            onKeyDown={(e) => {
              if (e.key === 'Enter') {
                storeToken((e.target as HTMLInputElement).value.trim());
                setToken((e.target as HTMLInputElement).value.trim());
              }
            }}
          />
        </div>
      )}
      <div className={`status-line ${message?.kind ?? ''}`} role="status">
        <span className="run-label" data-run-result={live && !live.run.active ? live.run.result : ''}>
          {runLabel}
        </span>
        {operation && (
          <span className="operation" data-operation-result={operation.result ?? ''}>
            {operation.label}: {operation.active ? 'running…' : operation.result}
            {operation.reason ? ` — ${operation.reason}` : ''}
          </span>
        )}
        {message && <span className="message">{message.text}</span>}
      </div>

      <Palette nodes={nodes} selected={paletteType} onSelect={setPaletteType} onAdd={(id) => addNode(id, 'child')} />

      {/* 4: the workspace (and 7: live status on each node) */}
      <section className="pane workspace" aria-label="Behavior tree">
        <h2>
          <span className="pane-number">4</span> Behavior tree
          {replay && <span className="replaying">replaying run #{replay.log.id} (read only)</span>}
        </h2>
        <div className="toolbar">
          <button type="button" disabled={!!replay} onClick={() => addNode(paletteType, 'child')}>
            Add child
          </button>
          <button type="button" disabled={!!replay} onClick={() => addNode(paletteType, 'sibling')}>
            Add sibling
          </button>
          <button
            type="button"
            disabled={!!replay || !selectedKey}
            onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, -1))}
          >
            ↑
          </button>
          <button
            type="button"
            disabled={!!replay || !selectedKey}
            onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, 1))}
          >
            ↓
          </button>
          <button type="button" disabled={!!replay || !selectedKey} onClick={() => selectedKey && edit((p) => T.removeNode(p, treeId, selectedKey), null)}>
            Delete
          </button>
          <button type="button" disabled={!canUndo(history) || !!replay} onClick={() => setHistory(undo(history))}>
            Undo
          </button>
          <button type="button" disabled={!canRedo(history) || !!replay} onClick={() => setHistory(redo(history))}>
            Redo
          </button>
          <span className="separator" />
          <button type="button" disabled={!selected || !!replay} onClick={saveSubtree}>
            Save subtree
          </button>
          <select aria-label="saved subtree" value={subtreeChoice} onChange={(e) => setSubtreeChoice(e.target.value)} onFocus={refreshLists}>
            <option value="">saved subtrees…</option>
            {savedSubtrees.map((s) => (
              <option key={s.name} value={s.name}>
                {s.name}
              </option>
            ))}
          </select>
          <button type="button" disabled={!subtreeChoice || !!replay} onClick={() => insertSubtree(false)}>
            Insert copy
          </button>
          <button type="button" disabled={!subtreeChoice || !!replay} onClick={() => insertSubtree(true)}>
            Insert as SubTree
          </button>
        </div>
        <div className="tabs">
          {(replay ? replay.plan : plan).trees.map((t) => (
            <button
              type="button"
              key={t.id}
              className={t.id === tree?.id ? 'tab active' : 'tab'}
              onClick={() => {
                setTreeId(t.id);
                setSelectedKey(t.root?.key ?? null);
              }}
            >
              {t.id}
              {t.id === (replay ? replay.plan : plan).mainTree ? ' (main)' : ''}
            </button>
          ))}
        </div>
        <div className="tree-scroll">
          <TreeView
            root={tree?.root ?? null}
            nodeInfo={nodeInfo}
            selectedKey={selectedKey}
            statuses={shownStatuses}
            problems={problems}
            readOnly={!!replay}
            onSelect={setSelectedKey}
            onToggle={(key) => setHistory(replace(history, T.toggleCollapsed(plan, treeId, key)))}
            onMove={(key, target, position) => edit((p) => T.moveNode(p, treeId, key, target, position, kindOf))}
            onDropNew={(id, target, position) => {
              const node = T.makeNode(id);
              edit((p) => {
                if (position === 'inside') return T.addChild(p, treeId, target, node, kindOf);
                const withNode = T.addSibling(p, treeId, target, node, kindOf);
                return position === 'before' ? T.moveNode(withNode, treeId, node.key, target, 'before', kindOf) : withNode;
              }, node.key);
            }}
          />
        </div>
      </section>

      <NodeEditor
        node={selected}
        info={selected ? nodeInfo(selected.id) : undefined}
        choices={waypointChoices}
        objects={cell?.objects.map((o) => o.name) ?? []}
        trees={plan.trees.map((t) => t.id).filter((id) => id !== treeId)}
        readOnly={!!replay}
        onChange={(name, value) => selectedKey && edit((p) => T.setAttribute(p, treeId, selectedKey, name, value))}
      />
      <ObjectsPane state={cell} selectedType={selected?.id ?? null} data={selectedData} />
      <View3D
        state={cell}
        candidates={selectedData?.candidates ?? []}
        selectedWaypoint={selected ? T.attribute(selected, 'waypoint') ?? null : null}
        api={api}
        pointCloudAvailable={info?.features.pointcloud ?? false}
      />
      <Waypoints state={cell} choices={choices} busy={running} run={runOperation} />
      <Replay
        api={api}
        replay={replay ? { log: replay.log, index: replay.index } : null}
        refreshKey={runsRefresh}
        onOpen={(log) => {
          if (!log.plan_json) return;
          const replayPlan = T.fromPlanJson(log.plan_json);
          setReplay({ log, plan: replayPlan, mapping: mapRun(replayPlan, log.nodes), index: log.transition_list.length });
          setTreeId(replayPlan.mainTree);
          setSelectedKey(null);
        }}
        onIndex={(index) => setReplay((r) => (r ? { ...r, index } : r))}
        onClose={() => {
          setReplay(null);
          setTreeId(plan.mainTree);
        }}
      />
    </div>
  );
}
