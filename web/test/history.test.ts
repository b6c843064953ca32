import { describe, expect, it } from 'vitest';
import { canRedo, canUndo, HISTORY_LIMIT, push, redo, replace, startHistory, undo } from '../src/model/history';

describe('undo and redo', () => {
  it('undoes and redoes in order, and a new edit drops the redo list', () => {
    let h = startHistory('a');
    h = push(h, 'b');
    h = push(h, 'c');
    expect(canUndo(h)).toBe(true);
    expect(canRedo(h)).toBe(false);
    h = undo(h);
    expect(h.present).toBe('b');
    h = undo(h);
    expect(h.present).toBe('a');
    expect(canUndo(h)).toBe(false);
    expect(undo(h)).toBe(h);
    h = redo(h);
    expect(h.present).toBe('b');
    h = push(h, 'd');
    expect(canRedo(h)).toBe(false);
    expect(h.past).toEqual(['a', 'b']);
  });

  it('ignores no-op edits and keeps folding out of the undo list', () => {
    let h = startHistory({ v: 1 });
    const same = push(h, h.present);
    expect(same).toBe(h);
    h = replace(h, { v: 2 });
    expect(h.past.length).toBe(0);
    expect(h.present).toEqual({ v: 2 });
  });

  it('keeps at most HISTORY_LIMIT steps', () => {
    let h = startHistory(0);
    for (let i = 1; i <= HISTORY_LIMIT + 50; i++) h = push(h, i);
    expect(h.past.length).toBe(HISTORY_LIMIT);
    for (let i = 0; i < HISTORY_LIMIT; i++) h = undo(h);
    expect(h.present).toBe(50);
  });
});
