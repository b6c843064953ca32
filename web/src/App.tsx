// The task editor (the paper's Fig. 5): 1 objects and SmartMove candidates, 2 the cell in 3D,
// 3 waypoints, 4 the tree workspace, 5 customise the selected operation, 6 the operations,
// 7 live execution and replay, 8 the menu of quick actions.

import { useCallback, useEffect, useMemo, useRef, useState } from 'react';
import { Api, ApiError, CellState, Choices, Diagnostic, Info, NodeInfo, RunInfo, RunLog } from './api';
import { Stream, StreamMessage } from './stream';
import { readToken, storeToken, tokenFromHash } from './token';
import * as T from './model/tree';
import { EditorPlan } from './model/tree';
import { canRedo, canUndo, History, push, redo, replace, startHistory, undo } from './model/history';
import { mapRun, mergeStatuses, NodeRef, NodeStatus, statusesAt, statusesByKey } from './model/status';
import { Palette } from './components/Palette';
import { Orientation, SelectMode, TreeCanvas } from './components/TreeCanvas';
import { HelpOverlay } from './components/HelpOverlay';
import { SignIn } from './components/SignIn';
import { NodeEditor } from './components/NodeEditor';
import { candidatesOf, ObjectsPane } from './components/ObjectsPane';
import { Waypoints } from './components/Waypoints';
import { View3D } from './components/View3D';
import { Replay } from './components/Replay';
import { Believed, believe, emptyBelief } from './model/belief';

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

/**
 * The menu's quick actions (pane 8): each runs one operation of the workcell outside a plan.
 * Add one here (a label, the node type, and when the cell offers it).
 */
function quickActions(info: Info | null): { label: string; node: string; title: string }[] {
  const actions: { label: string; node: string; title: string; when: boolean }[] = [
    { label: 'Detect objects', node: info?.features.detect_node ?? '', title: 'Look at the table and update the objects', when: !!info?.features.detect },
    { label: 'Calibrate', node: info?.features.calibrate_node ?? '', title: 'Calibrate the camera to the arm', when: !!info?.features.calibrate },
    { label: 'Home', node: 'Home', title: 'Move the arm to its home pose', when: true },
    { label: 'Open gripper', node: 'Open', title: 'Open the gripper', when: true },
    { label: 'Close gripper', node: 'Close', title: 'Close the gripper', when: true },
  ];
  return actions.filter((a) => a.when);
}

const NAME_PATTERN = /^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$/;

export function App() {
  const [token, setToken] = useState(readToken);
  const api = useMemo(() => new Api(token), [token]);
  const [info, setInfo] = useState<Info | null>(null);
  const [nodes, setNodes] = useState<NodeInfo[]>([]);
  const [choices, setChoices] = useState<Choices | null>(null);
  const [cell, setCell] = useState<CellState | null>(null);
  const [connected, setConnected] = useState(false);

  const planNameRef = useRef('');
  const [history, setHistory] = useState<History<EditorPlan>>(() => startHistory(T.emptyPlan()));
  const plan = history.present;
  const [treeId, setTreeId] = useState('main');
  const [selectedKey, setSelectedKeyOnly] = useState<string | null>(() => plan.trees[0].root?.key ?? null);
  // The selection: the primary node (customised in pane 5) and, with Shift or Ctrl, more.
  const [selectedKeys, setSelectedKeys] = useState<Set<string>>(new Set());
  const setSelectedKey = (key: string | null) => {
    setSelectedKeyOnly(key);
    setSelectedKeys(new Set(key ? [key] : []));
  };
  const [clipboard, setClipboard] = useState<T.EditorNode[]>([]);
  const [orientation, setOrientation] = useState<Orientation>('LR');
  const [help, setHelp] = useState(false);
  // The larger tree (M): the cell, the waypoints and the runs fold away.
  const [large, setLarge] = useState(false);
  const [fitRequest, setFitRequest] = useState(0);
  // Sign-in: 'missing' without a token, 'wrong' when the server refused it.
  const [signIn, setSignIn] = useState<'missing' | 'wrong' | null>(() => (readToken() ? null : 'missing'));
  // Plan runs started from this page: their statuses are painted on this plan.
  const startedHere = useRef(new Set<number>());
  const endedRuns = useRef(new Set<number>());
  const [planName, setPlanNameState] = useState('');
  const setPlanName = (name: string) => {
    planNameRef.current = name;
    setPlanNameState(name);
  };
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

  // The world the system believes (pane 1 lists it, pane 2 draws it): one step for every
  // snapshot as it arrives, not per render, so that a grasp or a release between two renders
  // is not missed.
  const beliefRef = useRef(emptyBelief());
  const [believed, setBelieved] = useState<Believed | undefined>(undefined);
  const showCell = (state: CellState) => {
    const next = believe(beliefRef.current, state);
    beliefRef.current = next.belief;
    setBelieved(next);
    setCell(state);
  };

  const planRef = useRef(plan);
  planRef.current = plan;
  const nodeInfo = useCallback((id: string) => nodes.find((n) => n.id === id), [nodes]);
  const kindOf = useCallback((id: string) => nodeInfo(id)?.kind, [nodeInfo]);

  const fail = (e: unknown) => {
    const error = e as ApiError;
    if (error.status === 401) setSignIn(token ? 'wrong' : 'missing');
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
            if (m.state) showCell(m.state);
            // The last run paints this plan only if it is a run of this plan (a reload starts
            // a new plan: another plan's old FAILURE must not show on it).
            if (m.run && m.run.kind === 'plan' && m.run.nodes && m.run.plan && m.run.plan === planNameRef.current) {
              setLive({
                run: m.run,
                statuses: new Map((m.run.statuses ?? []).map((s) => [s.uid, s])),
                mapping: mapRun(planRef.current, m.run.nodes),
              });
            }
            break;
          case 'state':
            showCell(m as CellState);
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
          case 'auth':
            setSignIn(m.ok ? null : 'wrong');
            break;
          case 'run_ended':
            endedRuns.current.add(m.run.id);
            // "Run #N started." is over: the status line shows how it ended.
            setMessage((msg) => (msg && /^Run #\d+ started/.test(msg.text) ? null : msg));
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

  // A #token=... pasted into the address of an open tab signs in at once (no reload).
  useEffect(() => {
    const onHash = () => {
      const fresh = tokenFromHash();
      if (fresh) {
        setToken(fresh);
        setSignIn(null);
      }
    };
    window.addEventListener('hashchange', onHash);
    return () => window.removeEventListener('hashchange', onHash);
  }, []);

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

  // Inserting (the palette, paste): inside the selected node when it takes children, else
  // right after it; the inserted node is selected, so clicking operations one after another
  // builds a sequence in order.
  const insert = (nodes: T.EditorNode[], at: string | null = selectedKey) => {
    if (nodes.length === 0) return;
    edit((p) => T.insertAt(p, treeId, at, nodes, kindOf), nodes[nodes.length - 1].key);
  };
  const addNode = (type: string) => insert([T.makeNode(type)]);
  const selectedNodes = () => {
    const root = T.findTree(plan, treeId)?.root ?? null;
    const keys = selectedKeys.size ? selectedKeys : new Set(selectedKey ? [selectedKey] : []);
    return T.topmostSelected(root, keys);
  };
  const copy = () => {
    const nodes = selectedNodes();
    if (nodes.length === 0) return;
    setClipboard(nodes.map(T.cloneNode));
    setMessage({ text: `Copied ${nodes.length} node(s) with what is under them: Ctrl+V pastes after the selected node.`, kind: 'info' });
  };
  const cut = () => {
    const nodes = selectedNodes();
    if (nodes.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const first = T.locate(root, nodes[0].key);
    const before = first?.parent ? first.parent.children[first.index - 1]?.key ?? first.parent.key : null;
    try {
      const next = T.removeNodes(plan, treeId, nodes.map((n) => n.key));
      setClipboard(nodes.map(T.cloneNode));
      setHistory(push(history, next));
      setSelectedKey(before);
      setMessage({ text: `Cut ${nodes.length} node(s): Ctrl+V pastes them after the selected node.`, kind: 'info' });
    } catch (e) {
      setMessage({ text: (e as Error).message, kind: 'error' });
    }
  };
  const paste = () => {
    if (clipboard.length === 0) {
      setMessage({ text: 'Nothing to paste: copy (Ctrl+C) or cut (Ctrl+X) nodes first.', kind: 'error' });
      return;
    }
    // After the last selected node (a copied range stays selected), as fresh copies: the
    // clipboard pastes again.
    const chosen = selectedNodes();
    insert(clipboard.map(T.cloneNode), chosen.length ? chosen[chosen.length - 1].key : selectedKey);
  };
  const duplicate = () => {
    const nodes = selectedNodes();
    if (nodes.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const last = nodes[nodes.length - 1];
    if (last.key === root?.key) {
      setMessage({ text: 'The root cannot be duplicated: select nodes under it.', kind: 'error' });
      return;
    }
    const copies = nodes.map(T.cloneNode);
    edit((p) => {
      let next = p;
      let after = last.key;
      for (const node of copies) {
        next = T.addSibling(next, treeId, after, node, kindOf);
        after = node.key;
      }
      return next;
    }, copies[copies.length - 1].key);
  };
  const removeSelected = () => {
    const nodes = selectedNodes();
    if (nodes.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const first = T.locate(root, nodes[0].key);
    const next = first?.parent ? first.parent.children[first.index - 1]?.key ?? first.parent.key : null;
    edit((p) => T.removeNodes(p, treeId, nodes.map((n) => n.key)), next);
  };
  const select = (key: string, mode: SelectMode) => {
    const root = T.findTree(replay ? replay.plan : plan, treeId)?.root ?? null;
    if (mode === 'range' && selectedKey) {
      setSelectedKeys(new Set(T.siblingRange(root, selectedKey, key)));
      return; // the primary node stays where the range started
    }
    if (mode === 'toggle') {
      const next = new Set(selectedKeys);
      if (next.has(key)) next.delete(key);
      else next.add(key);
      setSelectedKeys(next);
      setSelectedKeyOnly(key);
      return;
    }
    setSelectedKey(key);
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
      const ctrl = e.ctrlKey || e.metaKey;
      const key = e.key.toLowerCase();
      const root = tree?.root ?? null;
      const go = (direction: 'parent' | 'child' | 'previous' | 'next') => {
        const next = selectedKey ? T.neighbour(root, selectedKey, direction) : root?.key ?? null;
        if (next) setSelectedKey(next);
      };
      // Siblings stand below one another (left to right) or side by side (top down).
      const lr = orientation === 'LR';
      const arrows: Record<string, 'parent' | 'child' | 'previous' | 'next'> = lr
        ? { arrowleft: 'parent', arrowright: 'child', arrowup: 'previous', arrowdown: 'next' }
        : { arrowup: 'parent', arrowdown: 'child', arrowleft: 'previous', arrowright: 'next' };
      let handled = true;
      if (e.key === '?' || e.key === 'F1') setHelp((h) => !h);
      else if (e.key === 'Escape') {
        setHelp(false);
        if (selectedKey) setSelectedKey(selectedKey);
      } else if (ctrl && key === 'z') setHistory(e.shiftKey ? redo(history) : undo(history));
      else if (ctrl && key === 'y') setHistory(redo(history));
      else if (ctrl && key === 'c') copy();
      else if (ctrl && key === 'x' && !replay) cut();
      else if (ctrl && key === 'v' && !replay) paste();
      else if (ctrl && key === 'd' && !replay) duplicate();
      else if (ctrl && key === 's') void save();
      else if (!ctrl && !e.altKey && key === 'f') setFitRequest((n) => n + 1);
      else if (!ctrl && !e.altKey && key === 'm') setLarge((l) => !l);
      else if ((e.key === 'Delete' || e.key === 'Backspace') && selectedKey && !replay) removeSelected();
      else if (e.altKey && selectedKey && !replay && (key === (lr ? 'arrowup' : 'arrowleft') || key === (lr ? 'arrowdown' : 'arrowright')))
        edit((p) => T.shiftNode(p, treeId, selectedKey, key === (lr ? 'arrowup' : 'arrowleft') ? -1 : 1));
      else if (arrows[key] && !ctrl) go(arrows[key]);
      else if (e.key === ' ' && selectedKey && T.locate(root, selectedKey)?.node.children.length && !replay)
        setHistory(replace(history, T.toggleCollapsed(plan, treeId, selectedKey)));
      else handled = false;
      if (handled) e.preventDefault();
    };
    window.addEventListener('keydown', onKey);
    return () => window.removeEventListener('keydown', onKey);
  });

  // Once Check has found problems, they follow the edits: checked again after each change.
  const hasDiagnostics = diagnostics.length > 0;
  useEffect(() => {
    if (!hasDiagnostics || replay) return;
    const timer = setTimeout(() => {
      try {
        api.validate(T.toPlanJson(plan)).then((r) => setDiagnostics(r.diagnostics), () => undefined);
      } catch {
        // an empty tree: Check says so when clicked
      }
    }, 250);
    return () => clearTimeout(timer);
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [plan, hasDiagnostics]);

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
    // Another plan: the statuses of the last run belong to the plan that ran.
    setLive((l) => (l && l.run.active && l.run.plan === name ? { ...l, mapping: mapRun(next, l.run.nodes ?? []) } : null));
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
      startedHere.current.add(started.run);
      if (!endedRuns.current.has(started.run)) setMessage({ text: `Run #${started.run} started.`, kind: 'info' });
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
  // A run's statuses are painted on this plan when this page started it, or it is a run of
  // the plan open here (by name); another plan's run only shows in the status line.
  const liveIsOurs = !!live && (startedHere.current.has(live.run.id) || (!!live.run.plan && live.run.plan === planName));
  const replayStatuses = useMemo(
    () => (replay ? statusesAt(replay.log.transition_list, replay.index) : null),
    [replay],
  );
  const shownStatuses = useMemo(() => {
    if (replay && replayStatuses) return statusesByKey(replayStatuses, replay.mapping, tree?.id ?? treeId);
    if (live && liveIsOurs) return statusesByKey(live.statuses, live.mapping, tree?.id ?? treeId);
    return new Map<string, NodeStatus>();
  }, [replay, replayStatuses, live, liveIsOurs, tree, treeId]);
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
    <div className={`app ${large ? 'tree-large' : ''}`}>
      {/* 8: the menu, with plan files and the run controls (7) */}
      <header className="menu" aria-label="Menu">
        <span className="brand">costar</span>
        <span className="pane-number">8</span>
        {quickActions(info).map((action) => (
          <button key={action.label} type="button" disabled={running} title={action.title} onClick={() => runOperation(action.node)}>
            {action.label}
          </button>
        ))}
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
            setLive((l) => (l && l.run.active ? l : null));
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

      {signIn && (
        <SignIn
          problem={signIn}
          onToken={(t) => {
            storeToken(t);
            setToken(t);
            setSignIn(null);
          }}
          onDismiss={() => setSignIn(null)}
        />
      )}
      {help && <HelpOverlay onClose={() => setHelp(false)} />}
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

      <Palette nodes={nodes} disabled={!!replay} onAdd={addNode} />

      {/* 4: the workspace (and 7: live status on each node) */}
      <section className="pane workspace" aria-label="Behavior tree">
        <h2>
          <span className="pane-number">4</span> Behavior tree
          {replay && <span className="replaying">replaying run #{replay.log.id} (read only)</span>}
        </h2>
        <div className="toolbar">
          <button type="button" disabled={!!replay || !selectedKey} onClick={copy} title="Copy the selected nodes and what is under them (Ctrl+C)">
            Copy
          </button>
          <button type="button" disabled={!!replay || !selectedKey} onClick={cut} title="Cut (Ctrl+X)">
            Cut
          </button>
          <button type="button" disabled={!!replay || clipboard.length === 0} onClick={paste} title="Paste after the selected node, or inside it if it takes children (Ctrl+V)">
            Paste
          </button>
          <button type="button" disabled={!!replay || !selectedKey} onClick={duplicate} title="Duplicate right after (Ctrl+D)">
            Duplicate
          </button>
          <button
            type="button"
            disabled={!!replay || !selectedKey}
            title="Move before the previous sibling (Alt+↑)"
            onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, -1))}
          >
            ↑
          </button>
          <button
            type="button"
            disabled={!!replay || !selectedKey}
            title="Move after the next sibling (Alt+↓)"
            onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, 1))}
          >
            ↓
          </button>
          <button type="button" disabled={!!replay || !selectedKey} onClick={removeSelected} title="Delete the selected nodes (Delete)">
            Delete
          </button>
          <button type="button" className="icon" aria-label="Undo" disabled={!canUndo(history) || !!replay} onClick={() => setHistory(undo(history))} title="Undo (Ctrl+Z)">
            ↶
          </button>
          <button type="button" className="icon" aria-label="Redo" disabled={!canRedo(history) || !!replay} onClick={() => setHistory(redo(history))} title="Redo (Ctrl+Y)">
            ↷
          </button>
          <button
            type="button"
            className="icon"
            aria-label="Layout"
            onClick={() => setOrientation((o) => (o === 'LR' ? 'TB' : 'LR'))}
            title={orientation === 'LR' ? 'Laid out left to right: click for top down' : 'Laid out top down: click for left to right'}
          >
            {orientation === 'LR' ? '→' : '↓'}
          </button>
          <button type="button" aria-label="Fit the tree" onClick={() => setFitRequest((n) => n + 1)} title="Fit the whole tree into the pane (F)">
            Fit
          </button>
          <button
            type="button"
            className={`icon ${large ? 'on' : ''}`}
            aria-label="Larger tree"
            aria-pressed={large}
            onClick={() => setLarge((l) => !l)}
            title={large ? 'Show the cell, the waypoints and the runs again (M)' : 'Larger tree: fold away the cell, the waypoints and the runs (M)'}
          >
            ⤢
          </button>
          <button type="button" className="icon" aria-label="Keys" onClick={() => setHelp(true)} title="Keyboard shortcuts (?)">
            ?
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
          {subtreeChoice && (
            <>
              <button type="button" disabled={!!replay} onClick={() => insertSubtree(false)} title="Insert a copy of the saved subtree">
                Insert
              </button>
              <button type="button" disabled={!!replay} onClick={() => insertSubtree(true)} title="Insert a SubTree node that names it (and add its BehaviorTree to the file)">
                As SubTree
              </button>
            </>
          )}
        </div>
        {(replay ? replay.plan : plan).trees.length > 1 && (
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
        )}
        <div className="tree-canvas" aria-label="tree canvas">
          <TreeCanvas
            root={tree?.root ?? null}
            nodeInfo={nodeInfo}
            selectedKey={selectedKey}
            selectedKeys={selectedKeys}
            statuses={shownStatuses}
            problems={problems}
            readOnly={!!replay}
            orientation={orientation}
            fitRequest={fitRequest}
            onSelect={select}
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
        <p className="hint tree-hint">
          Click an operation (6) to insert it after the selected node, or inside it if it takes children · Shift+click selects
          siblings · Ctrl+C/X/V/D · arrows move the selection · ? lists every key
        </p>
      </section>

      <NodeEditor
        node={selected}
        info={selected ? nodeInfo(selected.id) : undefined}
        choices={waypointChoices}
        objects={cell?.objects.map((o) => o.name) ?? []}
        trees={plan.trees.map((t) => t.id).filter((id) => id !== treeId)}
        readOnly={!!replay}
        onChange={(name, value, clear) =>
          selectedKey &&
          edit((p) => (clear ?? []).reduce((q, other) => T.setAttribute(q, treeId, selectedKey, other, undefined), T.setAttribute(p, treeId, selectedKey, name, value)))
        }
      />
      <ObjectsPane state={cell} selectedType={selected?.id ?? null} data={selectedData} shapes={choices?.object_shape} believed={believed} />
      <View3D
        state={cell}
        candidates={selectedData?.candidates ?? []}
        selectedWaypoint={selected ? T.attribute(selected, 'waypoint') ?? null : null}
        api={api}
        pointCloudAvailable={info?.features.pointcloud ?? false}
        shapes={choices?.object_shape}
        believed={believed}
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
