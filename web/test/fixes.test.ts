import { describe, expect, it } from 'vitest';
import * as T from '../src/model/tree';
import { fixFor, renameWaypoint, waypointUses } from '../src/model/fixes';

const ports = (type: string) => (type === 'Move' ? ['waypoint'] : []);

describe("curing Check's problems", () => {
  it('wraps the children of a decorator that has more than one in a Sequence', () => {
    const plan = T.fromPlanJson({
      main_tree: 'main',
      trees: [{ id: 'main', root: { id: 'Repeat', attributes: [['num_cycles', '-1']], children: [{ id: 'Open' }, { id: 'Close' }] } }],
    });
    const root = plan.trees[0].root!;
    const fix = fixFor('Repeat needs exactly one child, has 2', 'main', root, null);
    expect(fix?.label).toBe('Wrap the 2 children in a Sequence');
    const fixed = fix!.apply(plan).trees[0].root!;
    expect(fixed.children).toHaveLength(1);
    expect(fixed.children[0].id).toBe('Sequence');
    expect(fixed.children[0].children.map((c) => c.id)).toEqual(['Open', 'Close']);
    expect(fixFor('Repeat needs exactly one child, has 0', 'main', root, null)).toBeNull();
  });

  it("takes a leaf's children out, after it", () => {
    const plan = T.fromPlanJson({
      main_tree: 'main',
      trees: [{ id: 'main', root: { id: 'Sequence', children: [{ id: 'Open', children: [{ id: 'Home' }] }, { id: 'Close' }] } }],
    });
    const root = plan.trees[0].root!;
    const fix = fixFor('Open is a leaf and cannot have children, has 1', 'main', root.children[0], root);
    expect(fix!.apply(plan).trees[0].root!.children.map((c) => `${c.id}/${c.children.length}`)).toEqual(['Open/0', 'Home/0', 'Close/0']);
  });
});

describe('a waypoint renamed in the cell', () => {
  const plan = T.fromPlanJson({
    main_tree: 'main',
    trees: [
      { id: 'main', root: { id: 'Sequence', children: [{ id: 'Move', attributes: [['waypoint', 'over_left']] }, { id: 'SubTree', attributes: [['ID', 'place']] }] } },
      { id: 'place', root: { id: 'Move', attributes: [['name', 'over_left'], ['waypoint', 'over_left']] } },
    ],
  });

  it('counts the nodes of every tree that name it, and renames them there only', () => {
    expect(waypointUses(plan, 'over_left', ports)).toBe(2);
    const renamed = renameWaypoint(plan, 'over_left', 'above_left', ports);
    expect(waypointUses(renamed, 'over_left', ports)).toBe(0);
    expect(waypointUses(renamed, 'above_left', ports)).toBe(2);
    // A node's name that happens to be the waypoint's stays.
    expect(T.attribute(renamed.trees[1].root!, 'name')).toBe('over_left');
    // Nodes that do not use it keep their identity (their run badges stay).
    expect(renamed.trees[0].root!.children[1]).toBe(plan.trees[0].root!.children[1]);
  });
});
