// Pane 5: customise the selected operation. Every parameter whose values the system knows is
// a list (waypoints, frames, object classes, grasps, predicates, fixed choices), never free text.

import type { Choices, NodeInfo, PortInfo } from '../api';
import type { EditorNode } from '../model/tree';
import { formatPredicates, parsePredicates, PredicateTerm, referenceChoices } from '../model/predicates';
import { formatPoseText, parsePoseText, POSE_FIELDS, PoseFields } from '../model/poseText';
import { argumentKinds, argumentWords, waypointPaths } from '../model/paths';
import { boundProblem, boundText, rangeProblem, rangeText, toPlan, toShown, unitOf } from '../model/units';

interface Props {
  node: EditorNode | null;
  info: NodeInfo | undefined;
  choices: Choices | null;
  objects: string[];
  trees: string[];
  readOnly: boolean;
  /** Sets one parameter; `clear` names others removed in the same edit (one undo step). */
  onChange: (name: string, value: string | undefined, clear?: string[]) => void;
  /** The node to each of these waypoints in turn: copies of it after it, one per waypoint (one undo step). */
  onAlongPath: (name: string, waypoints: string[]) => void;
}

function value(node: EditorNode, name: string): string | undefined {
  return node.attributes.find(([k]) => k === name)?.[1];
}

function Select(props: {
  id: string;
  current: string | undefined;
  options: string[];
  placeholder: string;
  disabled: boolean;
  onChange: (value: string | undefined) => void;
}) {
  const options = [...props.options];
  // A value the cell does not offer now (a waypoint renamed, a part no longer seen) stays shown,
  // marked, until it is changed: Check flags it.
  const unknown = props.current !== undefined && props.current !== '' && !options.includes(props.current);
  if (unknown) options.unshift(props.current!);
  return (
    <select
      id={props.id}
      value={props.current ?? ''}
      disabled={props.disabled}
      className={unknown ? 'unknown-choice' : undefined}
      title={unknown ? `'${props.current}' is not in the cell now` : undefined}
      onChange={(e) => props.onChange(e.target.value === '' ? undefined : e.target.value)}
    >
      <option value="">{props.placeholder}</option>
      {options.map((option) => (
        <option key={option} value={option}>
          {option === '' ? '(none)' : unknown && option === props.current ? `${option} (not in the cell now)` : option}
        </option>
      ))}
    </select>
  );
}

/** A pose or an offset as labelled fields: x, y, z in millimetres, roll, pitch, yaw in degrees. */
function PoseInput(props: { id: string; text: string | undefined; disabled: boolean; onChange: (value: string | undefined) => void }) {
  const fields = parsePoseText(props.text);
  if (!fields) {
    return (
      <div id={props.id} className="pose-fields">
        <span className="reason">'{props.text}' is not a pose (x;y;z or x;y;z;roll;pitch;yaw, m and degrees)</span>
        <button type="button" disabled={props.disabled} onClick={() => props.onChange(undefined)}>
          Clear
        </button>
      </div>
    );
  }
  const set = (key: keyof PoseFields, value: string) => {
    const number = Number(value);
    if (value.trim() === '' || !Number.isFinite(number)) return;
    props.onChange(formatPoseText({ ...fields, [key]: number }));
  };
  return (
    <div id={props.id} className="pose-fields" role="group" aria-label="pose">
      {POSE_FIELDS.map(({ key, label, unit }) => (
        <label key={key} className="pose-field">
          <span>
            {label} <span className="unit">{unit}</span>
          </span>
          <input
            type="number"
            step={unit === 'mm' ? 1 : 5}
            aria-label={`${label} (${unit === 'mm' ? 'millimetres' : 'degrees'})`}
            data-pose-field={key}
            value={Number(fields[key].toFixed(unit === 'mm' ? 1 : 3))}
            disabled={props.disabled}
            onChange={(e) => set(key, e.target.value)}
          />
        </label>
      ))}
    </div>
  );
}

/**
 * A path of waypoints (PressAndFollow's `path`): the waypoints in order, each removable; a whole
 * path taught as one (names sharing a prefix: row1_start, row1_end) set at once, or one
 * waypoint added at the end.
 */
function PathInput(props: { id: string; text: string | undefined; waypoints: string[]; disabled: boolean; onChange: (value: string | undefined) => void }) {
  const list = (props.text ?? '').split(';').map((w) => w.trim()).filter((w) => w !== '');
  const paths = waypointPaths(props.waypoints);
  const set = (next: string[]) => props.onChange(next.length ? next.join(';') : undefined);
  return (
    <div id={props.id} className="path-list" role="group" aria-label="path">
      {list.length === 0 && <span className="hint">no waypoints yet</span>}
      <ol>
        {list.map((w, i) => (
          <li key={`${i}-${w}`}>
            <span className={props.waypoints.includes(w) ? undefined : 'unknown-choice'} title={props.waypoints.includes(w) ? undefined : `'${w}' is not in the cell now`}>
              {w}
            </span>
            <button type="button" className="remove-condition" disabled={props.disabled} aria-label={`remove ${w}`} onClick={() => set(list.filter((_, k) => k !== i))}>
              ✕
            </button>
          </li>
        ))}
      </ol>
      {paths.length > 0 && (
        <select
          aria-label="whole path"
          className="whole-path"
          value=""
          disabled={props.disabled}
          onChange={(e) => {
            const path = paths.find((p) => p.prefix === e.target.value);
            if (path) set(path.waypoints);
          }}
        >
          <option value="">the whole path…</option>
          {paths.map((p) => (
            <option key={p.prefix} value={p.prefix} title={p.waypoints.join(' → ')}>
              {p.prefix}… ({p.waypoints.length}: {p.waypoints[0]} → {p.waypoints[p.waypoints.length - 1]})
            </option>
          ))}
        </select>
      )}
      <select aria-label="add waypoint" className="add-condition" value="" disabled={props.disabled} onChange={(e) => e.target.value && set([...list, e.target.value])}>
        <option value="">+ waypoint…</option>
        {props.waypoints.map((w) => (
          <option key={w} value={w}>
            {w}
          </option>
        ))}
      </select>
    </div>
  );
}

/** A number in the unit a technician states it in (mm, mm/s, N), with its range, the number of the node it must
 * stay below (a force below max_force) and why a value is refused. */
function NumberInput(props: {
  id: string;
  port: PortInfo;
  ports: PortInfo[];
  attributes: [string, string][];
  current: string | undefined;
  disabled: boolean;
  onChange: (value: string | undefined) => void;
}) {
  const { port } = props;
  const unit = unitOf(port);
  const range = [rangeText(port), boundText(port, props.ports, props.attributes)].filter((t) => t !== '').join(', ');
  const problem = rangeProblem(port, props.current) ?? boundProblem(port, props.ports, props.attributes);
  const placeholder = port.default !== undefined ? `default: ${toShown(unit, port.default) || '(none)'}` : 'type a number';
  return (
    <div className="number-port">
      <span className="number-field">
        <input
          id={props.id}
          type="number"
          step={port.type === 'int' ? 1 : 'any'}
          placeholder={placeholder}
          value={toShown(unit, props.current)}
          disabled={props.disabled}
          aria-invalid={problem !== null}
          onChange={(e) => props.onChange(toPlan(unit, e.target.value))}
        />
        {unit && <span className="unit">{unit.shown}</span>}
      </span>
      {range && <span className="hint range">{range}</span>}
      {problem && (
        <span className="reason" role="alert">
          {problem}
        </span>
      )}
    </div>
  );
}

function PredicateList(props: {
  id: string;
  text: string;
  choices: Choices;
  references: string[];
  disabled: boolean;
  onChange: (value: string | undefined) => void;
}) {
  const terms = parsePredicates(props.text);
  const arity = (name: string) => props.choices.predicate.find((p) => p.name === name)?.arity ?? 1;
  const update = (next: PredicateTerm[]) => {
    const text = formatPredicates(next);
    props.onChange(text === '' ? undefined : text);
  };
  const withArity = (name: string, args: string[]) => {
    // The part is the first argument; the others are references the user picks.
    const count = Math.max(0, arity(name) - 1);
    const rest = args.filter((a) => a !== '?').slice(0, count);
    const reference = props.references.includes('table_center') ? 'table_center' : props.references[0] ?? 'world';
    while (rest.length < count) rest.push(reference);
    return rest;
  };
  return (
    <div className="predicate-list" id={props.id}>
      {terms.map((term, i) => (
        <div className="predicate-row" key={i}>
          <select
            value={term.name}
            disabled={props.disabled}
            aria-label="predicate"
            onChange={(e) => {
              const next = [...terms];
              next[i] = { name: e.target.value, args: withArity(e.target.value, term.args) };
              update(next);
            }}
          >
            {props.choices.predicate
              .filter((p) => p.arity >= 1)
              .map((p) => (
                <option key={p.name} value={p.name} title={p.description}>
                  {p.name}
                </option>
              ))}
          </select>
          <span className="predicate-part">(part</span>
          {term.args
            .filter((a) => a !== '?')
            .map((arg, j) => (
              <span key={j} className="predicate-arg">
                ,
                <select
                  value={arg}
                  disabled={props.disabled}
                  className={props.references.includes(arg) ? undefined : 'unknown-choice'}
                  title={props.references.includes(arg) ? undefined : `'${arg}' is not in the cell now`}
                  aria-label="reference"
                  onChange={(e) => {
                    const next = [...terms];
                    const args = [...next[i].args.filter((a) => a !== '?')];
                    args[j] = e.target.value;
                    next[i] = { ...next[i], args };
                    update(next);
                  }}
                >
                  {referenceChoices(arg, props.references).map((r) => (
                    <option key={r.value} value={r.value}>
                      {r.label}
                    </option>
                  ))}
                </select>
              </span>
            ))}
          <span>)</span>
          <button
            type="button"
            className="remove-condition"
            disabled={props.disabled}
            onClick={() => update(terms.filter((_, k) => k !== i))}
            aria-label="remove condition"
          >
            ✕
          </button>
        </div>
      ))}
      <select
        aria-label="add condition"
        className="add-condition"
        value=""
        disabled={props.disabled}
        onChange={(e) => {
          const name = e.target.value;
          if (name) update([...terms, { name, args: withArity(name, []) }]);
        }}
      >
        <option value="">+ condition…</option>
        {props.choices.predicate
          .filter((p) => p.arity >= 1)
          .map((p) => (
            <option key={p.name} value={p.name} title={p.description}>
              {p.name}(part{p.arity > 1 ? ', …' : ''})
            </option>
          ))}
      </select>
    </div>
  );
}

export function NodeEditor({ node, info, choices, objects, trees, readOnly, onChange, onAlongPath }: Props) {
  if (!node) {
    return (
      <section className="pane editor" aria-label="Customise">
        <h2>
          <span className="pane-number">5</span> Customise
        </h2>
        <p className="empty">Select a node in the tree.</p>
      </section>
    );
  }
  const frames = choices?.frame ?? ['world'];
  // Parameters that cannot stand with the new value: those the port excludes (SmartRelease's
  // target and target_class), and a grasp not taught for a newly chosen class.
  const changedWith = (port: PortInfo, v: string): string[] => {
    const clear = [...(port.excludes ?? [])].filter((name) => value(node, name) !== undefined);
    if (port.name === 'object_class') {
      const grasp = value(node, 'grasp');
      if (grasp !== undefined && !(choices?.grasp?.[v] ?? []).includes(grasp)) clear.push('grasp');
    }
    return clear;
  };
  const references = [...new Set([...frames, ...objects, ...(choices?.object_class ?? [])])];
  const inputFor = (port: PortInfo) => {
    const id = `port-${port.name}`;
    const current = value(node, port.name);
    const placeholder = port.default !== undefined ? `default: ${port.default === '' ? '(none)' : port.default}` : 'choose…';
    if (node.id === 'SubTree' && port.name === 'ID') {
      return <Select id={id} current={current} options={trees} placeholder="choose a tree…" disabled={readOnly} onChange={(v) => onChange(port.name, v)} />;
    }
    if (node.id === 'CheckPredicate' && port.name === 'args') {
      const predicate = choices?.predicate.find((p) => p.name === value(node, 'predicate'));
      const arity = predicate?.arity ?? 0;
      const kinds = argumentKinds(predicate?.description ?? '', arity);
      const words = argumentWords(predicate?.description ?? '', arity);
      const args = (current ?? '').split(';').filter((a) => a !== '');
      while (args.length < arity) args.push('');
      const setArg = (i: number, v: string | undefined) => {
        const next = [...args.slice(0, arity)];
        next[i] = v ?? '';
        onChange(port.name, next.join(';'));
      };
      return (
        <div id={id} className="args">
          {arity === 0 && <span className="hint">no arguments</span>}
          {args.slice(0, arity).map((arg, i) =>
            kinds[i] === 'number' ? (
              <span key={i} className="number-field">
                <input
                  id={`${id}-${i}`}
                  type="number"
                  step="any"
                  placeholder="newtons"
                  value={arg}
                  disabled={readOnly}
                  aria-invalid={arg !== '' && !Number.isFinite(Number(arg))}
                  onChange={(e) => setArg(i, e.target.value)}
                />
                <span className="unit">N</span>
              </span>
            ) : (
              <Select
                key={i}
                id={`${id}-${i}`}
                current={arg || undefined}
                options={words[i] ?? (kinds[i] === 'waypoint' ? choices?.waypoint ?? [] : ['?', ...references])}
                placeholder="choose…"
                disabled={readOnly}
                onChange={(v) => setArg(i, v)}
              />
            ),
          )}
        </div>
      );
    }
    if (port.choices_from === 'predicate' && choices) {
      return <PredicateList id={id} text={current ?? ''} choices={choices} references={references} disabled={readOnly} onChange={(v) => onChange(port.name, v)} />;
    }
    if (port.choices_from === 'waypoint' && port.type.includes('vector')) {
      return <PathInput id={id} text={current} waypoints={choices?.waypoint ?? []} disabled={readOnly} onChange={(v) => onChange(port.name, v)} />;
    }
    let list: string[] | undefined = port.choices;
    let shownPlaceholder = placeholder;
    if (port.choices_from === 'waypoint') list = choices?.waypoint ?? [];
    if (port.choices_from === 'trajectory') list = choices?.trajectory ?? [];
    if (port.choices_from === 'frame') list = frames;
    if (port.choices_from === 'object_class') list = port.choices ?? choices?.object_class ?? [];
    if (port.choices_from === 'grasp') {
      const objectClass = value(node, 'object_class');
      const grasps = choices?.grasp ?? {};
      list = objectClass ? grasps[objectClass] ?? [] : [...new Set(Object.values(grasps).flat())];
      if (port.default === '') shownPlaceholder = `default: the first taught${objectClass && list[0] ? ` (${list[0]})` : ''}`;
    }
    if (list && port.extra_choices) list = [...port.extra_choices, ...list.filter((c) => !port.extra_choices!.includes(c))];
    if (list && port.choices_from === 'waypoint') {
      // One waypoint (Move's): or a path taught as one, a copy of the node to each of its waypoints.
      const paths = waypointPaths(list);
      return (
        <div className="waypoint-port">
          <Select id={id} current={current} options={list} placeholder={shownPlaceholder} disabled={readOnly} onChange={(v) => onChange(port.name, v)} />
          {paths.length > 0 && (
            <select
              aria-label="along a path"
              className="whole-path"
              value=""
              disabled={readOnly}
              title={`a ${node.id} to each waypoint of a path taught as one, in order, with this node's other parameters`}
              onChange={(e) => {
                const path = paths.find((p) => p.prefix === e.target.value);
                if (path) onAlongPath(port.name, path.waypoints);
              }}
            >
              <option value="">{`a ${node.id} to each of a path…`}</option>
              {paths.map((p) => (
                <option key={p.prefix} value={p.prefix} title={p.waypoints.join(' → ')}>
                  {p.prefix}… ({p.waypoints.length}: {p.waypoints[0]} → {p.waypoints[p.waypoints.length - 1]})
                </option>
              ))}
            </select>
          )}
        </div>
      );
    }
    if (list) {
      // The empty choice of an optional list is its default: shown by the placeholder.
      const options = port.default === '' ? list.filter((c) => c !== '') : list;
      return (
        <Select
          id={id}
          current={current}
          options={options}
          placeholder={shownPlaceholder}
          disabled={readOnly}
          onChange={(v) => onChange(port.name, v, v !== undefined ? changedWith(port, v) : undefined)}
        />
      );
    }
    if (port.type === 'int' || port.type === 'double') {
      return (
        <NumberInput
          id={id}
          port={port}
          ports={info?.ports ?? []}
          attributes={node.attributes}
          current={current}
          disabled={readOnly}
          onChange={(v) => onChange(port.name, v)}
        />
      );
    }
    if (port.type === 'costar::Pose') {
      return <PoseInput id={id} text={current} disabled={readOnly} onChange={(v) => onChange(port.name, v)} />;
    }
    return (
      <input
        id={id}
        type="text"
        placeholder={placeholder}
        value={current ?? ''}
        disabled={readOnly}
        onChange={(e) => onChange(port.name, e.target.value === '' ? undefined : e.target.value)}
      />
    );
  };
  return (
    <section className="pane editor" aria-label="Customise">
      <h2>
        <span className="pane-number">5</span> Customise: <span className={`cat-text cat-${info?.category}`}>{node.id}</span>
      </h2>
      {info && <p className="description">{info.description}</p>}
      <div className="ports">
        <label htmlFor="port-name">name</label>
        <input
          id="port-name"
          type="text"
          placeholder="(optional)"
          value={value(node, 'name') ?? ''}
          disabled={readOnly}
          onChange={(e) => onChange('name', e.target.value === '' ? undefined : e.target.value)}
        />
        {(info?.ports ?? []).map((port) => (
          <div className="port" key={port.name} title={port.description}>
            <label htmlFor={`port-${port.name}`}>
              {port.name}
              {port.default === undefined && value(node, port.name) === undefined && <span className="required"> required</span>}
            </label>
            {inputFor(port)}
          </div>
        ))}
      </div>
      {!info && <p className="reason">Unknown node type '{node.id}' for this workcell.</p>}
    </section>
  );
}
