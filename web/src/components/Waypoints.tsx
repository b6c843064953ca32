// Pane 3: waypoints (the arm's, kept in its waypoint file): jog the arm (along axes, or one of
// the cell's joints), with the tool's pose and the joint angles read out live beside the
// buttons as a pendant shows them; teach where it is, rename, delete, move to one. Every button
// runs one operation of the arm; while the cell would refuse it, it is disabled and says why.

import { useState, type ReactNode } from 'react';
import type { CellState } from '../api';
import { poseReadout, RobotDescription } from '../model/robot';
import { readoutNumber } from '../model/poseText';

interface Props {
  state: CellState | null;
  /** Frames a pose may be taught in: those the world has now. */
  frames: string[];
  robot: RobotDescription | null;
  /** Why the cell would refuse a motion or a change now (disabled with this reason), or null. */
  refusal: string | null;
  run: (node: string, attributes?: Record<string, string>) => void;
  /** Renames a waypoint (the page then offers to rename it in the open plan). */
  rename: (from: string, to: string) => void;
  /** Shown below the teach row (hand guiding, components/HandGuiding.tsx). */
  children?: ReactNode;
}

const AXES = ['x', 'y', 'z'] as const;
const ROTATIONS = ['roll', 'pitch', 'yaw'] as const;

function degrees(rad: number) {
  return readoutNumber((rad * 180) / Math.PI);
}

export function Waypoints({ state, frames, robot, refusal, run, rename, children }: Props) {
  const busy = refusal !== null;
  const why = refusal ?? undefined;
  const [name, setName] = useState('');
  const [kind, setKind] = useState<'pose' | 'joints'>('pose');
  const [frame, setFrame] = useState('world');
  const [step, setStep] = useState(10); // mm or degrees
  const [jogFrame, setJogFrame] = useState<'world' | 'tool'>('world');
  const [renaming, setRenaming] = useState<string | null>(null);
  const [newName, setNewName] = useState('');
  const waypoints = state?.waypoints ?? [];
  const joints = state?.arm.joints ?? [];
  const endpoint = state?.arm.endpoint;
  const tool = endpoint ? poseReadout(endpoint.p, endpoint.q) : null;
  return (
    <section className="pane waypoints" aria-label="Waypoints">
      <h2>
        <span className="pane-number">3</span> Waypoints
      </h2>
      <div className="jog">
        {tool && (
          <div className="tool-readout" aria-label="tool pose" title="The tool centre point in the world (the arm's endpoint), as the arm reports it">
            <span className="readout-label">tool</span>
            <span data-readout="X">X {readoutNumber(tool.x * 1000)}</span>
            <span data-readout="Y">Y {readoutNumber(tool.y * 1000)}</span>
            <span data-readout="Z">Z {readoutNumber(tool.z * 1000)} mm</span>
            <span className="readout-label" />
            <span data-readout="roll">roll {readoutNumber(tool.roll)}°</span>
            <span data-readout="pitch">pitch {readoutNumber(tool.pitch)}°</span>
            <span data-readout="yaw">yaw {readoutNumber(tool.yaw)}°</span>
          </div>
        )}
        <div className="jog-row">
          jog by
          <select value={step} onChange={(e) => setStep(Number(e.target.value))} aria-label="jog step">
            {[1, 5, 10, 50].map((s) => (
              <option key={s} value={s}>
                {s} mm / °
              </option>
            ))}
          </select>
          <select value={jogFrame} onChange={(e) => setJogFrame(e.target.value as 'world' | 'tool')} aria-label="jog frame">
            <option value="world">along world axes</option>
            <option value="tool">along tool axes</option>
          </select>
        </div>
        <div className="jog-grid">
          {[...AXES, ...ROTATIONS].map((axis) => {
            const amount = (sign: number) => String((sign * (AXES.includes(axis as (typeof AXES)[number]) ? step / 1000 : step)));
            return (
              <span key={axis} className="jog-pair">
                <span className="jog-name">{axis}</span>
                <button type="button" disabled={busy} title={why} aria-label={`jog ${axis} minus`} onClick={() => run('JogCartesian', { axis, amount: amount(-1), frame: jogFrame })}>
                  −
                </button>
                <button type="button" disabled={busy} title={why} aria-label={`jog ${axis} plus`} onClick={() => run('JogCartesian', { axis, amount: amount(1), frame: jogFrame })}>
                  +
                </button>
              </span>
            );
          })}
        </div>
        <div className="jog-grid joints">
          {(robot?.joints ?? []).map((joint, i) => (
            <span key={joint.name} className="jog-pair" title={joint.label ? `${joint.label} (${joint.name})` : joint.name} data-joint={i + 1}>
              <span className="jog-name">J{i + 1}</span>
              <button type="button" disabled={busy} title={why} aria-label={`jog J${i + 1} minus`} onClick={() => run('JogJoint', { joint: String(i + 1), degrees: String(-step) })}>
                −
              </button>
              <button type="button" disabled={busy} title={why} aria-label={`jog J${i + 1} plus`} onClick={() => run('JogJoint', { joint: String(i + 1), degrees: String(step) })}>
                +
              </button>
              <span className="readout" data-readout={`J${i + 1}`}>
                {joints[i] !== undefined ? `${degrees(joints[i])}°` : '–'}
              </span>
            </span>
          ))}
        </div>
      </div>
      <div className="teach">
        <input placeholder="new waypoint name" value={name} onChange={(e) => setName(e.target.value)} aria-label="waypoint name" />
        <select value={kind} onChange={(e) => setKind(e.target.value as 'pose' | 'joints')} aria-label="waypoint kind">
          <option value="pose">tool pose</option>
          <option value="joints">joint angles</option>
        </select>
        {kind === 'pose' && (
          <select value={frame} onChange={(e) => setFrame(e.target.value)} aria-label="relative to">
            {frames.map((f) => (
              <option key={f} value={f}>
                in {f}
              </option>
            ))}
          </select>
        )}
        <button
          type="button"
          disabled={busy || !name}
          title={why ?? (!name ? 'name the waypoint first' : 'save where the arm is now')}
          onClick={() => {
            run('Teach', kind === 'pose' ? { waypoint: name, kind, frame } : { waypoint: name, kind });
            setName('');
          }}
        >
          Teach here
        </button>
      </div>
      {children}
      <table className="waypoint-table">
        <tbody>
          {waypoints.map((w) => (
            <tr key={w.name} data-waypoint={w.name}>
              <td>
                {renaming === w.name ? (
                  <input value={newName} onChange={(e) => setNewName(e.target.value)} aria-label="new name" autoFocus />
                ) : (
                  w.name
                )}
                <div className="dim">
                  {w.kind === 'joints' ? 'joint angles' : `in ${w.frame}`}
                  {w.p ? ` · ${w.p.map((v) => v.toFixed(3)).join(', ')}` : ''}
                </div>
              </td>
              <td className="actions">
                {renaming === w.name ? (
                  <>
                    <button
                      type="button"
                      disabled={busy || !newName || newName === w.name}
                      title={why}
                      onClick={() => {
                        rename(w.name, newName);
                        setRenaming(null);
                      }}
                    >
                      OK
                    </button>
                    <button type="button" onClick={() => setRenaming(null)}>
                      Cancel
                    </button>
                  </>
                ) : (
                  <>
                    <button type="button" disabled={busy} title={why} onClick={() => run('Move', { waypoint: w.name })}>
                      Move to
                    </button>
                    <button
                      type="button"
                      disabled={busy}
                      title={why}
                      onClick={() => {
                        setRenaming(w.name);
                        setNewName(w.name);
                      }}
                    >
                      Rename
                    </button>
                    <button
                      type="button"
                      disabled={busy}
                      title={why}
                      onClick={() => {
                        if (confirm(`Delete waypoint '${w.name}'?`)) run('DeleteWaypoint', { waypoint: w.name });
                      }}
                    >
                      Delete
                    </button>
                  </>
                )}
              </td>
            </tr>
          ))}
        </tbody>
      </table>
      {waypoints.length === 0 && <p className="empty">No waypoints yet: jog the arm and teach one.</p>}
    </section>
  );
}
