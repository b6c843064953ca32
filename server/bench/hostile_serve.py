#!/usr/bin/env python3
"""A stranger attacks a running `costar serve` whose simulated arm is moving (issue 27).

Starts `costar serve -w CELL` on a fresh store that already holds a plan and a run log of
120,000 transitions, starts a plan that moves the arm up and down forever, then sends classes of
hostile requests with and without the token, while a WebSocket client times the live stream and
the server's memory is sampled. After each request the server must still be alive, and after
each class it must still answer, with the arm's run still active. Prints, per class: attempts,
crashes (the server died or stopped answering), 5xx answers, security findings (a refused kind
of request accepted: a Host or Origin that is not this server's, a change without the token, a
hostile plan saved or called valid), data loss (the saved plan or the long log changed), the
largest gap of the live stream and the server's peak memory. Then SIGTERM with the arm moving
(exit 0, the run logged STOPPED, the plan and the long log intact after a restart), and rounds of
kill -9 while the arm moves and plans are saved (every acknowledged save is there after a
restart). Exit 0 when every count is 0. scripts/hostile_server.sh runs it on every cell.

Usage: server/bench/hostile_serve.py PATH/TO/costar [--workcell ur5-sim] [--transitions 120000] [--kills 5]
Stdlib only (no browser needed: the requests are written byte by byte).
"""

import argparse
import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_log_reads import StreamWatcher, memory_kb, read_whole_log, stop_server, write_long_run  # noqa: E402

MOVING_PLAN = ('<root BTCPP_format="4"><BehaviorTree ID="move"><Repeat num_cycles="-1"><Sequence>'
               '<MoveRelative offset="0;0;0.06" speed="0.05"/><MoveRelative offset="0;0;-0.06" speed="0.05"/>'
               '</Sequence></Repeat></BehaviorTree></root>')
KEEP_PLAN = ('<root BTCPP_format="4"><BehaviorTree ID="keep"><Sequence name="kept">'
             '<AlwaysSuccess/></Sequence></BehaviorTree></root>')


def start(costar, workcell, folder):
    waypoints = os.path.join(folder, "waypoints.json")
    if not os.path.exists(waypoints):
        with open(waypoints, "w") as out:
            out.write('{"waypoints": []}\n')
    command = [costar, "serve", "-w", workcell, "--store", os.path.join(folder, "editor.sqlite"), "--port", "0",
               "--token-file", os.path.join(folder, "token"), "--waypoints", waypoints, "--pace", "1"]
    stderr = open(os.path.join(folder, "stderr.txt"), "a")
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr, text=True)
    for line in process.stdout:
        if line.startswith("listening on http://127.0.0.1:"):
            threading.Thread(target=lambda: [None for _ in process.stdout], daemon=True).start()
            with open(os.path.join(folder, "token")) as token:
                return process, int(line.split(":")[2].split("/")[0]), token.read().strip()
    raise RuntimeError("costar serve did not start: " + open(os.path.join(folder, "stderr.txt")).read()[-2000:])


def exchange(port, data, timeout=60.0):
    """Sends raw bytes on one connection; the status of the (first) answer and its body, or
    (0, reason) when no answer came."""
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout) as sock:
            try:
                sock.sendall(data)
            except OSError:
                pass  # the server may answer and close before reading everything (413)
            received = b""
            while True:
                try:
                    chunk = sock.recv(1 << 16)
                except (socket.timeout, ConnectionResetError):
                    break
                if not chunk:
                    break
                received += chunk
                head, _, body = received.partition(b"\r\n\r\n")
                length = re.search(rb"(?i)content-length: *([0-9]+)", head)
                if length and len(body) >= int(length[1]):
                    break
                if received.startswith(b"HTTP/1.1 101"):
                    break
    except OSError as error:
        return 0, str(error)
    match = re.match(rb"HTTP/1\.[01] ([0-9]{3})", received)
    if not match:
        return 0, "no answer" if not received else "not HTTP: " + repr(received[:80])
    return int(match[1]), received.partition(b"\r\n\r\n")[2].decode("utf-8", "replace")


def request(method, target, body=b"", token=None, host="127.0.0.1", headers=b""):
    if isinstance(body, str):
        body = body.encode()
    text = f"{method} {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n".encode() + headers
    if token:
        text += f"Authorization: Bearer {token}\r\n".encode()
    if body or method in ("POST", "PUT"):
        text += f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\n".encode()
    return text + b"\r\n" + body


def upgrade(host, origin):
    text = (f"GET /api/stream HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n")
    if origin is not None:
        text += f"Origin: {origin}\r\n"
    return (text + "\r\n").encode()


def frame(opcode, payload, fin=True, rsv=0, mask=True, length=None):
    """One WebSocket frame as a client writes it (masked unless told), `length` announced in
    place of the payload's."""
    n = len(payload) if length is None else length
    head = bytes([(0x80 if fin else 0) | (rsv << 4) | opcode])
    bit = 0x80 if mask else 0
    if n < 126:
        head += bytes([bit | n])
    elif n < 1 << 16:
        head += bytes([bit | 126]) + struct.pack(">H", n)
    else:
        head += bytes([bit | 127]) + struct.pack(">Q", n)
    if not mask:
        return head + payload
    key = os.urandom(4)
    if not payload:
        return head + key
    mask_bytes = (key * (len(payload) // 4 + 1))[:len(payload)]
    return head + key + (int.from_bytes(payload, "big") ^ int.from_bytes(mask_bytes, "big")).to_bytes(len(payload), "big")


def frame_attacks():
    """(what, bytes sent on an open stream) that break the WebSocket protocol or the stream's
    messages."""
    text = lambda data: frame(0x1, data)  # noqa: E731
    return [("unmasked text frame", frame(0x1, b'{"type":"ping"}', mask=False)),
            ("reserved opcode 3", frame(0x3, b"x")), ("reserved opcode 11", frame(0xB, b"x")),
            ("RSV bits set", frame(0x1, b'{"type":"ping"}', rsv=7)),
            ("text that is not UTF-8", text(b'{"type":"ping","x":"\xff\xfe"}')),
            ("ping of 126 bytes", frame(0x9, b"p" * 126)), ("fragmented ping", frame(0x9, b"p", fin=False)),
            ("continuation first", frame(0x0, b"x")),
            ("text inside a fragmented text", frame(0x1, b"{", fin=False) + frame(0x1, b"}")),
            ("2^63 bytes announced", frame(0x2, b"abc", length=(1 << 63) - 1)),
            ("16 MiB announced, 1 KiB sent", frame(0x1, b"a" * 1024, length=16 << 20)),
            ("2 MiB message", text(b'{"type":"ping","pad":"' + b"a" * (2 << 20) + b'"}')),
            ("close code 999", frame(0x8, struct.pack(">H", 999))), ("close of 1 byte", frame(0x8, b"\x03")),
            ("100,000 nested arrays", text(b"[" * 100000)), ("message that is not JSON", text(b"\x00\x01garbage")),
            ("unknown type", text(b'{"type":"shutdown"}')), ("type not a string", text(b'{"type":[1,2]}')),
            ("1,000 pings at once", b"".join(frame(0x9, b"p") for _ in range(1000))),
            ("1,000 ping messages at once", b"".join(text(b'{"type":"ping"}') for _ in range(1000)))]


def chain(trees, loop=False):
    xml = '<root BTCPP_format="4" main_tree_to_execute="T0">\n'
    for i in range(trees):
        nxt = f'<SubTree ID="T{i + 1}"/>' if i + 1 < trees else ('<SubTree ID="T0"/>' if loop else "<AlwaysSuccess/>")
        xml += f'<BehaviorTree ID="T{i}"><Inverter>{nxt}</Inverter></BehaviorTree>\n'
    return xml + "</root>\n"


def hostile_plans():
    """(what, xml or editor JSON) of plans that must be refused."""
    doubling = '<root BTCPP_format="4" main_tree_to_execute="d0">'
    for i in range(40):
        doubling += f'<BehaviorTree ID="d{i}"><Sequence><SubTree ID="d{i + 1}"/><SubTree ID="d{i + 1}"/></Sequence></BehaviorTree>'
    doubling += '<BehaviorTree ID="d40"><AlwaysSuccess/></BehaviorTree></root>'
    wide = "".join("<AlwaysSuccess/>" for _ in range(1000))
    long_name = ('<root BTCPP_format="4" main_tree_to_execute="m"><BehaviorTree ID="m"><Sequence name="' + "n" * 100000 +
                 f'"><SubTree ID="w"/></Sequence></BehaviorTree><BehaviorTree ID="w"><Sequence>{wide}</Sequence>'
                 '</BehaviorTree></root>')
    nested = '<root BTCPP_format="4"><BehaviorTree ID="m">' + "<Inverter>" * 20000 + "<AlwaysSuccess/>" + \
             "</Inverter>" * 20000 + "</BehaviorTree></root>"
    unknown = '<root BTCPP_format="4" main_tree_to_execute="T0">' + "".join(
        f'<BehaviorTree ID="T{i}"><SubTree ID="missing"/></BehaviorTree>' for i in range(10000)) + "</root>"
    json_chain = {"main_tree": "T0", "trees": [
        {"id": f"T{i}", "root": {"id": "Inverter", "children": [
            {"id": "SubTree", "attributes": [["ID", f"T{i + 1}"]]} if i + 1 < 6000 else {"id": "AlwaysSuccess"}]}}
        for i in range(6000)]}
    long_id = '<root BTCPP_format="4"><BehaviorTree ID="m"><' + "Frobnicate" * 90000 + "/></BehaviorTree></root>"
    return [("chain of 11,000 SubTrees", chain(11000)), ("loop of 11,000 SubTrees", chain(11000, loop=True)),
            ("tree used twice at each of 40 levels", doubling), ("100 KB name over 1,000 nodes", long_name),
            ("20,000 nested elements", nested), ("10,000 unknown subtrees", unknown),
            ("900 KB node type name", long_id), ("editor JSON chain of 6,000", json_chain)]


def text_attacks():
    """(what, raw JSON body bytes) with text that is not UTF-8 or not XML characters."""
    def xml_body(name):
        return (b'{"xml": "<root BTCPP_format=\\"4\\"><BehaviorTree ID=\\"m\\"><Sequence name=\\"' + name +
                b'\\"><AlwaysSuccess/></Sequence></BehaviorTree></root>"}')
    return [("name with FF FE", xml_body(b"ok \xff\xfe")), ("name cut in a character", xml_body(b"\xc3")),
            ("encoded surrogate", xml_body(b"\xed\xa0\x80")), ("surrogate reference", xml_body(b"a&#xD800;b")),
            ("decimal surrogate reference", xml_body(b"&#55296;")), ("NUL reference", xml_body(b"&#0;")),
            ("reference beyond U+10FFFF", xml_body(b"&#x110000;")),
            ("overflowing reference", xml_body(b"&#99999999999999999999999;")),
            ("lone surrogate JSON escape", xml_body(b"\\ud800")), ("JSON string with FF", b'{"xml": "\xff"}'),
            ("editor JSON name FF", b'{"plan": {"main_tree": "m", "trees": [{"id": "m", "root": {"id": "Sequence",'
                                    b' "attributes": [["name", "\xff"]], "children": [{"id": "AlwaysSuccess"}]}}]}}'),
            ("editor JSON name with a NUL escape",
             b'{"plan": {"main_tree": "m", "trees": [{"id": "m", "root": {"id": "AlwaysSuccess",'
             b' "attributes": [["name", "a\\u0000b"]]}}]}}')]


class Tally:
    def __init__(self, name):
        self.name, self.attempts, self.crashes, self.errors, self.security, self.loss = name, 0, 0, 0, 0, 0
        self.notes = []

    def note(self, kind, text):
        setattr(self, kind, getattr(self, kind) + 1)
        if len(self.notes) < 8:
            self.notes.append(f"{kind}: {text}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("costar")
    parser.add_argument("--workcell", default="ur5-sim")
    parser.add_argument("--transitions", type=int, default=120000)
    parser.add_argument("--kills", type=int, default=5, help="rounds of kill -9 during a motion and saves")
    args = parser.parse_args()
    folder = tempfile.mkdtemp(prefix="costar_hostile_")
    process, port, token = start(args.costar, args.workcell, folder)
    stop_server(process)
    write_long_run(os.path.join(folder, "editor.sqlite"), 1, args.transitions)
    process, port, token = start(args.costar, args.workcell, folder)
    tallies = []

    def alive(tally, what):
        if process.poll() is not None:
            tally.note("crashes", f"{what}: the server died (exit {process.returncode})")
            return False
        return True

    status, body = exchange(port, request("PUT", "/api/plans/keep", json.dumps({"xml": KEEP_PLAN}), token))
    assert status == 201, (status, body)
    status, body = exchange(port, request("POST", "/api/runs", json.dumps({"xml": MOVING_PLAN}), token))
    assert status == 202, (status, body)
    moving_run = json.loads(body)["run"]
    time.sleep(2.0)
    watcher = StreamWatcher(port)
    peak = [0]
    sampling = [True]

    def sample():
        while sampling[0] and process.poll() is None:
            peak[0] = max(peak[0], memory_kb(process.pid, "VmRSS"))
            time.sleep(0.05)

    threading.Thread(target=sample, daemon=True).start()

    def check(tally, what, data, accept, timeout=60.0, silence_is_right=False):
        """Sends one request; `accept(status, body)` says whether the answer is right; a 2xx
        where it is not is a security finding, 5xx or nothing an error (unless silence is the
        right answer: a request that never ends is closed after 30 s)."""
        if process.poll() is not None:
            return  # dead already: counted once
        tally.attempts += 1
        status, body = exchange(port, data, timeout)
        if not alive(tally, what):
            return
        if status == 0 and silence_is_right:
            return
        if status == 0 or status >= 500:
            tally.note("errors", f"{what}: {status} {body[:120]}")
        elif not accept(status, body):
            tally.note("security" if 200 <= status < 300 or status == 101 else "errors", f"{what}: {status} {body[:160]}")

    def run_class(name, body):
        tally = Tally(name)
        peak[0] = memory_kb(process.pid, "VmRSS") if process.poll() is None else 0
        start_time = time.monotonic()
        body(tally)
        end_time = time.monotonic()
        if alive(tally, "after the class"):
            status, _ = exchange(port, request("GET", "/api/info"))
            if status != 200:
                tally.note("crashes", f"GET /api/info after the class: {status}")
            status, active = exchange(port, request("GET", "/api/runs/active"))
            if status != 200 or json.loads(active).get("id") != moving_run or not json.loads(active).get("active"):
                tally.note("errors", f"the arm's run is no longer active: {active[:200]}")
        tally.gap = watcher.max_gap(start_time, end_time)
        tally.peak_mb = peak[0] / 1024
        tallies.append(tally)

    refused = lambda status, body: 400 <= status < 500  # noqa: E731

    def plans(tally):
        for what, plan in hostile_plans():
            body = json.dumps({"plan": plan} if isinstance(plan, dict) else {"xml": plan})
            invalid = lambda s, b: refused(s, b) or (s == 200 and '"valid":false' in b)  # noqa: E731
            check(tally, f"validate {what}", request("POST", "/api/validate", body, token), invalid)
            check(tally, f"save {what}", request("PUT", "/api/plans/hostile", body, token), refused)
            check(tally, f"save as subtree {what}", request("PUT", "/api/subtrees/T0", body, token), refused)
            check(tally, f"run {what}", request("POST", "/api/runs", body, token), refused)
            check(tally, f"validate {what} without the token", request("POST", "/api/validate", body), refused)
        status, _ = exchange(port, request("GET", "/api/plans/hostile"))
        if status == 200:
            tally.note("security", "a hostile plan was saved")

    def texts(tally):
        for what, body in text_attacks():
            for method, target in (("POST", "/api/validate"), ("PUT", "/api/plans/text"), ("POST", "/api/runs"),
                                   ("POST", "/api/operations")):
                check(tally, f"{method} {target} {what}", request(method, target, body, token), refused)
        for target in (b"/api/plans/\xff\xfe", b"/api/runs/\xc3", b"/api/%ff%fe", b"/api/plans/a%00b"):
            check(tally, f"GET {target!r}", b"GET " + target + b" HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n",
                  refused)
        check(tally, "header value FF", request("GET", "/api/info", headers=b"X-A: \xff\xfe\r\n"),
              lambda s, b: s in (200, 400))
        status, _ = exchange(port, request("GET", "/api/plans/text"))
        if status == 200:
            tally.note("security", "a plan with text that is not UTF-8 was saved")

    def huge(tally):
        announced = (f"PUT /api/plans/big HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {token}\r\n"
                     "Content-Length: 2097152\r\n\r\n").encode() + b'{"xml": "'
        check(tally, "2 MiB announced", announced, lambda s, b: s == 413)
        check(tally, "1 MiB + 1 sent", request("PUT", "/api/plans/big", b"x" * ((1 << 20) + 1), token),
              lambda s, b: s == 413)
        chunked = (f"PUT /api/plans/big HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer {token}\r\n"
                   "Transfer-Encoding: chunked\r\n\r\n").encode() + b"".join(
                       b"10000\r\n" + b"a" * 0x10000 + b"\r\n" for _ in range(48))
        check(tally, "3 MiB chunked", chunked, lambda s, b: s == 413)
        check(tally, "1 MiB of [", request("POST", "/api/validate", b"[" * 1000000, token), refused)
        check(tally, "1 MiB of {\"a\":", request("POST", "/api/validate", b'{"a":' * 200000, token), refused)
        check(tally, "1 MiB string", request("POST", "/api/validate", b'{"xml": "' + b"a" * 1000000 + b'"}', token),
              refused)
        check(tally, "headers over 8 KiB", request("GET", "/api/info", headers=b"X-Long: " + b"a" * 20000 + b"\r\n"),
              refused)
        check(tally, "10,000 headers", request("GET", "/api/info", headers=b"X-A: b\r\n" * 10000), refused)
        check(tally, "Content-Length lies", b"POST /api/validate HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " +
              token.encode() + b"\r\nContent-Length: 100\r\nConnection: close\r\n\r\n{}", lambda s, b: s == 400,
              timeout=35, silence_is_right=True)

    def paths(tally):
        for target in ["//api//info", "/api/../api/info", "/api/plans/%2e%2e", "/api/runs/99999999999999999999",
                       "/api/runs/-1", "/api/runs/0x10", "/api/runs/1/transitions?from=-1",
                       "/api/runs/1/transitions?from=99999999999999999999", "/api/runs/1?limit=0",
                       "/api/runs/1?limit=100000", "/api/runs/1/transitions?from=1&limit=abc",
                       "/api/runs/1/transitions/x", "/api/runs/active/transitions", "/api/plans/a?version=0",
                       "/api/pointcloud?max=-1", "/api/runs?limit=1e9", "/api?", "/" + "/" * 6000,
                       "/api/plans/" + "a" * 5000, "/../../etc/passwd", "/index.html%00.js", "/assets/../../x"]:
            check(tally, f"GET {target[:60]}", request("GET", target), lambda s, b: s < 500)
        for method in ["BREW", "get", "OPTIONS", "TRACE", "CONNECT", "PATCH", "PROPFIND", "DELETE"]:
            check(tally, f"{method} /api/runs", request(method, "/api/runs", b"", token), refused)
        check(tally, "absolute form", request("GET", "http://127.0.0.1/api/info"), refused)
        check(tally, "HTTP/0.9", b"GET /api/info\r\n\r\n", lambda s, b: True)

    def hosts(tally):
        good = ["127.0.0.1", f"127.0.0.1:{port}", "localhost", f"localhost:{port}", "[::1]", f"[::1]:{port}",
                "127.3.4.5"]
        bad = ["127.attacker.example", "127.0.0.1.nip.io", "127.0.0.1evil", "[::1].evil.com", "evil.example",
               "localhost.evil.example", "127.0.0.1:80@evil.example", "127.1", "0x7f.0.0.1", "2130706433",
               "[::ffff:127.0.0.1]", "", "127.0.0.1:", "127.0.0.1:99999", "LOCALHOST.", "127.0.0.1 evil"]
        for host in good:
            check(tally, f"Host {host}", request("GET", "/api/info", host=host), lambda s, b: s == 200)
        for host in bad:
            check(tally, f"Host {host!r}", request("GET", "/api/info", host=host), lambda s, b: s in (400, 421))
            check(tally, f"Host {host!r}, change with the token",
                  request("POST", "/api/control", b'{"action":"pause"}', token, host=host), lambda s, b: s in (400, 421))
        here = f"127.0.0.1:{port}"
        origins_good = [(None, here), (f"http://127.0.0.1:{port}", here), (f"http://localhost:{port}", f"localhost:{port}")]
        origins_bad = [(f"http://127.evil.example:{port}", here), (f"http://127.0.0.1.nip.io:{port}", here),
                       (f"http://localhost:{port + 1}", here), ("http://127.0.0.1:5173", here),
                       (f"http://[::1].evil.com:{port}", here), ("null", here), (f"file://127.0.0.1:{port}", here),
                       (f"http://127.0.0.1:{port}.evil.example", here), (f"http://evil.example", here),
                       (f"http://127.0.0.1:{port}", "127.attacker.example")]
        for origin, host in origins_good:
            check(tally, f"Origin {origin} Host {host}", upgrade(host, origin), lambda s, b: s == 101)
        for origin, host in origins_bad:
            check(tally, f"Origin {origin} Host {host}", upgrade(host, origin), lambda s, b: s in (403, 421))

    def no_token(tally):
        changes = [("POST", "/api/runs", json.dumps({"xml": KEEP_PLAN})), ("POST", "/api/control", '{"action":"stop"}'),
                   ("POST", "/api/operations", '{"node":"Home"}'), ("PUT", "/api/plans/keep", json.dumps({"xml": KEEP_PLAN})),
                   ("DELETE", "/api/plans/keep", ""), ("PUT", "/api/subtrees/s", json.dumps({"xml": KEEP_PLAN})),
                   ("POST", "/api/validate", json.dumps({"xml": KEEP_PLAN})), ("GET", "/api/test/ground_truth", "")]
        for bad in [None, "wrong", token + "x", token[1:], "\xc3", token.upper()]:
            for method, target, body in changes:
                check(tally, f"{method} {target} token {bad!r}", request(method, target, body, bad),
                      lambda s, b: s in (401, 404))

    def logs(tally):
        results = [None] * 12

        def reader(i):
            try:
                results[i] = read_whole_log(port, 1)
            except OSError as error:
                results[i] = (0, str(error))

        readers = [threading.Thread(target=reader, args=(i,)) for i in range(12)]
        for thread in readers:
            thread.start()
        for thread in readers:
            thread.join()
        for count, size in results:
            tally.attempts += 1
            if count != args.transitions:
                tally.note("errors", f"a full read got {count} transitions ({size})")
        alive(tally, "12 concurrent reads of the long log")

    def stream_frames(tally):
        """Malformed frames and messages on the live stream; commands on it without the token."""
        def stream(data, wait=1.0):
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
                    sock.sendall(upgrade(f"127.0.0.1:{port}", None))
                    answer = b""
                    while b"\r\n\r\n" not in answer:
                        chunk = sock.recv(4096)
                        if not chunk:
                            return False, answer
                        answer += chunk
                    try:
                        sock.sendall(data)
                    except OSError:
                        pass  # closed on a protocol error before all was read
                    # The stream goes on (a snapshot 20 times a second): read what comes for
                    # `wait` seconds, or until the server closes it.
                    deadline = time.monotonic() + wait
                    received = answer
                    try:
                        while time.monotonic() < deadline:
                            sock.settimeout(max(0.01, deadline - time.monotonic()))
                            chunk = sock.recv(65536)
                            if not chunk:
                                break
                            received += chunk
                    except OSError:
                        pass
                    return True, received
            except OSError as error:
                return False, str(error).encode()

        for what, data in frame_attacks():
            tally.attempts += 1
            opened, _ = stream(data)
            if not alive(tally, what):
                return
            if not opened:
                tally.note("errors", f"{what}: the stream did not open")
            status, _ = exchange(port, request("GET", "/api/info"), timeout=10)
            if status != 200:
                tally.note("errors", f"{what}: GET /api/info then answered {status}")
        # Commands without the token (loopback: the stream opens without it): refused, the run
        # goes on unpaused.
        for bad in [None, "wrong", token + "x", token[:-1]]:
            for action in ["pause", "stop", "step"]:
                tally.attempts += 1
                auth = b"" if bad is None else frame(0x1, json.dumps({"type": "auth", "token": bad}).encode())
                stream(auth + frame(0x1, json.dumps({"type": "control", "action": action}).encode()))
                if not alive(tally, f"control {action} with token {bad!r}"):
                    return
                status, active = exchange(port, request("GET", "/api/runs/active"))
                if status != 200 or not json.loads(active).get("active") or json.loads(active).get("paused"):
                    tally.note("security", f"control {action} with token {bad!r} took effect: {active[:160]}")
                    exchange(port, request("POST", "/api/control", b'{"action":"resume"}', token))

    def saves(tally):
        """20 saves of one plan and 20 of plans of their own at once: each acknowledged save is
        kept, as the version it was acknowledged as."""
        results = {}

        def save(key, name, marker):
            plan = KEEP_PLAN.replace('name="kept"', f'name="{marker}"')
            results[key] = exchange(port, request("PUT", f"/api/plans/{name}", json.dumps({"xml": plan}), token))

        threads = [threading.Thread(target=save, args=(("same", i), "shared", f"s{i}")) for i in range(20)] + \
                  [threading.Thread(target=save, args=(("own", i), f"own{i}", f"o{i}")) for i in range(20)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        versions = {}
        for (kind, i), (status, body) in sorted(results.items()):
            tally.attempts += 1
            if status != 201:
                tally.note("errors", f"save {kind} {i}: {status} {body[:120]}")
                continue
            version = json.loads(body)["version"]
            name = "shared" if kind == "same" else f"own{i}"
            marker = f"s{i}" if kind == "same" else f"o{i}"
            if kind == "same":
                if version in versions:
                    tally.note("loss", f"saves {versions[version]} and {i} were both acknowledged as version {version}")
                versions[version] = i
            got, saved = exchange(port, request("GET", f"/api/plans/{name}?version={version}"))
            if got != 200 or f'name="{marker}"' not in json.loads(saved)["xml"]:
                tally.note("loss", f"{name} version {version} does not hold save {marker}: {got} {saved[:120]}")
        alive(tally, "40 concurrent saves")

    def connections(tally):
        idle = []
        for _ in range(200):
            try:
                idle.append(socket.create_connection(("127.0.0.1", port)))
                idle[-1].sendall(b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never finished
            except OSError as error:
                tally.note("errors", f"connection refused: {error}")
        silent = []
        for _ in range(50):
            sock = socket.create_connection(("127.0.0.1", port))
            sock.sendall(upgrade("127.0.0.1", None))
            silent.append(sock)  # never reads the stream
        time.sleep(3.0)
        start_time = time.monotonic()
        check(tally, "GET /api/info beside 200 idle and 50 silent stream clients", request("GET", "/api/info"),
              lambda s, b: s == 200)
        if time.monotonic() - start_time > 1.0:
            tally.note("errors", "GET /api/info took over 1 s")
        tally.attempts += 250
        for sock in idle + silent:
            sock.close()

    for name, body in [("deep, wide and huge plans", plans), ("text that is not UTF-8", texts),
                       ("huge bodies", huge), ("odd paths and methods", paths), ("Host and Origin", hosts),
                       ("no or wrong token", no_token), (f"12 concurrent reads of a {args.transitions:,}-transition log", logs),
                       ("malformed WebSocket frames, commands without the token", stream_frames),
                       ("40 concurrent saves", saves), ("idle connections", connections)]:
        if process.poll() is None:
            run_class(name, body)
    sampling[0] = False
    watcher.stop = True

    # Data: the saved plan and the long log are intact, through a restart.
    tally = Tally("data after a restart")
    if process.poll() is None:
        stop_server(process)
        tally.attempts += 1
        if process.returncode != 0:
            tally.note("crashes", f"SIGTERM: exit {process.returncode}")
    process, port, token = start(args.costar, args.workcell, folder)
    status, body = exchange(port, request("GET", "/api/plans/keep"))
    tally.attempts += 1
    if status != 200 or json.loads(body)["version"] != 1 or 'name="kept"' not in json.loads(body)["xml"]:
        tally.note("loss", f"the saved plan: {status} {body[:200]}")
    count, _ = read_whole_log(port, 1)
    tally.attempts += 1
    if count != args.transitions:
        tally.note("loss", f"the long log has {count} transitions")
    status, body = exchange(port, request("GET", f"/api/runs/{moving_run}"))
    tally.attempts += 1
    if status != 200 or json.loads(body)["result"] not in ("STOPPED",):
        tally.note("loss", f"the moving run's log after SIGTERM: {status} {body[:200]}")
    tally.gap, tally.peak_mb = float("nan"), memory_kb(process.pid, "VmRSS") / 1024
    tallies.append(tally)

    # kill -9 while the arm moves and plans are being saved: every acknowledged save survives,
    # the store opens again, the interrupted run's log reads.
    killed = Tally(f"kill -9 during a motion and saves ({args.kills} kills)")
    peak_mb = 0.0
    for round_ in range(args.kills):
        status, body = exchange(port, request("POST", "/api/runs", json.dumps({"xml": MOVING_PLAN}), token))
        if status != 202:
            killed.note("errors", f"round {round_}: the moving plan did not start: {status} {body[:120]}")
            break
        interrupted = json.loads(body)["run"]
        acknowledged = []
        saving = [True]

        def saver(round_=round_, port=port, token=token):
            n = 0
            while saving[0]:
                name = f"k{round_}_{n}"
                plan = KEEP_PLAN.replace('name="kept"', f'name="{name}"')
                status, _ = exchange(port, request("PUT", f"/api/plans/{name}", json.dumps({"xml": plan}), token), 5)
                if status == 201:
                    acknowledged.append(name)
                n += 1

        thread = threading.Thread(target=saver)
        thread.start()
        time.sleep(1.0 + 0.37 * round_)
        process.send_signal(signal.SIGKILL)
        process.wait()
        saving[0] = False
        thread.join()
        killed.attempts += 1 + len(acknowledged)  # the kill, and each acknowledged save looked for
        process, port, token = start(args.costar, args.workcell, folder)
        peak_mb = max(peak_mb, memory_kb(process.pid, "VmRSS") / 1024)
        for name in acknowledged:
            got, saved = exchange(port, request("GET", f"/api/plans/{name}"))
            if got != 200 or f'name="{name}"' not in json.loads(saved)["xml"]:
                killed.note("loss", f"acknowledged save {name} lost: {got} {saved[:120]}")
        got, body = exchange(port, request("GET", f"/api/runs/{interrupted}"))
        if got not in (200, 404):  # 404: killed before the writer's first batch
            killed.note("errors", f"the interrupted run's log: {got} {body[:160]}")
        if not acknowledged:
            killed.note("errors", f"round {round_}: no save was acknowledged before the kill")
    killed.gap, killed.peak_mb = float("nan"), peak_mb
    tallies.append(killed)
    stop_server(process)

    print(f"costar serve -w {args.workcell} ({args.costar}); the arm moving under run {moving_run} throughout")
    print("| class | attempts | crashes | 5xx or no answer | security findings | data loss | largest stream gap | peak RSS |")
    print("|---|---|---|---|---|---|---|---|")
    for t in tallies:
        gap = "—" if t.gap != t.gap else f"{t.gap * 1000:.0f} ms"  # NaN: under 2 snapshots in the class
        print(f"| {t.name} | {t.attempts} | {t.crashes} | {t.errors} | {t.security} | {t.loss} | {gap} | "
              f"{t.peak_mb:.0f} MB |")
    for t in tallies:
        for note in t.notes:
            print(f"  {t.name}: {note}")
    fatal = open(os.path.join(folder, "stderr.txt")).read()
    if "fatal" in fatal:
        print("stderr:", fatal[-2000:])
    bad = sum(t.crashes + t.errors + t.security + t.loss for t in tallies)
    print(f"total: {sum(t.attempts for t in tallies)} attempts, {bad} findings; files in {folder}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
