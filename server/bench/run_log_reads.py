#!/usr/bin/env python3
"""Reads of a long run log while the live stream runs (issue 27): figures for docs/BENCHMARKS.md.

Starts `costar serve -w test` on a store holding one run of 120,000 transitions (written here
with sqlite3, as the run-log writer writes them: every 10th transition a FAILURE with a reason,
every 3rd with an operation's result data, 27 MB as the API's JSON), then has READERS clients
read the whole log at once, each as the page does (GET /api/runs/ID, then the pages that
`next_from` names; a server without pages answers everything in the first), while a WebSocket
client of the live stream times the gaps between state snapshots and another client times
GET /api/info. Prints the server's memory (VmRSS before, VmHWM during, VmRSS after), each full
read's wall time, the largest stream gap and the slowest /api/info.

Usage: server/bench/run_log_reads.py PATH/TO/costar [--readers 6] [--transitions 120000]
Stdlib only; works with any costar build (to compare before and after a change).
"""

import argparse
import base64
import json
import os
import re
import socket
import sqlite3
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request


def start_server(costar, store, token_file):
    process = subprocess.Popen(
        [costar, "serve", "-w", "test", "--store", store, "--port", "0", "--token-file", token_file, "--pace", "1"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    for line in process.stdout:
        if line.startswith("listening on http://127.0.0.1:"):
            port = int(line.split(":")[2].split("/")[0])
            threading.Thread(target=lambda: [None for _ in process.stdout], daemon=True).start()
            return process, port
    raise RuntimeError("costar serve did not start")


def stop_server(process):
    process.terminate()
    process.wait(timeout=30)


def write_long_run(store, run_id, transitions):
    db = sqlite3.connect(store)
    xml = ('<root BTCPP_format="4"><BehaviorTree ID="main"><Repeat num_cycles="-1"><Sequence>'
           '<TestLog message="a"/><TestLog message="b"/></Sequence></Repeat></BehaviorTree></root>')
    db.execute("INSERT INTO runs (id, plan, version, xml, started_at, result, ended_at, clock_seconds, transitions) "
               "VALUES (?, 'long', 1, ?, 1.0, 'STOPPED', 2.0, ?, ?)", (run_id, xml, transitions * 0.01, transitions))
    nodes = [(0, -1, "Repeat", "", "main/Repeat[1]"), (1, 0, "Sequence", "", "main/Repeat[1]/Sequence[1]"),
             (2, 1, "TestLog", "", "main/Repeat[1]/Sequence[1]/TestLog[1]"),
             (3, 1, "TestLog", "", "main/Repeat[1]/Sequence[1]/TestLog[2]")]
    db.executemany("INSERT INTO run_nodes (run, uid, parent, id, name, path) VALUES (?, ?, ?, ?, ?, ?)",
                   [(run_id,) + n for n in nodes])
    data = json.dumps({"candidates": [{"object": f"node_{i}", "cost": 0.1 * i, "feasible": i % 2 == 0,
                                       "reason": "collision with the table"} for i in range(4)]})
    rows = []
    for seq in range(1, transitions + 1):
        uid = seq % 4
        failure = seq % 10 == 0
        rows.append((run_id, seq, seq * 0.01, uid, "RUNNING", "FAILURE" if failure else "SUCCESS",
                     "no reachable candidate for the link: 3 candidates, none feasible" if failure else "",
                     nodes[uid][4] if failure else "", data if seq % 3 == 0 else ""))
    db.executemany("INSERT INTO transitions (run, seq, t, uid, from_status, to_status, reason, origin, data) "
                   "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)", rows)
    db.commit()
    db.close()


def get(port, path):
    with urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=600) as response:
        return response.read()


NEXT_FROM = re.compile(rb'"next_from":(null|[0-9]+)')


def read_whole_log(port, run_id):
    """As the page reads it: the run with its first page, then each page `next_from` names.
    Not parsed as JSON here (that would hold Python's lock and delay the stream's watcher)."""
    count, size, path = 0, 0, f"/api/runs/{run_id}"
    while path:
        body = get(port, path)
        count += body.count(b'"seq":')
        size += len(body)
        found = NEXT_FROM.search(body)
        path = f"/api/runs/{run_id}/transitions?from={int(found[1])}" if found and found[1] != b"null" else None
    return count, size


class StreamWatcher:
    """A WebSocket client of /api/stream that records when each state snapshot arrives."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port))
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n")
                          .encode())
        self.buffer = b""
        while b"\r\n\r\n" not in self.buffer:
            self.buffer += self.sock.recv(4096)
        self.buffer = self.buffer.split(b"\r\n\r\n", 1)[1]
        self.times = []
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def need(self, n):
        while len(self.buffer) < n:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise EOFError
            self.buffer += chunk

    def run(self):
        message = b""
        try:
            while not self.stop:
                self.need(2)
                fin, length = self.buffer[0] & 0x80, self.buffer[1] & 0x7F
                header = 2
                if length == 126:
                    self.need(4)
                    length, header = struct.unpack(">H", self.buffer[2:4])[0], 4
                elif length == 127:
                    self.need(10)
                    length, header = struct.unpack(">Q", self.buffer[2:10])[0], 10
                self.need(header + length)
                message += self.buffer[header:header + length]
                self.buffer = self.buffer[header + length:]
                if fin:
                    if b'"type":"state"' in message:
                        self.times.append(time.monotonic())
                    message = b""
        except (EOFError, OSError):
            pass

    def max_gap(self, start, end):
        times = [t for t in self.times if start <= t <= end]
        return max((b - a for a, b in zip(times, times[1:])), default=float("nan"))


def memory_kb(pid, field):
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("costar")
    parser.add_argument("--readers", type=int, default=6)
    parser.add_argument("--transitions", type=int, default=120000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        store = os.path.join(folder, "editor.sqlite")
        token = os.path.join(folder, "token")
        process, _ = start_server(args.costar, store, token)  # creates the store's tables
        stop_server(process)
        write_long_run(store, 1, args.transitions)
        process, port = start_server(args.costar, store, token)
        try:
            time.sleep(1.0)
            rss_before = memory_kb(process.pid, "VmRSS")
            watcher = StreamWatcher(port)
            info_times = []
            load_running = threading.Event()
            load_running.set()

            def poll_info():
                while load_running.is_set():
                    start = time.monotonic()
                    get(port, "/api/info")
                    info_times.append(time.monotonic() - start)
                    time.sleep(0.1)

            time.sleep(1.0)
            poller = threading.Thread(target=poll_info, daemon=True)
            poller.start()
            results = [None] * args.readers

            def reader(i):
                start = time.monotonic()
                count, size = read_whole_log(port, 1)
                results[i] = (time.monotonic() - start, count, size)

            start = time.monotonic()
            readers = [threading.Thread(target=reader, args=(i,)) for i in range(args.readers)]
            for thread in readers:
                thread.start()
            for thread in readers:
                thread.join()
            end = time.monotonic()
            load_running.clear()
            poller.join()
            time.sleep(2.0)
            rss_peak = memory_kb(process.pid, "VmHWM")
            rss_after = memory_kb(process.pid, "VmRSS")
            gap_during = watcher.max_gap(start, end)
            watcher.stop = True
        finally:
            stop_server(process)
    walls = sorted(r[0] for r in results)
    print(f"costar: {args.costar}")
    print(f"log: {results[0][1]} transitions, {results[0][2] / 1e6:.1f} MB of JSON per full read")
    print(f"{args.readers} concurrent full reads: {end - start:.2f} s wall in all; each {walls[0]:.2f}-{walls[-1]:.2f} s")
    print(f"server memory: VmRSS {rss_before / 1024:.0f} MB before, VmHWM {rss_peak / 1024:.0f} MB, "
          f"VmRSS {rss_after / 1024:.0f} MB 2 s after")
    print(f"live stream: largest gap between state snapshots during the reads {gap_during * 1000:.0f} ms "
          f"(50 ms at 20 Hz)")
    print(f"GET /api/info during the reads: slowest {max(info_times) * 1000:.0f} ms of {len(info_times)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
