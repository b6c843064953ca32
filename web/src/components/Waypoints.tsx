// Pane 3: waypoints (the arm's, kept in its waypoint file): jog the arm, teach where it is,
// rename, delete, move to one. Every button runs one operation of the arm.

import { useState } from 'react';
import type { CellState, Choices } from '../api';

interface Props {
  state: CellState | null;
  choices: Choices | null;
  busy: boolean;
  run: (node: string, attributes?: Record<string, string>) => void;
}

const AXES = ['x', 'y', 'z'] as const;
const ROTATIONS = ['roll', 'pitch', 'yaw'] as const;

export function Waypoints({ state, choices, busy, run }: Props) {
  const [name, setName] = useState('');
  const [kind, setKind] = useState<'pose' | 'joints'>('pose');
  const [frame, setFrame] = useState('world');
  const [step, setStep] = useState(10); // mm or degrees
  const [jogFrame, setJogFrame] = useState<'world' | 'tool'>('world');
  const [renaming, setRenaming] = useState<string | null>(null);
  const [newName, setNewName] = useState('');
  const waypoints = state?.waypoints ?? [];
  const joints = state?.arm.joints ?? [];
  return (
    <section className="pane waypoints" aria-label="Waypoints">
      <h2>
        <span className="pane-number">3</span> Waypoints
      </h2>
      <div className="jog">
        <div className="jog-row">
          step
          <select value={step} onChange={(e) => setStep(Number(e.target.value))} aria-label="jog step">
            {[1, 5, 10, 50].map((s) => (
              <option key={s} value={s}>
                {s} mm / °
              </option>
            ))}
          </select>
          <select value={jogFrame} onChange={(e) => setJogFrame(e.target.value as 'world' | 'tool')} aria-label="jog frame">
            <option value="world">world axes</option>
            <option value="tool">tool axes</option>
          </select>
        </div>
        <div className="jog-row">
          {AXES.map((axis) => (
            <span key={axis} className="jog-pair">
              {axis}
              <button type="button" disabled={busy} onClick={() => run('JogCartesian', { axis, amount: String(-step / 1000), frame: jogFrame })}>
                −
              </button>
              <button type="button" disabled={busy} onClick={() => run('JogCartesian', { axis, amount: String(step / 1000), frame: jogFrame })}>
                +
              </button>
            </span>
          ))}
          {ROTATIONS.map((axis) => (
            <span key={axis} className="jog-pair">
              {axis}
              <button type="button" disabled={busy} onClick={() => run('JogCartesian', { axis, amount: String(-step), frame: jogFrame })}>
                −
              </button>
              <button type="button" disabled={busy} onClick={() => run('JogCartesian', { axis, amount: String(step), frame: jogFrame })}>
                +
              </button>
            </span>
          ))}
        </div>
        <div className="jog-row">
          {[1, 2, 3, 4, 5, 6].map((j) => (
            <span key={j} className="jog-pair" title={joints[j - 1] !== undefined ? `${((joints[j - 1] * 180) / Math.PI).toFixed(1)}°` : ''}>
              J{j}
              <button type="button" disabled={busy} onClick={() => run('JogJoint', { joint: String(j), degrees: String(-step) })}>
                −
              </button>
              <button type="button" disabled={busy} onClick={() => run('JogJoint', { joint: String(j), degrees: String(step) })}>
                +
              </button>
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
            {(choices?.frame ?? ['world']).map((f) => (
              <option key={f} value={f}>
                in {f}
              </option>
            ))}
          </select>
        )}
        <button
          type="button"
          disabled={busy || !name}
          onClick={() => {
            run('Teach', kind === 'pose' ? { waypoint: name, kind, frame } : { waypoint: name, kind });
            setName('');
          }}
        >
          Teach here
        </button>
      </div>
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
                      disabled={busy || !newName}
                      onClick={() => {
                        run('RenameWaypoint', { waypoint: w.name, new_name: newName });
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
                    <button type="button" disabled={busy} onClick={() => run('Move', { waypoint: w.name })}>
                      Move to
                    </button>
                    <button
                      type="button"
                      disabled={busy}
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
