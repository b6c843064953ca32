// The live stream (WebSocket /api/stream): hello, then run_started / statuses / run_ended
// events and state snapshots. Reconnects by itself.

import type { CellState, Info, RunInfo } from './api';
import type { NodeStatus } from './model/status';

export type StreamMessage =
  | { type: 'hello'; info: Info; run: RunInfo | null; state: CellState }
  | { type: 'state' } & CellState
  | { type: 'run_started'; run: RunInfo }
  | { type: 'statuses'; run: number; nodes: NodeStatus[] }
  | { type: 'run_ended'; run: RunInfo }
  | { type: 'auth'; ok: boolean }
  | { type: 'scene_reset'; t: number }
  | { type: 'control'; action: string; ok: boolean }
  | { type: 'error'; error: string };

export interface StreamHandlers {
  onMessage: (message: StreamMessage) => void;
  onConnection: (connected: boolean) => void;
}

export class Stream {
  private socket: WebSocket | null = null;
  private closed = false;
  private retry = 500;

  constructor(
    private token: string,
    private handlers: StreamHandlers,
  ) {
    this.connect();
  }

  private connect() {
    const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
    const socket = new WebSocket(`${scheme}://${location.host}/api/stream`);
    this.socket = socket;
    socket.onopen = () => {
      this.retry = 500;
      if (this.token) socket.send(JSON.stringify({ type: 'auth', token: this.token }));
      this.handlers.onConnection(true);
    };
    socket.onmessage = (event) => {
      try {
        this.handlers.onMessage(JSON.parse(event.data as string) as StreamMessage);
      } catch {
        // ignore a message that is not JSON
      }
    };
    socket.onclose = () => {
      this.handlers.onConnection(false);
      if (!this.closed) {
        setTimeout(() => this.connect(), this.retry);
        this.retry = Math.min(this.retry * 2, 5000);
      }
    };
  }

  send(message: unknown) {
    if (this.socket?.readyState === WebSocket.OPEN) this.socket.send(JSON.stringify(message));
  }

  close() {
    this.closed = true;
    this.socket?.close();
  }
}
