// What the cell would refuse, said before a click: every control the server would answer with an
// error is disabled and says why (its tooltip, the status line). The cell's state decides, not the
// page's: a run started from another page or before a reload counts the same.

export interface CellControlState {
  /** The live stream is open. */
  connected: boolean;
  /** The page has a token the server has not refused. */
  signedIn: boolean;
  /** The active run or operation, if any (id; plan runs count up, operations down). */
  activeRun: number | null;
  /** A past run is being replayed in the tree. */
  replaying: boolean;
}

export const NOT_CONNECTED = 'not connected to the cell: wait for the connection to come back';
export const SIGN_IN = 'Sign in to change plans or move the robot';

function busy(state: CellControlState): string | null {
  if (state.activeRun === null) return null;
  return state.activeRun > 0
    ? `run #${state.activeRun} is active: stop it or wait for it to end`
    : 'an operation is running: wait for it to end or stop it';
}

/** Why a control that moves the robot (Run, a jog, Home, Move to, Teach, ...) is refused, or null. */
export function motionRefusal(state: CellControlState): string | null {
  if (!state.connected) return NOT_CONNECTED;
  if (!state.signedIn) return SIGN_IN;
  return busy(state);
}

/** Why starting the open plan (Run, Step from idle) is refused, or null. */
export function runRefusal(state: CellControlState): string | null {
  if (state.replaying) return 'replaying a run: Back to editing first';
  return motionRefusal(state);
}

/** Why Stop, Pause, Resume or Step on the active run is refused, or null. */
export function controlRefusal(state: CellControlState): string | null {
  if (!state.connected) return NOT_CONNECTED;
  if (!state.signedIn) return SIGN_IN;
  if (state.activeRun === null) return 'nothing is running';
  return null;
}

/** Why a change to the store (Save, saving a subtree) is refused, or null. */
export function saveRefusal(state: CellControlState): string | null {
  if (!state.connected) return NOT_CONNECTED;
  if (!state.signedIn) return SIGN_IN;
  if (state.replaying) return 'replaying a run: Back to editing first';
  return null;
}

/** Why "Reset scene" is refused, or null. */
export function resetRefusal(state: CellControlState): string | null {
  const refusal = motionRefusal(state);
  return refusal === null ? null : refusal.replace('wait for it to end', 'wait for it to end before resetting the scene');
}
