// Replay: pick a past run (the store's run log, each run labelled with its cell) and scrub
// through its status transitions; the 3D view and the Objects pane show the cell as the run's
// log has it at that moment.

import { useEffect, useState } from 'react';
import type { Api, RunLog, StoredRun } from '../api';

interface Props {
  api: Api;
  /** The run log, newest first. */
  runs: StoredRun[];
  replay: { log: RunLog; index: number } | null;
  onRefresh: () => void;
  onOpen: (log: RunLog) => void;
  onIndex: (index: number) => void;
  onClose: () => void;
}

export function Replay({ api, runs, replay, onRefresh, onOpen, onIndex, onClose }: Props) {
  const [playing, setPlaying] = useState(false);
  const [error, setError] = useState('');

  useEffect(() => {
    if (!playing || !replay) return;
    if (replay.index >= replay.log.transition_list.length) {
      setPlaying(false);
      return;
    }
    const timer = setTimeout(() => onIndex(replay.index + 1), 60);
    return () => clearTimeout(timer);
  }, [playing, replay, onIndex]);

  const transitions = replay?.log.transition_list ?? [];
  const current = replay && replay.index > 0 ? transitions[replay.index - 1] : undefined;
  return (
    <section className="pane replay" aria-label="Replay">
      <h2>
        <span className="pane-number">7</span> Runs &amp; replay
      </h2>
      {error && <p className="reason">{error}</p>}
      <div className="replay-pick">
        <select
          aria-label="past run"
          value={replay?.log.id ?? ''}
          onFocus={onRefresh}
          onChange={async (e) => {
            const id = Number(e.target.value);
            if (!id) return;
            try {
              setError('');
              onOpen(await api.runLog(id));
            } catch (err) {
              setError((err as Error).message);
            }
          }}
        >
          <option value="">pick a past run…</option>
          {runs.map((run) => (
            <option key={run.id} value={run.id}>
              #{run.id}
              {run.workcell ? ` ${run.workcell}` : ''} · {run.plan || '(unsaved plan)'}
              {run.version ? ` v${run.version}` : ''} · {run.result || 'running'} ·{' '}
              {new Date(run.started_at * 1000).toLocaleTimeString()}
            </option>
          ))}
        </select>
        {replay && (
          <button type="button" onClick={onClose}>
            Back to editing
          </button>
        )}
      </div>
      {replay && (
        <div className="scrub">
          <button type="button" onClick={() => setPlaying(!playing)}>
            {playing ? 'Pause' : 'Play'}
          </button>
          <input
            type="range"
            aria-label="replay position"
            min={0}
            max={transitions.length}
            value={replay.index}
            onChange={(e) => onIndex(Number(e.target.value))}
          />
          <span className="dim">
            {replay.index}/{transitions.length}
            {current ? ` · t=${current.t.toFixed(2)} s · ${replay.log.nodes[current.uid]?.id ?? ''} → ${current.to}` : ''}
          </span>
          <p className="dim">
            Run #{replay.log.id}: {replay.log.result}
            {replay.log.failure_reason ? ` — ${replay.log.failure_reason}` : ''} ({replay.log.clock_seconds.toFixed(2)} s)
          </p>
        </div>
      )}
    </section>
  );
}
