// The server's HTTP API (docs/EDITOR.md). Changes carry the token: Authorization: Bearer.

import type { PlanJson } from './model/tree';
import type { NodeStatus, RunNode, Transition } from './model/status';
import type { FingerReading, RobotDescription } from './model/robot';
import type { GraspPose } from './model/graspDrawing';

export interface PortInfo {
  name: string;
  type: string;
  description: string;
  default?: string;
  choices?: string[];
  choices_from?: string;
  /** Offered besides the choices_from list (SmartRelease's target: 'table'). */
  extra_choices?: string[];
  /** Parameters cleared when this one is set (they cannot be given together). */
  excludes?: string[];
  min?: number;
  max?: number;
  /** Another number of the same node this one must stay below (MoveUntilContact's force: 'max_force'). */
  less_than?: string;
}

export interface NodeInfo {
  id: string;
  kind: 'Control' | 'Decorator' | 'Action' | 'Condition' | 'SubTree';
  category: 'internal' | 'robot_action' | 'knowledge';
  description: string;
  asynchronous: boolean;
  component?: string;
  ports: PortInfo[];
  /** Why this cell refuses it whatever the plan (a 2-finger gripper's Scissor mode): not offered. */
  unavailable?: string;
}

export interface Choices {
  waypoint: string[];
  frame: string[];
  object_class: string[];
  predicate: { name: string; arity: number; description: string }[];
  grasp: Record<string, string[]>;
  /** Each grasp's tool centre point in its class's frame ({p, q [x, y, z, w]}) and the gripper mode it needs. */
  grasp_pose?: Record<string, Record<string, GraspPose>>;
  /** Each object class's shape (boxes in its frame, metres) and named colours (RGB in [0, 1]). */
  object_shape?: Record<string, ObjectShape>;
  /** Trajectories recorded by hand guiding (FreeDrive's record), and their kept points in the world. */
  trajectory?: string[];
  trajectory_line?: Record<string, { frame: string; points: [number, number, number][] }>;
}

export interface ObjectShape {
  boxes: { center: [number, number, number]; half_size: [number, number, number] }[];
  colors: { name: string; rgb: [number, number, number] }[];
}

export interface Info {
  workcell: string;
  description: string;
  simulator: boolean;
  features: { detect: boolean; calibrate: boolean; pointcloud: boolean; detect_node: string; calibrate_node: string; free_drive?: boolean };
  pace?: number;
}

export interface Pose {
  p: [number, number, number];
  q: [number, number, number, number];
}

export interface CellState {
  type: 'state';
  t: number;
  run: number;
  mode: 'idle' | 'running' | 'paused';
  /** wrench: the wrist sensor's (N, N m, in the tool frame); in_contact: it reads more than 4 N. */
  arm: {
    joints?: number[];
    endpoint?: Pose;
    moving?: boolean;
    wrench?: { frame: string; force: [number, number, number]; torque: [number, number, number] };
    in_contact?: boolean;
  };
  /** The power tool, on cells that have one: speed in `unit` (opm: per minute). */
  tool?: { speed: number; unit: string; on: boolean; at_speed: boolean; held: boolean; docked: boolean };
  /** The speed and separation monitor, when the scene has a person (docs/PERSON.md): the sensed
   * separation and the protective distance (m), the speed override (0 held .. 1 full speed). */
  safety?: { separation: number; protective_distance: number; speed_scale: number; slowed: boolean; stopped: boolean; collaborative: boolean };
  /** reading: the gripper_fingers symbol (2 fingers: their opening, m; 3 fingers: each one's position, 0 open .. 1 closed). */
  gripper: { open: boolean; closed: boolean; holding: boolean; mode?: string; reading?: FingerReading };
  /** color: the mean RGB ([0, 1]) DetectObjects saw on the part, when it reported one. */
  objects: (Pose & { name: string; class: string; color?: [number, number, number] })[];
  waypoints: (Partial<Pose> & { name: string; kind: 'pose' | 'joints'; frame?: string })[];
  frames: (Pose & { name: string; parent: string })[];
  predicates: string[];
}

export interface RunInfo {
  id: number;
  kind: 'plan' | 'operation';
  plan: string;
  version: number;
  label: string;
  /** The cell it runs on. */
  workcell?: string;
  active: boolean;
  paused?: boolean;
  /** A plan run's plan (the editor's JSON): any page can show what runs. */
  plan_json?: PlanJson;
  result: string;
  failure_path?: string;
  failure_reason?: string;
  clock_seconds: number;
  nodes?: RunNode[];
  statuses?: NodeStatus[];
  stopped?: boolean;
}

export interface StoredRun {
  id: number;
  plan: string;
  version: number;
  workcell?: string;
  started_at: number;
  result: string;
  clock_seconds: number;
  transitions: number;
  failure_reason?: string;
}

export interface RunLog extends StoredRun {
  xml: string;
  plan_json: PlanJson | null;
  nodes: RunNode[];
  transition_list: Transition[];
  /** The seq of the next page of transitions; null after the last. */
  next_from?: number | null;
}

export interface Diagnostic {
  where: string;
  line: number;
  message: string;
  node?: { tree: string; path: number[] };
}

export class ApiError extends Error {
  constructor(
    message: string,
    public status: number,
    public diagnostics: Diagnostic[] = [],
  ) {
    super(message);
  }
}

export class Api {
  constructor(public token: string) {}

  private async request<T>(method: string, path: string, body?: unknown): Promise<T> {
    const headers: Record<string, string> = {};
    if (body !== undefined) headers['Content-Type'] = 'application/json';
    if (this.token) headers.Authorization = `Bearer ${this.token}`;
    const response = await fetch(path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
    const text = await response.text();
    let json: unknown = null;
    try {
      json = text ? JSON.parse(text) : null;
    } catch {
      json = null;
    }
    if (!response.ok) {
      const error = (json as { error?: string; diagnostics?: Diagnostic[] }) ?? {};
      throw new ApiError(error.error ?? `${response.status} ${response.statusText}`, response.status, error.diagnostics);
    }
    return json as T;
  }

  info = () => this.request<Info>('GET', '/api/info');
  nodes = () => this.request<NodeInfo[]>('GET', '/api/nodes');
  choices = () => this.request<Choices>('GET', '/api/choices');
  state = () => this.request<CellState>('GET', '/api/state');
  plans = () => this.request<{ name: string; latest_version: number; versions: number }[]>('GET', '/api/plans');
  plan = (name: string, version?: number) =>
    this.request<{ name: string; version: number; saved_at: number; xml: string; plan: PlanJson }>(
      'GET',
      `/api/plans/${encodeURIComponent(name)}${version ? `?version=${version}` : ''}`,
    );
  savePlan = (name: string, plan: PlanJson) =>
    this.request<{ name: string; version: number }>('PUT', `/api/plans/${encodeURIComponent(name)}`, { plan });
  importPlan = (name: string, xml: string) =>
    this.request<{ name: string; version: number }>('PUT', `/api/plans/${encodeURIComponent(name)}`, { xml });
  deletePlan = (name: string) => this.request('DELETE', `/api/plans/${encodeURIComponent(name)}`);
  subtrees = () => this.request<{ name: string; latest_version: number }[]>('GET', '/api/subtrees');
  subtree = (name: string) =>
    this.request<{ name: string; version: number; plan: PlanJson }>('GET', `/api/subtrees/${encodeURIComponent(name)}`);
  saveSubtree = (name: string, plan: PlanJson) =>
    this.request<{ name: string; version: number }>('PUT', `/api/subtrees/${encodeURIComponent(name)}`, { plan });
  validate = (plan: PlanJson, name?: string) =>
    this.request<{ valid: boolean; diagnostics: Diagnostic[]; xml: string }>('POST', '/api/validate', name ? { plan, name } : { plan });
  convertXml = (xml: string) =>
    this.request<{ valid: boolean; diagnostics: Diagnostic[]; xml: string; plan: PlanJson }>('POST', '/api/validate', {
      xml,
    });
  runPlan = (plan: PlanJson, paused = false) => this.request<{ run: number }>('POST', '/api/runs', { plan, paused });
  runSaved = (name: string, version?: number, paused = false) =>
    this.request<{ run: number }>('POST', '/api/runs', { name, version, paused });
  control = (action: 'pause' | 'resume' | 'step' | 'stop') => this.request('POST', '/api/control', { action });
  operation = (node: string, attributes: Record<string, string> = {}) =>
    this.request<{ run: number }>('POST', '/api/operations', { node, attributes });
  /**
   * Free-drive's hand: a push on the tool (N, N m, world) for 0.25 s, holding the dead-man 2 s,
   * answered with why free-drive held back its last step ('' when it did not: a contact ahead, a
   * joint limit, near a singularity) and its speed (m/s); or let go.
   */
  drag = (body: { force: [number, number, number]; torque?: [number, number, number] } | { release: true }) =>
    this.request<{ ok: string; blocked?: string; speed?: number }>('POST', '/api/drag', body);
  runStatus = (id: number) => this.request<RunInfo>('GET', `/api/runs/${id}`);
  runs = () => this.request<StoredRun[]>('GET', '/api/runs');
  /** A logged run with every transition: the server answers a long log in pages. */
  runLog = async (id: number) => {
    const log = await this.request<RunLog>('GET', `/api/runs/${id}`);
    for (let from = log.next_from; from != null; ) {
      const page = await this.request<{ transition_list: Transition[]; next_from: number | null }>(
        'GET',
        `/api/runs/${id}/transitions?from=${from}`,
      );
      log.transition_list.push(...page.transition_list);
      from = page.next_from;
    }
    return log;
  };
  versions = (name: string) =>
    this.request<{ version: number; saved_at: number }[]>('GET', `/api/plans/${encodeURIComponent(name)}/versions`);
  robot = () => this.request<RobotDescription>('GET', '/api/robot');
  resetScene = () => this.request<{ reset: boolean }>('POST', '/api/scene/reset');
  runStates = (id: number) => this.request<{ run: number; states: { t: number; state: CellState }[] }>('GET', `/api/runs/${id}/states`);
  pointCloud = (max = 20000) =>
    this.request<{ points: number[]; colors: number[]; t?: number }>('GET', `/api/pointcloud?max=${max}`);
}
