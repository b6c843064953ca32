// The saved plans and every version of each (the store keeps them all): open any version,
// compare it with the plan open now (a tree diff: nodes added, removed, changed and their
// attributes), or restore it (saved again as the newest version; the versions after it stay).

import { useEffect, useState } from 'react';
import type { Api } from '../api';
import { describeEntry, DiffEntry, diffPlans } from '../model/diff';
import * as T from '../model/tree';

interface Props {
  api: Api;
  /** The plan open now and its name, to compare with. */
  open: T.EditorPlan;
  openName: string;
  /** Why saving (restore) is refused now, or null. */
  saveRefusal: string | null;
  onOpen: (plan: T.PlanJson, name: string, version: number) => void;
  /** Shows a comparison on the open plan's tree (older: the version compared with). */
  onCompare: (label: string, entries: DiffEntry[]) => void;
  onRestore: (name: string, version: number, newVersion: number) => void;
  onClose: () => void;
  onError: (error: unknown) => void;
}

function when(seconds: number) {
  return new Date(seconds * 1000).toLocaleString();
}

export function PlanBrowser({ api, open, openName, saveRefusal, onOpen, onCompare, onRestore, onClose, onError }: Props) {
  const [plans, setPlans] = useState<{ name: string; latest_version: number; versions: number; updated_at?: number }[]>([]);
  const [chosen, setChosen] = useState(openName);
  const [versions, setVersions] = useState<{ version: number; saved_at: number }[]>([]);
  const [comparison, setComparison] = useState<{ label: string; entries: DiffEntry[] } | null>(null);

  useEffect(() => {
    api.plans().then(setPlans, onError);
    // eslint-disable-next-line react-hooks/exhaustive-deps
  }, [api]);
  useEffect(() => {
    setComparison(null);
    if (!chosen) {
      setVersions([]);
      return;
    }
    api.versions(chosen).then(setVersions, () => setVersions([]));
  }, [api, chosen]);

  const compare = async (version: number) => {
    try {
      const doc = await api.plan(chosen, version);
      const entries = diffPlans(T.fromPlanJson(doc.plan), open);
      const label = `${chosen} v${version} → the open plan${openName ? ` (${openName})` : ''}`;
      setComparison({ label, entries });
    } catch (e) {
      onError(e);
    }
  };

  return (
    <div className="overlay" role="dialog" aria-label="Plans and versions" onClick={(e) => e.target === e.currentTarget && onClose()}>
      <div className="plan-browser">
        <h2>Plans and versions</h2>
        <div className="browser-columns">
          <ul className="plan-list" aria-label="saved plans">
            {plans.length === 0 && <li className="empty">No plan saved yet.</li>}
            {plans.map((p) => (
              <li key={p.name}>
                <button type="button" className={p.name === chosen ? 'chosen' : ''} data-plan={p.name} onClick={() => setChosen(p.name)}>
                  {p.name} <span className="dim">v{p.latest_version}</span>
                </button>
              </li>
            ))}
          </ul>
          <div className="version-list">
            {chosen && (
              <table aria-label="versions">
                <tbody>
                  {versions.map((v) => (
                    <tr key={v.version} data-version={v.version}>
                      <td>
                        v{v.version}
                        {v.version === versions[0]?.version ? ' (newest)' : ''}
                      </td>
                      <td className="dim">{when(v.saved_at)}</td>
                      <td className="actions">
                        <button
                          type="button"
                          title="Open this version in the editor (saving it makes a new version)"
                          onClick={async () => {
                            try {
                              const doc = await api.plan(chosen, v.version);
                              onOpen(doc.plan, doc.name, doc.version);
                            } catch (e) {
                              onError(e);
                            }
                          }}
                        >
                          Open
                        </button>
                        <button type="button" title="What changed from this version to the plan open now" onClick={() => compare(v.version)}>
                          Compare
                        </button>
                        <button
                          type="button"
                          disabled={saveRefusal !== null || v.version === versions[0]?.version}
                          title={saveRefusal ?? (v.version === versions[0]?.version ? 'this is the newest version' : 'Save this version again as the newest one (the others stay)')}
                          onClick={async () => {
                            try {
                              const doc = await api.plan(chosen, v.version);
                              const saved = await api.importPlan(chosen, doc.xml);
                              onRestore(chosen, v.version, saved.version);
                            } catch (e) {
                              onError(e);
                            }
                          }}
                        >
                          Restore
                        </button>
                      </td>
                    </tr>
                  ))}
                </tbody>
              </table>
            )}
            {comparison && (
              <div className="comparison" aria-label="comparison">
                <h3>{comparison.label}</h3>
                {comparison.entries.length === 0 ? (
                  <p className="dim">No difference.</p>
                ) : (
                  <ul>
                    {comparison.entries.map((entry, i) => (
                      <li key={i} className={`diff-${entry.kind}`} data-diff={entry.kind}>
                        {describeEntry(entry)}
                      </li>
                    ))}
                  </ul>
                )}
                <button type="button" onClick={() => onCompare(comparison.label, comparison.entries)}>
                  Show on the tree
                </button>
              </div>
            )}
          </div>
        </div>
        <div className="browser-buttons">
          <button type="button" onClick={onClose}>
            Close
          </button>
        </div>
      </div>
    </div>
  );
}
