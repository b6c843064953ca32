// The task editor (the paper's Fig. 5) and the cell's control panel: 1 objects and SmartMove
// candidates, 2 the cell in 3D, 3 waypoints and jogging, 4 the tree workspace, 5 customise the
// selected operation, 6 the operations, 7 live execution and replay, 8 the menu.
//
// What the cell does is the cell's, not the page's: the active run (whoever started it, before
// or after a reload) is shown and can be paused, stepped and stopped from any signed-in page;
// every control the cell would refuse is disabled and says why (model/controls.ts). Lists,
// Check and the nodes' badges follow what the cell knows now and the plan as it is now.

import { useCallback, useEffect, useMemo, useRef, useState } from 'react';
import { Api, ApiError, CellState, Choices, Diagnostic, Info, NodeInfo, RunInfo, RunLog, StoredRun } from './api';
import { Stream, StreamMessage } from './stream';
import { readToken, storeToken, tokenFromHash } from './token';
import * as T from './model/tree';
import { EditorPlan } from './model/tree';
import { canRedo, canUndo, History, push, redo, replace, startHistory, undo } from './model/history';
import {
  MappedRef,
  mapRun,
  mapRunOnto,
  mergeStatuses,
  NodeRef,
  NodeStatus,
  runningNode,
  statusesAt,
  statusesByKey,
  unchangedStatusesByKey,
} from './model/status';
import { controlRefusal, motionRefusal, resetRefusal, runRefusal, saveRefusal } from './model/controls';
import { rangeProblems } from './model/units';
import { fixFor, renameWaypoint, waypointUses } from './model/fixes';
import type { DiffEntry } from './model/diff';
import type { RobotDescription } from './model/robot';
import { Palette } from './components/Palette';
import { Orientation, SelectMode, TreeCanvas } from './components/TreeCanvas';
import { HelpOverlay } from './components/HelpOverlay';
import { SignIn } from './components/SignIn';
import { NodeEditor } from './components/NodeEditor';
import { candidatesOf, ObjectsPane } from './components/ObjectsPane';
import { Waypoints } from './components/Waypoints';
import { HandGuiding, type ShownGrasp } from './components/HandGuiding';
import { freeDriveAttributes, type Guiding } from './model/handGuide';
import { View3D } from './components/View3D';
import { Replay } from './components/Replay';
import { PlanBrowser } from './components/PlanBrowser';
import { Believed, believe, emptyBelief } from './model/belief';

/** The cell's current (or last) plan run, as the stream tells it. */
interface CellRun {
  run: RunInfo;
  statuses: Map<number, NodeStatus>;
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
  /** The cell's snapshots during the run (clock seconds since its start). */
  states: { t: number; state: CellState }[];
}

/** The last thing done from this page (one at a time: the status line shows only it). */
type Message = { text: string; kind: 'info' | 'error' } | null;

interface Offer {
  label: string;
  apply: () => void;
}

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

/** A node of a run as people read it: type and name. */
function nodeLabel(node: { id: string; name: string } | undefined) {
  return node ? `${node.id}${node.name ? ` “${node.name}”` : ''}` : '';
}

export function App() {
  const [token, setToken] = useState(readToken);
  const api = useMemo(() => new Api(token), [token]);
  const [info, setInfo] = useState<Info | null>(null);
  const [nodes, setNodes] = useState<NodeInfo[]>([]);
  const [choices, setChoices] = useState<Choices | null>(null);
  const [robot, setRobot] = useState<RobotDescription | null>(null);
  const [guiding, setGuiding] = useState<Guiding>({ mode: 'free', locked: [], record: '', recordFrame: 'world' });
  /** The grasp drawn on the parts in the 3D view (the one taught last, or chosen under the waypoints). */
  const [shownGrasp, setShownGrasp] = useState<ShownGrasp | null>(null);
  const guidingRef = useRef(guiding);
  guidingRef.current = guiding;
  const [cell, setCell] = useState<CellState | null>(null);
  const [connected, setConnected] = useState(false);
  // The server refused the token (401, or the stream's auth answer).
  const [tokenRefused, setTokenRefused] = useState(false);

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
  const [browsing, setBrowsing] = useState(false);
  // The larger tree (M): the cell, the waypoints and the runs fold away.
  const [large, setLarge] = useState(false);
  const [fitRequest, setFitRequest] = useState(0);
  // Sign-in: 'missing' without a token, 'wrong' when the server refused it.
  const [signIn, setSignIn] = useState<'missing' | 'wrong' | null>(() => (readToken() ? null : 'missing'));
  const [planName, setPlanNameState] = useState('');
  const setPlanName = (name: string) => {
    planNameRef.current = name;
    setPlanNameState(name);
  };
  const [saved, setSaved] = useState<{ name: string; plan: EditorPlan; version: number } | null>(null);
  const [savedSubtrees, setSavedSubtrees] = useState<{ name: string }[]>([]);
  const [subtreeChoice, setSubtreeChoice] = useState('');
  const [diagnostics, setDiagnostics] = useState<Diagnostic[]>([]);
  const [message, setMessage] = useState<Message>(null);
  const [offer, setOffer] = useState<Offer | null>(null);
  const say = (text: string, kind: 'info' | 'error' = 'info', next: Offer | null = null) => {
    setMessage({ text, kind });
    setOffer(next);
  };

  // The cell's run and which of the open plan's nodes it maps onto (null: it is another plan).
  const [cellRun, setCellRun] = useState<CellRun | null>(null);
  const cellRunRef = useRef<CellRun | null>(null);
  cellRunRef.current = cellRun;
  const [shown, setShown] = useState<{ runId: number; mapping: Map<number, MappedRef> } | null>(null);
  const [operation, setOperation] = useState<OperationState | null>(null);
  const [replay, setReplay] = useState<ReplayState | null>(null);
  const [comparison, setComparison] = useState<{ label: string; entries: DiffEntry[] } | null>(null);
  const [runs, setRuns] = useState<StoredRun[]>([]);
  // Plan runs started from this page (mapped onto the plan open when they started).
  const startedHere = useRef(new Map<number, EditorPlan>());
  // Waypoint renames asked for here, by operation id: offered in the open plan when done.
  const renames = useRef(new Map<number, { from: string; to: string }>());
  // How operations ended, by id (the stream may tell before the request that started one returns).
  const ended = useRef(new Map<number, string>());

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
  const savedRef = useRef(saved);
  savedRef.current = saved;
  const nodeInfo = useCallback((id: string) => nodes.find((n) => n.id === id), [nodes]);
  const kindOf = useCallback((id: string) => nodeInfo(id)?.kind, [nodeInfo]);
  const waypointPorts = useCallback(
    (type: string) => nodeInfo(type)?.ports.filter((p) => p.choices_from === 'waypoint').map((p) => p.name) ?? [],
    [nodeInfo],
  );

  const fail = (e: unknown) => {
    const error = e as ApiError;
    if (error.status === 401) {
      setTokenRefused(!!token);
      setSignIn(token ? 'wrong' : 'missing');
    }
    say(error.status === undefined ? `not connected to the cell (${error.message})` : error.message, 'error');
    if (error.diagnostics?.length) setDiagnostics(error.diagnostics);
  };

  const refreshLists = useCallback(() => {
    api.choices().then(setChoices, () => undefined);
    api.subtrees().then(setSavedSubtrees, () => undefined);
    api.runs().then(setRuns, () => undefined);
  }, [api]);

  // --- the open plan and the cell's run ------------------------------------------------------
  /** Opens a plan in the editor (a fresh history). */
  const loadPlan = (json: T.PlanJson, name: string, version?: number) => {
    const next = T.fromPlanJson(json);
    setHistory(startHistory(next));
    planRef.current = next;
    setTreeId(next.mainTree);
    setSelectedKey(T.findTree(next, next.mainTree)?.root?.key ?? null);
    setPlanName(name);
    const savedNow = version ? { name, plan: next, version } : null;
    setSaved(savedNow);
    savedRef.current = savedNow;
    setDiagnostics([]);
    setReplay(null);
    setComparison(null);
    setShown(null);
    return next;
  };

  /** Paints the run on the open plan, where its nodes are still what ran. */
  const showRunOn = (run: RunInfo, open: EditorPlan) => {
    const ran = run.plan_json ? T.fromPlanJson(run.plan_json) : undefined;
    setShown({ runId: run.id, mapping: mapRunOnto(open, run.nodes ?? [], ran) });
  };

  /**
   * The cell runs (or ran) a plan: show it on the open plan if that is the plan that runs;
   * on a fresh page (nothing opened, nothing edited), open the plan that runs.
   */
  const adoptRun = (run: RunInfo) => {
    const open = planRef.current;
    const here = startedHere.current.get(run.id);
    if (here) {
      showRunOn(run, here);
      return;
    }
    const pristine = !planNameRef.current && T.countNodes(open) <= 1 && history.past.length === 0;
    const samePlan = !!run.plan && run.plan === planNameRef.current;
    if (samePlan) {
      showRunOn(run, open);
    } else if (pristine && run.active && run.plan_json) {
      const next = loadPlan(run.plan_json, run.plan, run.plan ? run.version : undefined);
      showRunOn(run, next);
    }
  };

  /** Opens the plan the cell runs (the status line's Show button). */
  const showRunningPlan = () => {
    if (!cellRun?.run.plan_json) return;
    if (dirty && T.countNodes(plan) > 1 && !confirm('Discard the changes to this plan?')) return;
    const run = cellRun.run;
    const next = loadPlan(run.plan_json!, run.plan, run.plan ? run.version : undefined);
    showRunOn(run, next);
  };

  /** A rename asked for here ended: offer to take it into the open plan if it names the old waypoint. */
  const renamed = (id: number) => {
    const rename = renames.current.get(id);
    if (!rename || !ended.current.has(id)) return;
    renames.current.delete(id);
    if (ended.current.get(id) !== 'SUCCESS') return;
    const uses = waypointUses(planRef.current, rename.from, waypointPorts);
    if (uses === 0) return;
    say(`Waypoint '${rename.from}' is now '${rename.to}': ${uses} node(s) of this plan still name '${rename.from}'.`, 'error', {
      label: `Rename it in this plan (${uses})`,
      apply: () => {
        edit((p) => renameWaypoint(p, rename.from, rename.to, waypointPorts));
        say(`Renamed '${rename.from}' to '${rename.to}' in this plan (not saved yet).`);
      },
    });
  };

  // --- connection --------------------------------------------------------------------------
  const messageHandler = useRef<(m: StreamMessage) => void>(() => undefined);
  messageHandler.current = (m: StreamMessage) => {
    switch (m.type) {
      case 'hello': {
        setInfo(m.info);
        if (m.state) showCell(m.state);
        const run = m.run;
        if (run && run.kind === 'plan') {
          setCellRun({ run, statuses: new Map((run.statuses ?? []).map((s) => [s.uid, s])) });
          adoptRun(run);
        } else if (run && run.kind === 'operation' && run.active) {
          setOperation({ id: run.id, label: run.label, active: true });
        }
        break;
      }
      case 'state':
        showCell(m as CellState);
        break;
      case 'run_started':
        if (m.run.kind === 'plan') {
          setCellRun({ run: m.run, statuses: new Map() });
          adoptRun(m.run);
          if (!startedHere.current.has(m.run.id)) say(`Run #${m.run.id} started${m.run.plan ? ` (${m.run.plan} v${m.run.version})` : ''} from another page.`);
        } else {
          setOperation({ id: m.run.id, label: m.run.label, active: true });
        }
        break;
      case 'statuses':
        setCellRun((c) => (c && c.run.id === m.run ? { ...c, statuses: mergeStatuses(c.statuses, m.nodes) } : c));
        break;
      case 'auth':
        setTokenRefused(!m.ok);
        if (!m.ok) setSignIn('wrong');
        break;
      case 'scene_reset':
        beliefRef.current = emptyBelief();
        break;
      case 'run_ended':
        if (m.run.kind === 'plan') {
          setCellRun((c) => (c && c.run.id === m.run.id ? { ...c, run: { ...c.run, ...m.run, active: false } } : c));
          setMessage((msg) => (msg && /^Run #\d+ started/.test(msg.text) ? null : msg));
          api.runs().then(setRuns, () => undefined);
        } else {
          setOperation((o) => (o && o.id === m.run.id ? { ...o, active: false, result: m.run.result, reason: m.run.failure_reason } : o));
          api.choices().then(setChoices, () => undefined);
          ended.current.set(m.run.id, m.run.result);
          renamed(m.run.id);
        }
        break;
      default:
        break;
    }
  };

  useEffect(() => {
    api.info().then(setInfo, fail);
    api.nodes().then(setNodes, fail);
    api.robot().then(setRobot, () => setRobot(null));
    refreshLists();
    const stream = new Stream(token, {
      onConnection: setConnected,
      onMessage: (m) => messageHandler.current(m),
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
        setTokenRefused(false);
        setSignIn(null);
      }
    };
    window.addEventListener('hashchange', onHash);
    return () => window.removeEventListener('hashchange', onHash);
  }, []);

  // --- what the cell would refuse ------------------------------------------------------------
  const activeRun = cell && cell.mode !== 'idle' && cell.run ? cell.run : cellRun?.run.active ? cellRun.run.id : operation?.active ? operation.id : null;
  const controls = {
    connected,
    signedIn: !!token && !tokenRefused,
    activeRun,
    replaying: !!replay,
  };
  // A number out of its range is refused before anything is saved or run (the field says why).
  const outOfRange = useMemo(
    () => plan.trees.flatMap((t) => rangeProblems(t.root, nodeInfo).map((p) => ({ ...p, tree: t.id }))),
    [plan, nodeInfo],
  );
  const rangeRefusal = outOfRange.length ? `${outOfRange[0].id}: ${outOfRange[0].message}` : null;
  const refusedRun = runRefusal(controls) ?? rangeRefusal;
  const refusedMotion = motionRefusal(controls);
  const refusedControl = controlRefusal(controls);
  const refusedSave = saveRefusal(controls) ?? rangeRefusal;
  const paused = cell?.mode === 'paused';

  // --- editing -------------------------------------------------------------------------------
  const edit = (change: (p: EditorPlan) => EditorPlan, select?: string | null) => {
    try {
      const next = change(planRef.current);
      setHistory((h) => push(h, next));
      planRef.current = next;
      if (select !== undefined) setSelectedKey(select);
      setMessage(null);
      setOffer(null);
    } catch (e) {
      say((e as Error).message, 'error');
    }
  };

  // Inserting (the palette, paste): inside the selected node when it takes children, else
  // right after it; the inserted node is selected, so clicking operations one after another
  // builds a sequence in order.
  const insert = (inserted: T.EditorNode[], at: string | null = selectedKey) => {
    if (inserted.length === 0) return;
    edit((p) => T.insertAt(p, treeId, at, inserted, kindOf), inserted[inserted.length - 1].key);
  };
  const addNode = (type: string) => insert([T.makeNode(type)]);
  const selectedNodes = () => {
    const root = T.findTree(plan, treeId)?.root ?? null;
    const keys = selectedKeys.size ? selectedKeys : new Set(selectedKey ? [selectedKey] : []);
    return T.topmostSelected(root, keys);
  };
  const copy = () => {
    const chosen = selectedNodes();
    if (chosen.length === 0) return;
    setClipboard(chosen.map(T.cloneNode));
    say(`Copied ${chosen.length} node(s) with what is under them: Ctrl+V pastes after the selected node.`);
  };
  const cut = () => {
    const chosen = selectedNodes();
    if (chosen.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const first = T.locate(root, chosen[0].key);
    const before = first?.parent ? first.parent.children[first.index - 1]?.key ?? first.parent.key : null;
    try {
      const next = T.removeNodes(plan, treeId, chosen.map((n) => n.key));
      setClipboard(chosen.map(T.cloneNode));
      setHistory(push(history, next));
      setSelectedKey(before);
      say(`Cut ${chosen.length} node(s): Ctrl+V pastes them after the selected node.`);
    } catch (e) {
      say((e as Error).message, 'error');
    }
  };
  const paste = () => {
    if (clipboard.length === 0) {
      say('Nothing to paste: copy (Ctrl+C) or cut (Ctrl+X) nodes first.', 'error');
      return;
    }
    // After the last selected node (a copied range stays selected), as fresh copies: the
    // clipboard pastes again.
    const chosen = selectedNodes();
    insert(clipboard.map(T.cloneNode), chosen.length ? chosen[chosen.length - 1].key : selectedKey);
  };
  const duplicate = () => {
    const chosen = selectedNodes();
    if (chosen.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const last = chosen[chosen.length - 1];
    if (last.key === root?.key) {
      say('The root cannot be duplicated: select nodes under it.', 'error');
      return;
    }
    const copies = chosen.map(T.cloneNode);
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
    const chosen = selectedNodes();
    if (chosen.length === 0) return;
    const root = T.findTree(plan, treeId)?.root ?? null;
    const first = T.locate(root, chosen[0].key);
    const next = first?.parent ? first.parent.children[first.index - 1]?.key ?? first.parent.key : null;
    edit((p) => T.removeNodes(p, treeId, chosen.map((n) => n.key)), next);
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

  const shownPlan = replay ? replay.plan : plan;
  const tree = T.findTree(shownPlan, treeId) ?? T.findTree(shownPlan, shownPlan.mainTree);
  const selected = tree && selectedKey ? T.locate(tree.root, selectedKey)?.node ?? null : null;
  const dirty = !saved || saved.name !== planName || !T.samePlan(saved.plan, plan);

  useEffect(() => {
    const onKey = (e: KeyboardEvent) => {
      const target = e.target as HTMLElement;
      const ctrl = e.ctrlKey || e.metaKey;
      const key = e.key.toLowerCase();
      // A list just chosen from keeps the focus: the tree's Ctrl shortcuts (copy, paste,
      // duplicate, undo) still apply there (a list has no text of its own to copy or undo).
      const treeShortcut = ctrl && ['c', 'x', 'v', 'd', 'z', 'y'].includes(key);
      if (target && (['INPUT', 'TEXTAREA'].includes(target.tagName) || (target.tagName === 'SELECT' && !treeShortcut))) return;
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
        setBrowsing(false);
        if (selectedKey) setSelectedKey(selectedKey);
      } else if (ctrl && key === 'z' && !replay) setHistory(e.shiftKey ? redo(history) : undo(history));
      else if (ctrl && key === 'y' && !replay) setHistory(redo(history));
      else if (ctrl && key === 'c') copy();
      else if (ctrl && key === 'x' && !replay) cut();
      else if (ctrl && key === 'v' && !replay) paste();
      else if (ctrl && key === 'd' && !replay) duplicate();
      else if (ctrl && key === 's') {
        if (refusedSave) say(`Not saved: ${refusedSave}.`, 'error');
        else void save();
      } else if (!ctrl && !e.altKey && key === 'f') setFitRequest((n) => n + 1);
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
        api.validate(T.toPlanJson(plan), planName || undefined).then((r) => setDiagnostics(r.diagnostics), () => undefined);
      } catch {
        // an empty tree: Check says so when clicked
      }
    }, 250);
    return () => clearTimeout(timer);
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [plan, hasDiagnostics]);

  // --- files ---------------------------------------------------------------------------------
  const save = async (): Promise<{ name: string; version: number } | null> => {
    if (!NAME_PATTERN.test(planName)) {
      say('Give the plan a name: letters, digits, _ and - (it is not a path).', 'error');
      return null;
    }
    try {
      const result = await api.savePlan(planName, T.toPlanJson(plan));
      setSaved({ name: planName, plan, version: result.version });
      setDiagnostics([]);
      say(`Saved ${result.name} version ${result.version}.`);
      return result;
    } catch (e) {
      fail(e);
      return null;
    }
  };

  const check = async () => {
    try {
      const result = await api.validate(T.toPlanJson(plan), planName || undefined);
      setDiagnostics(result.diagnostics);
      if (result.valid) {
        say(`${planName ? `Plan '${planName}'` : 'This plan'} is valid for ${info?.workcell ?? 'this cell'}.`);
        return;
      }
      const first = result.diagnostics[0];
      const count = result.diagnostics.length === 1 ? '1 problem' : `${result.diagnostics.length} problems`;
      // A cure for the problem, else the offer standing (a rename to take into the plan).
      say(`${count}: ${first.message}`, 'error', fixOffer(result.diagnostics) ?? offer);
    } catch (e) {
      fail(e);
    }
  };

  /** The first of Check's problems the editor can cure, as a button. */
  const fixOffer = (found: Diagnostic[]): Offer | null => {
    for (const d of found) {
      if (!d.node) continue;
      const root = T.findTree(planRef.current, d.node.tree)?.root ?? null;
      const node = T.nodeAtPath(root, d.node.path);
      if (!node) continue;
      const parent = T.locate(root, node.key)?.parent ?? null;
      const fix = fixFor(d.message, d.node.tree, node, parent);
      if (fix) return { label: fix.label, apply: () => edit(fix.apply) };
    }
    return null;
  };

  const run = async (startPaused = false) => {
    setReplay(null);
    try {
      let started: { run: number };
      const open = planRef.current;
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
      startedHere.current.set(started.run, open);
      // The stream may have told of the start already: show it on this plan now.
      if (cellRunRef.current?.run.id === started.run) showRunOn(cellRunRef.current.run, open);
      say(`Run #${started.run} started${startPaused ? ' paused: Step ticks it once, Resume runs it' : ''}.`);
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
      setMessage(null);
      setOffer(null);
      return started.run;
    } catch (e) {
      fail(e);
      return null;
    }
  };

  /** Grabbing the tool's handle in the 3D view: FreeDrive in the guiding mode (refused, with the
   * reason shown, while a plan runs); a recording applies to this one drag. */
  const grabTool = useCallback(async () => {
    const id = await runOperation('FreeDrive', freeDriveAttributes(guidingRef.current));
    if (id !== null && guidingRef.current.record) setGuiding((g) => ({ ...g, record: '' }));
    return id !== null;
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [api]);

  const renameWaypointInCell = async (from: string, to: string) => {
    const id = await runOperation('RenameWaypoint', { waypoint: from, new_name: to });
    if (id === null) return;
    renames.current.set(id, { from, to });
    renamed(id);
  };

  const control = (action: 'pause' | 'resume' | 'step' | 'stop') =>
    api.control(action).then(
      () => setMessage(null),
      (e) => fail(e),
    );

  const resetScene = async () => {
    try {
      await api.resetScene();
      beliefRef.current = emptyBelief();
      say('Scene reset: the parts where the scene puts them, the arm at home. Detect objects to see them.');
    } catch (e) {
      fail(e);
    }
  };

  const exportXml = async () => {
    try {
      const result = await api.validate(T.toPlanJson(plan), planName || undefined);
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
      if (result.valid) say(`Imported ${file.name} (not saved yet).`);
      else say(`Imported ${file.name}: ${result.diagnostics.length} problem(s): ${result.diagnostics[0].message}`, 'error', fixOffer(result.diagnostics));
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
      say(`Saved subtree ${name} version ${result.version}.`);
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

  const openReplay = async (log: RunLog) => {
    if (!log.plan_json) return;
    const replayPlan = T.fromPlanJson(log.plan_json);
    let states: { t: number; state: CellState }[] = [];
    try {
      // Logged snapshots carry no waypoints or frames (they are not the run's): none drawn.
      states = (await api.runStates(log.id)).states.map(({ t, state }) => ({
        t,
        state: { ...state, waypoints: state.waypoints ?? [], frames: state.frames ?? [], objects: state.objects ?? [], predicates: state.predicates ?? [] },
      }));
    } catch {
      // a run logged before snapshots were kept: the tree replays alone
    }
    setReplay({ log, plan: replayPlan, mapping: mapRun(replayPlan, log.nodes), index: log.transition_list.length, states });
    setTreeId(replayPlan.mainTree);
    setSelectedKey(null);
  };

  // --- what the panes show ---------------------------------------------------------------------
  const replayStatuses = useMemo(() => (replay ? statusesAt(replay.log.transition_list, replay.index) : null), [replay]);
  const runIsShown = !!cellRun && !!shown && shown.runId === cellRun.run.id;
  const shownStatuses = useMemo(() => {
    if (replay && replayStatuses) return statusesByKey(replayStatuses, replay.mapping, tree?.id ?? treeId);
    if (cellRun && shown && shown.runId === cellRun.run.id) return unchangedStatusesByKey(cellRun.statuses, shown.mapping, plan, tree?.id ?? treeId);
    return new Map<string, NodeStatus>();
  }, [replay, replayStatuses, cellRun, shown, plan, tree, treeId]);
  const runningKey = useMemo(() => {
    for (const [key, status] of shownStatuses) if (status.status === 'RUNNING') return key;
    return null;
  }, [shownStatuses]);
  const deepestRunningKey = useMemo(() => {
    // The running leaf: a RUNNING node none of whose children runs.
    let found: string | null = null;
    const walk = (node: T.EditorNode | null) => {
      if (!node) return;
      if (shownStatuses.get(node.key)?.status === 'RUNNING') found = node.key;
      node.children.forEach(walk);
    };
    if (runningKey) walk(tree?.root ?? null);
    return found;
  }, [shownStatuses, runningKey, tree]);
  const problems = useMemo(() => {
    const map = new Map<string, string>();
    for (const d of diagnostics) {
      if (d.node && d.node.tree === tree?.id) {
        const node = T.nodeAtPath(tree.root, d.node.path);
        if (node) map.set(node.key, d.message);
      }
    }
    for (const p of outOfRange) if (p.tree === tree?.id && !map.has(p.key)) map.set(p.key, p.message);
    return map;
  }, [diagnostics, tree, outOfRange]);
  const changes = useMemo(() => {
    if (!comparison || replay) return undefined;
    const map = new Map<string, 'added' | 'changed'>();
    for (const entry of comparison.entries) {
      if (entry.kind !== 'removed' && entry.tree === tree?.id) map.set(entry.key, entry.kind);
    }
    return map;
  }, [comparison, replay, tree]);

  // Replay: the cell as the run's log has it at the replayed moment (and what was believed then).
  const replayed = useMemo(() => {
    if (!replay || replay.states.length === 0) return null;
    const t = replay.index > 0 ? replay.log.transition_list[replay.index - 1]?.t ?? 0 : 0;
    let belief = emptyBelief();
    let last: Believed | undefined;
    let state: CellState | null = null;
    for (const entry of replay.states) {
      if (entry.t > t && state) break;
      last = believe(belief, entry.state);
      belief = last.belief;
      state = entry.state;
    }
    return state ? { state, believed: last, t } : null;
  }, [replay]);
  const viewState = replayed ? replayed.state : cell;
  const viewBelieved = replayed ? replayed.believed : believed;

  const selectedData = selected ? candidatesOf(shownStatuses.get(selected.key)?.data) : null;
  // What the lists offer: what the cell knows now (the live snapshot), not what it knew when
  // the page loaded.
  const shownGraspPose = useMemo(() => {
    const pose = shownGrasp ? choices?.grasp_pose?.[shownGrasp.objectClass]?.[shownGrasp.name] : undefined;
    return shownGrasp && pose ? { ...shownGrasp, pose } : undefined;
  }, [shownGrasp, choices]);
  const liveChoices = useMemo(() => {
    if (!choices) return null;
    if (!cell) return choices;
    const waypoints = cell.waypoints.map((w) => w.name).sort();
    const frames = new Set(['world', ...cell.frames.map((f) => f.name), ...cell.waypoints.filter((w) => w.kind === 'pose').map((w) => w.name), ...cell.objects.map((o) => o.name)]);
    return { ...choices, waypoint: waypoints, frame: [...frames].sort((a, b) => (a === 'world' ? -1 : b === 'world' ? 1 : a.localeCompare(b))) };
  }, [choices, cell]);

  const runLabel = (() => {
    if (cellRun) {
      const r = cellRun.run;
      const what = `Run #${r.id}${r.plan ? ` (${r.plan} v${r.version})` : ' (unsaved plan)'}${r.workcell ? ` on ${r.workcell}` : ''}`;
      if (r.active) {
        const at = nodeLabel(runningNode(cellRun.statuses, r.nodes ?? []));
        return `${what}: ${paused ? 'PAUSED' : 'RUNNING'}${at ? ` at ${at}` : ''}`;
      }
      return `${what}: ${r.result}${r.failure_reason ? ` at ${r.failure_path}: ${r.failure_reason}` : ''}`;
    }
    const last = runs[0];
    if (last) return `Last run: #${last.id}${last.plan ? ` (${last.plan} v${last.version})` : ''}${last.workcell ? ` on ${last.workcell}` : ''}: ${last.result || 'INTERRUPTED'}`;
    return 'Nothing has run yet.';
  })();
  const lastAction = message
    ? message
    : operation
      ? {
          text: `${operation.label}: ${operation.active ? 'running…' : operation.result}${operation.reason ? ` — ${operation.reason}` : ''}`,
          kind: operation.result === 'FAILURE' ? ('error' as const) : ('info' as const),
        }
      : null;

  const stepRefusal = activeRun !== null ? refusedControl : refusedRun;

  return (
    <div className={`app ${large ? 'tree-large' : ''}`}>
      {/* 8: the menu, with plan files and the run controls (7) */}
      <header className="menu" aria-label="Menu">
        <span className="brand">costar</span>
        {quickActions(info).map((action) => (
          <button key={action.label} type="button" disabled={refusedMotion !== null} title={refusedMotion ?? action.title} onClick={() => runOperation(action.node)}>
            {action.label}
          </button>
        ))}
        {info?.simulator && (
          <button
            type="button"
            disabled={resetRefusal(controls) !== null}
            title={resetRefusal(controls) ?? 'Build the simulated scene again from its file and seed, the arm at home'}
            onClick={() => confirm('Reset the simulated scene? The parts go back where the scene puts them and the arm goes home.') && resetScene()}
          >
            Reset scene
          </button>
        )}
        <span className="separator" />
        <input className="plan-name" aria-label="plan name" placeholder="plan name" value={planName} onChange={(e) => setPlanName(e.target.value)} />
        <button type="button" onClick={save} disabled={refusedSave !== null} title={refusedSave ?? 'Save as the next version (Ctrl+S)'}>
          Save{dirty && planName ? ' *' : ''}
        </button>
        <button type="button" onClick={() => setBrowsing(true)} title="Saved plans: open, compare or restore any version">
          Plans…
        </button>
        <button
          type="button"
          onClick={() => {
            if (dirty && T.countNodes(plan) > 1 && !confirm('Discard the changes to this plan?')) return;
            const next = T.emptyPlan();
            setHistory(startHistory(next));
            planRef.current = next;
            setTreeId(next.mainTree);
            setSelectedKey(next.trees[0].root?.key ?? null);
            setPlanName('');
            setSaved(null);
            setDiagnostics([]);
            setComparison(null);
            setShown(null);
            setMessage(null);
            setOffer(null);
          }}
        >
          New
        </button>
        <label className="file-button" title="Open a plan file (BehaviorTree.CPP v4 XML)">
          Import
          <input type="file" accept=".xml,application/xml" onChange={(e) => e.target.files?.[0] && importXml(e.target.files[0])} />
        </label>
        <button type="button" onClick={exportXml} title="Download the plan file that costar run runs">
          Export
        </button>
        <button type="button" onClick={check} title="Check the plan against this cell: its operations, waypoints, frames, gripper">
          Check
        </button>
        <span className="separator" />
        <button type="button" className="run" disabled={refusedRun !== null} title={refusedRun ?? 'Run the plan on the cell (saves it first)'} onClick={() => run(false)}>
          ▶ Run
        </button>
        <button
          type="button"
          disabled={refusedControl !== null}
          title={refusedControl ?? (paused ? 'Go on from where it paused' : 'Hold the run: the cell stands still, no time limit runs out')}
          onClick={() => control(paused ? 'resume' : 'pause')}
        >
          {paused ? 'Resume' : 'Pause'}
        </button>
        <button
          type="button"
          disabled={stepRefusal !== null}
          title={stepRefusal ?? (activeRun !== null ? 'Tick the paused run once' : 'Start the plan paused, ticked one step')}
          onClick={() => (activeRun !== null ? control('step') : run(true))}
        >
          Step
        </button>
        <button type="button" className="stop" disabled={refusedControl !== null} title={refusedControl ?? 'Stop the run: the arm decelerates and stops'} onClick={() => control('stop')}>
          ■ Stop
        </button>
        <span
          className={`connection ${connected ? (controls.signedIn ? 'on' : 'look') : 'off'}`}
          title={connected ? (controls.signedIn ? 'connected and signed in' : 'connected, looking only: sign in to change plans or move the robot') : 'not connected to the cell'}
        >
          {connected ? `${info?.workcell ?? 'connected'}${controls.signedIn ? '' : ' (look only)'}` : 'not connected'}
        </span>
      </header>

      {signIn && (
        <SignIn
          problem={signIn}
          onToken={(t) => {
            storeToken(t);
            setToken(t);
            setTokenRefused(false);
            setSignIn(null);
          }}
          onDismiss={() => setSignIn(null)}
        />
      )}
      {help && <HelpOverlay onClose={() => setHelp(false)} />}
      {browsing && (
        <PlanBrowser
          api={api}
          open={plan}
          openName={planName}
          saveRefusal={refusedSave}
          onOpen={(json, name, version) => {
            if (dirty && T.countNodes(plan) > 1 && !confirm('Discard the changes to this plan?')) return;
            loadPlan(json, name, version);
            setBrowsing(false);
            say(`Opened ${name} version ${version}.`);
          }}
          onCompare={(label, entries) => {
            setComparison({ label, entries });
            setBrowsing(false);
          }}
          onRestore={(name, version, newVersion) => {
            setBrowsing(false);
            void api.plan(name, newVersion).then((doc) => {
              loadPlan(doc.plan, doc.name, doc.version);
              say(`Restored ${name} version ${version} as version ${newVersion}.`);
            }, fail);
          }}
          onClose={() => setBrowsing(false)}
          onError={fail}
        />
      )}
      <div className={`status-line ${lastAction?.kind ?? ''}`} role="status">
        <span className="run-label" data-run-result={cellRun && !cellRun.run.active ? cellRun.run.result : ''} data-run-active={cellRun?.run.active ? 'true' : 'false'}>
          {runLabel}
        </span>
        {cellRun && cellRun.run.plan_json && !runIsShown && !replay && (
          <button type="button" className="small" onClick={showRunningPlan} title="Open the plan of this run in the editor">
            Show it
          </button>
        )}
        {lastAction && (
          <span className="message" data-kind={lastAction.kind}>
            {lastAction.text}
          </span>
        )}
        {offer && (
          <button
            type="button"
            className="small offer"
            onClick={() => {
              offer.apply();
            }}
          >
            {offer.label}
          </button>
        )}
      </div>

      <Palette nodes={nodes} disabledReason={replay ? 'replaying a run: Back to editing first' : null} onAdd={addNode} />

      {/* 4: the workspace (and 7: live status on each node) */}
      <section className="pane workspace" aria-label="Behavior tree">
        <h2>
          <span className="pane-number">4</span> Behavior tree
          {planName && !replay && (
            <span className="plan-title">
              {planName}
              {saved ? ` v${saved.version}` : ''}
              {dirty ? ' (changed)' : ''}
            </span>
          )}
          {replay && <span className="replaying">replaying run #{replay.log.id} (read only)</span>}
          {comparison && !replay && (
            <span className="comparing">
              comparing: {comparison.label}
              {comparison.entries.some((e) => e.kind === 'removed') && ` · removed: ${comparison.entries.filter((e) => e.kind === 'removed').map((e) => e.path.split(' › ').pop()).join(', ')}`}
              <button type="button" className="small" onClick={() => setComparison(null)}>
                Stop comparing
              </button>
            </span>
          )}
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
          <button type="button" disabled={!!replay || !selectedKey} title="Move before the previous sibling (Alt+↑)" onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, -1))}>
            ↑
          </button>
          <button type="button" disabled={!!replay || !selectedKey} title="Move after the next sibling (Alt+↓)" onClick={() => selectedKey && edit((p) => T.shiftNode(p, treeId, selectedKey, 1))}>
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
          <button type="button" disabled={!selected || refusedSave !== null} title={refusedSave ?? 'Save the selected node and what is under it by name'} onClick={saveSubtree}>
            Save subtree
          </button>
          <select aria-label="saved subtree" value={subtreeChoice} onChange={(e) => setSubtreeChoice(e.target.value)} onFocus={refreshLists}>
            <option value="">subtrees…</option>
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
        {shownPlan.trees.length > 1 && (
          <div className="tabs">
            {shownPlan.trees.map((t) => (
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
                {t.id === shownPlan.mainTree ? ' (main)' : ''}
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
            paused={!replay && paused}
            runningKey={deepestRunningKey}
            changes={changes}
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
        choices={liveChoices}
        objects={cell?.objects.map((o) => o.name) ?? []}
        trees={plan.trees.map((t) => t.id).filter((id) => id !== treeId)}
        readOnly={!!replay}
        onChange={(name, value, clear) =>
          selectedKey &&
          edit((p) => (clear ?? []).reduce((q, other) => T.setAttribute(q, treeId, selectedKey, other, undefined), T.setAttribute(p, treeId, selectedKey, name, value)))
        }
        onAlongPath={(name, waypoints) => {
          if (!selectedKey) return;
          let last = selectedKey;
          edit((p) => {
            const done = T.alongPath(p, treeId, selectedKey, name, waypoints, kindOf);
            last = done.last;
            return done.plan;
          });
          setSelectedKey(last);
        }}
      />
      <ObjectsPane state={viewState} selectedType={selected?.id ?? null} data={selectedData} shapes={choices?.object_shape} believed={viewBelieved} />
      <View3D
        state={viewState}
        candidates={selectedData?.candidates ?? []}
        selectedWaypoint={selected ? T.attribute(selected, 'waypoint') ?? null : null}
        api={api}
        pointCloudAvailable={info?.features.pointcloud ?? false}
        shapes={choices?.object_shape}
        believed={viewBelieved}
        robot={robot}
        onGrab={replay || !info?.features.free_drive ? undefined : grabTool}
        trajectoryLines={choices?.trajectory_line}
        grasp={shownGraspPose}
        replayLabel={replay ? (replayed ? `run #${replay.log.id} at t = ${replayed.t.toFixed(1)} s (replay)` : `run #${replay.log.id}: no snapshots logged (the cell now)`) : undefined}
      />
      <Waypoints
        state={cell}
        frames={liveChoices?.frame ?? ['world']}
        robot={robot}
        refusal={refusedMotion}
        run={runOperation}
        rename={renameWaypointInCell}
      >
        {info?.features.free_drive && (
          <HandGuiding
            guiding={guiding}
            onGuiding={setGuiding}
            frames={liveChoices?.frame ?? ['world']}
            classes={choices?.object_class ?? []}
            trajectories={choices?.trajectory ?? []}
            graspModes={(nodes.find((n) => n.id === 'TeachGrasp')?.ports.find((p) => p.name === 'mode')?.choices ?? []).filter((m) => m !== '')}
            grasps={choices?.grasp ?? {}}
            shownGrasp={shownGrasp}
            onShowGrasp={setShownGrasp}
            refusal={refusedMotion}
            run={runOperation}
          />
        )}
      </Waypoints>
      <Replay
        api={api}
        runs={runs}
        replay={replay ? { log: replay.log, index: replay.index } : null}
        onRefresh={() => api.runs().then(setRuns, () => undefined)}
        onOpen={openReplay}
        onIndex={(index) => setReplay((r) => (r ? { ...r, index } : r))}
        onClose={() => {
          setReplay(null);
          setTreeId(plan.mainTree);
        }}
      />
    </div>
  );
}
