// Teaching by demonstration (docs/TEACHING.md), under the waypoint pane: the guiding mode the
// tool's handle in the 3D view moves the arm in (Franka's: free, translation only, rotation only,
// world axes locked: x, y, z), recording the guided path as a trajectory, replaying one, and teaching a grasp
// of the part the gripper is around now (SmartMove's relative transform for that class), drawn on
// the parts of that class in the 3D view (the one taught last, or any of the class's chosen).

import { useState } from 'react';
import type { Guiding } from '../model/handGuide';

interface Props {
  guiding: Guiding;
  onGuiding: (guiding: Guiding) => void;
  /** Frames a recording or a replay may be relative to (detected parts, table_center...). */
  frames: string[];
  classes: string[];
  trajectories: string[];
  /** The gripper's modes a grasp may need (TeachGrasp's mode: the 3-finger gripper's); none: no choice. */
  graspModes: string[];
  /** The grasps of each class (GET /api/choices), for the one drawn on the parts. */
  grasps: Record<string, string[]>;
  /** The grasp drawn on the parts in the 3D view (the one taught last, or chosen), or null. */
  shownGrasp: ShownGrasp | null;
  onShowGrasp: (shown: ShownGrasp | null) => void;
  refusal: string | null;
  run: (node: string, attributes?: Record<string, string>) => void;
}

export interface ShownGrasp {
  objectClass: string;
  name: string;
}

const MODES: { mode: Guiding['mode']; label: string; title: string }[] = [
  { mode: 'free', label: 'Free', title: 'the tool moves and turns as it is pushed' },
  { mode: 'translation', label: 'Translate', title: 'the tool keeps its orientation' },
  { mode: 'rotation', label: 'Rotate', title: 'the tool keeps its place and turns' },
];

export function HandGuiding({ guiding, onGuiding, frames, classes, trajectories, graspModes, grasps, shownGrasp, onShowGrasp, refusal, run }: Props) {
  const busy = refusal !== null;
  const why = refusal ?? undefined;
  const [graspClass, setGraspClass] = useState('');
  const [graspName, setGraspName] = useState('');
  const [graspMode, setGraspMode] = useState('');
  const [replay, setReplay] = useState('');
  const [replayFrame, setReplayFrame] = useState('');
  const objectClass = graspClass || classes[0] || '';
  const chosen = replay || trajectories[0] || '';
  return (
    <div className="hand-guiding" aria-label="Hand guiding">
      <div className="guide-row" title="Grab the sphere at the tool in the 3D view and drag: the arm follows while the pointer is held">
        guide by hand
        {MODES.map((m) => (
          <button
            key={m.mode}
            type="button"
            className="small"
            aria-pressed={guiding.mode === m.mode}
            title={m.title}
            onClick={() => onGuiding({ ...guiding, mode: m.mode })}
          >
            {m.label}
          </button>
        ))}
        lock
        {(['x', 'y', 'z'] as const).map((axis) => (
          <label key={axis} title={`the tool keeps its world ${axis}${axis === 'z' ? ' (its height)' : ''}`}>
            <input
              type="checkbox"
              checked={guiding.locked.includes(axis)}
              aria-label={`lock ${axis}`}
              onChange={(e) => onGuiding({ ...guiding, locked: e.target.checked ? [...guiding.locked, axis] : guiding.locked.filter((a) => a !== axis) })}
            />
            {axis}
          </label>
        ))}
      </div>
      <div className="guide-row">
        <input
          placeholder="record the next drag as…"
          title="the next drag of the tool is recorded under this name (a trajectory), relative to the frame beside"
          value={guiding.record}
          aria-label="trajectory name"
          onChange={(e) => onGuiding({ ...guiding, record: e.target.value })}
        />
        <select value={guiding.recordFrame} aria-label="record relative to" onChange={(e) => onGuiding({ ...guiding, recordFrame: e.target.value })}>
          {frames.map((f) => (
            <option key={f} value={f}>
              in {f}
            </option>
          ))}
        </select>
      </div>
      <div className="guide-row">
        <select value={chosen} aria-label="trajectory" onChange={(e) => setReplay(e.target.value)}>
          {trajectories.length === 0 && <option value="">(no trajectories recorded)</option>}
          {trajectories.map((t) => (
            <option key={t} value={t}>
              {t}
            </option>
          ))}
        </select>
        <select value={replayFrame} aria-label="replay relative to" onChange={(e) => setReplayFrame(e.target.value)}>
          <option value="">as recorded</option>
          {frames.map((f) => (
            <option key={f} value={f}>
              in {f}
            </option>
          ))}
        </select>
        <button
          type="button"
          disabled={busy || !chosen}
          title={why ?? 'replay the trajectory (FollowTrajectory)'}
          onClick={() => run('FollowTrajectory', replayFrame ? { trajectory: chosen, frame: replayFrame } : { trajectory: chosen })}
        >
          Replay
        </button>
      </div>
      <div className="guide-row">
        <select value={objectClass} aria-label="grasp class" onChange={(e) => setGraspClass(e.target.value)}>
          {classes.map((c) => (
            <option key={c} value={c}>
              {c}
            </option>
          ))}
        </select>
        {graspModes.length > 0 && (
          <select value={graspMode} aria-label="grasp mode" title="the gripper mode SmartGrasp sets for this grasp" onChange={(e) => setGraspMode(e.target.value)}>
            <option value="">mode it is in</option>
            {graspModes.map((m) => (
              <option key={m} value={m}>
                {m}
              </option>
            ))}
          </select>
        )}
        <input placeholder="grasp name" value={graspName} aria-label="grasp name" onChange={(e) => setGraspName(e.target.value)} />
        <button
          type="button"
          disabled={busy || !graspName || !objectClass}
          title={why ?? (!graspName ? 'name the grasp first' : 'the gripper is around a detected part of this class now: SmartGrasp will hold parts of it like this')}
          onClick={() => {
            run('TeachGrasp', graspMode ? { object_class: objectClass, grasp: graspName, mode: graspMode } : { object_class: objectClass, grasp: graspName });
            onShowGrasp({ objectClass, name: graspName });
            setGraspName('');
          }}
        >
          Teach grasp
        </button>
        <select
          value={shownGrasp && shownGrasp.objectClass === objectClass ? shownGrasp.name : ''}
          aria-label="grasp shown"
          title="the grasp drawn on the parts of this class in the 3D view: where SmartGrasp puts the tool centre point"
          onChange={(e) => onShowGrasp(e.target.value ? { objectClass, name: e.target.value } : null)}
        >
          <option value="">draw no grasp</option>
          {(grasps[objectClass] ?? []).map((g) => (
            <option key={g} value={g}>
              draw {g}
            </option>
          ))}
        </select>
      </div>
    </div>
  );
}
