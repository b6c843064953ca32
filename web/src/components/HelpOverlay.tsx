// The keyboard shortcuts, listed over the page (the ? key, or the "?" button).

export const HELP_SHORTCUTS: [string, string][] = [
  ['click an operation (6)', 'insert it after the selected node, or inside it if it takes children'],
  ['click · Shift+click · Ctrl+click', 'select a node · a range of its siblings · one more node'],
  ['Ctrl+C · Ctrl+X · Ctrl+V', 'copy · cut · paste (after the selected node, or inside it)'],
  ['Ctrl+D', 'duplicate the selected nodes right after them'],
  ['Delete or Backspace', 'delete the selected nodes and what is under them'],
  ['arrow keys', 'move the selection: to the parent, the first child, the previous or next sibling'],
  ['Alt+arrow', 'move the selected node among its siblings'],
  ['Space', 'fold or unfold the selected node'],
  ['Ctrl+Z · Ctrl+Y (Ctrl+Shift+Z)', 'undo · redo'],
  ['Ctrl+S', 'save the plan'],
  ['wheel · Ctrl+wheel or pinch · drag', 'scroll · zoom · pan the tree'],
  ['F', 'fit the whole tree into the pane (the Fit button)'],
  ['M', 'larger tree: fold away the cell, the waypoints and the runs, and back (the ⤢ button)'],
  ['drag a node onto another', 'its leading or trailing edge: before or after it; its middle: inside it'],
  ['? or F1 · Escape', 'this list · close it'],
];

export function HelpOverlay({ onClose }: { onClose: () => void }) {
  return (
    <div className="overlay" role="dialog" aria-label="Keyboard shortcuts" onClick={onClose}>
      <div className="help" onClick={(e) => e.stopPropagation()}>
        <h2>Keyboard shortcuts</h2>
        <table>
          <tbody>
            {HELP_SHORTCUTS.map(([keys, what]) => (
              <tr key={keys}>
                <th>{keys}</th>
                <td>{what}</td>
              </tr>
            ))}
          </tbody>
        </table>
        <button type="button" onClick={onClose}>
          Close
        </button>
      </div>
    </div>
  );
}
