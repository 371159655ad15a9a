#!/usr/bin/env python3
"""Soak test of `remora serve` (make soak; docs/server.md, "The soak test").

One server on loopback, several clients for a set time (default 10 minutes) sending random valid
and invalid requests: regions, transforms, commits, undo/redo, bakes, uploads of good and broken
files, picks, views, exports, wrong methods and paths, malformed JSON, and connections that hang
up in the middle of a request or of an answer. Checked:

- every answer is a well-formed 2xx or documented 4xx (JSON errors with a message, 405 with
  Allow), never a 5xx, a dropped connection or a malformed reply;
- the server's resident memory, sampled every second, stays under the bound computed at the start
  (printed with its terms; the report gives its peak per 30 seconds);
- the final state (positions, faces, region, transforms, history flags, counters) equals that of a
  second server given only the accepted state-changing requests, one at a time, in the order the
  server accepted them (clients take a lock around state-changing requests so that order is
  known; reads, picks, probes that can change nothing and hang-ups run concurrently with them).

Python 3's standard library only (http.client, a second HTTP implementation next to the server's
cpp-httplib). Exit code 0 when every check passed; a JSON report with --report.
"""

import argparse
import http.client
import json
import math
import os
import random
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

DOCUMENTED = {200, 202, 400, 404, 405, 409, 413, 422}
MAX_EDITORS = 3  # SessionOptions::max_editors, the editors the history keeps alive
REGIONS_KEPT = 2  # the regions an editor keeps for an undo (multires/editor.h)


class Violation(Exception):
    pass


class Server:
    """`remora serve` on a free loopback port, with its resident memory."""

    def __init__(self, cli, mesh, upload_mb, web_root):
        args = [cli, "serve", "--port", "0", "--threads", "1", "--web-root", web_root,
                "--max-upload-mb", str(upload_mb)]
        if mesh:
            args.insert(2, mesh)
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True)
        line = self.proc.stdout.readline()
        match = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        if not match:
            raise RuntimeError(f"remora serve did not start: {line}{self.proc.stderr.read()}")
        self.port = int(match.group(1))

    def rss_bytes(self):
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
        return 0

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        try:
            return self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return -9


class Client:
    """One kept-alive connection; every answer checked against the API's promises."""

    def __init__(self, port, tally):
        self.port = port
        self.tally = tally
        self.conn = None

    def request(self, method, path, body=None, content_type="application/octet-stream"):
        for attempt in range(2):
            if self.conn is None:
                self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
            headers = {"Content-Type": content_type} if body is not None else {}
            try:
                self.conn.request(method, path, body=body, headers=headers)
                r = self.conn.getresponse()
                data = r.read()
            except (ConnectionError, http.client.RemoteDisconnected, BrokenPipeError):
                # A kept-alive connection the server closed between requests: once more on a new
                # one; twice is a failure.
                self.conn.close()
                self.conn = None
                if attempt == 1:
                    raise Violation(f"{method} {path}: the connection dropped")
                continue
            self.check(method, path, r, data)
            return r.status, dict(r.getheaders()), data

    def check(self, method, path, r, data):
        self.tally.count(f"{r.status}")
        if r.status not in DOCUMENTED:
            raise Violation(f"{method} {path}: undocumented status {r.status}: {data[:300]!r}")
        ctype = r.getheader("Content-Type", "")
        if r.status >= 400:
            try:
                err = json.loads(data)["error"]
            except (ValueError, KeyError, TypeError):
                raise Violation(f"{method} {path}: {r.status} without a JSON error: {data[:300]!r}")
            if not isinstance(err, str) or not err:
                raise Violation(f"{method} {path}: {r.status} with an empty error")
            if r.status == 405 and not r.getheader("Allow"):
                raise Violation(f"{method} {path}: 405 without Allow")
        elif ctype.startswith("application/json"):
            try:
                json.loads(data)
            except ValueError:
                raise Violation(f"{method} {path}: {r.status} JSON that does not parse")

    def json(self, method, path, body=None):
        status, _, data = self.request(method, path, body, "application/json")
        return status, json.loads(data)


class Tally:
    def __init__(self):
        self.lock = threading.Lock()
        self.counts = {}

    def count(self, key, n=1):
        with self.lock:
            self.counts[key] = self.counts.get(key, 0) + n


def floats(data):
    return struct.unpack(f"<{len(data) // 4}f", data)


def wait_idle(client, limit=600):
    deadline = time.time() + limit
    while time.time() < deadline:
        _, st = client.json("GET", "/api/status?wait=2000")
        if st["state"] != "busy":
            return st
    raise Violation("a job did not end")


# Meshes to upload: a torus of quads split into triangles (valid) and broken files.
def torus_off(around=48, tube=24):
    lines = [f"OFF\n{around * tube} {2 * around * tube} 0"]
    for i in range(around):
        for j in range(tube):
            u, v = 2 * math.pi * i / around, 2 * math.pi * j / tube
            r = 1 + 0.3 * math.cos(v)
            lines.append(f"{r * math.cos(u):.9g} {r * math.sin(u):.9g} {0.3 * math.sin(v):.9g}")
    for i in range(around):
        for j in range(tube):
            a, b = i * tube + j, ((i + 1) % around) * tube + j
            c, d = ((i + 1) % around) * tube + (j + 1) % tube, i * tube + (j + 1) % tube
            lines += [f"3 {a} {b} {c}", f"3 {a} {c} {d}"]
    return ("\n".join(lines) + "\n").encode()


def broken_uploads(mesh_bytes):
    return [
        ("cut.ply", mesh_bytes[: len(mesh_bytes) // 2]),
        ("nan.off", b"OFF\n3 1 0\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n"),
        ("range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"),
        ("garbage.stl", bytes(random.Random(7).getrandbits(8) for _ in range(999))),
        ("lying.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      b"property float z\nelement face 5\nproperty list uchar int vertex_indices\n"
                      b"end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
        ("empty.off", b""),
        ("flat.off", b"OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n"),
    ]


class Soak:
    def __init__(self, args, port, mesh_bytes, positions):
        self.args = args
        self.port = port
        self.tally = Tally()
        self.mutation_lock = threading.Lock()
        self.accepted = []  # (method, path, body) of accepted state-changing requests, in order
        self.violations = []
        self.deadline = time.time() + args.seconds
        self.uploads = [("soak" + os.path.splitext(args.mesh)[1], mesh_bytes),
                        ("torus.off", torus_off())]
        self.broken = broken_uploads(mesh_bytes)
        self.positions = positions  # the current mesh's rest positions, for regions

    # State-changing requests, under the lock: the server's order of acceptance is the log's.
    def mutate(self, c, rng):
        with self.mutation_lock:
            kind = rng.choices(["region", "transform", "commit", "undo", "redo", "load", "broken"],
                               [20, 40, 10, 8, 6, 2, 4])[0]
            if kind == "region":
                # A region sent while a region job runs stops that job, which may or may not have
                # installed its region by then; the replay could not tell, so regions wait for the
                # previous region's job here (the stop is tested in test_server_editing.cpp).
                if self.accepted and self.accepted[-1][1] == "/api/region":
                    wait_idle(c)
                method, path, body = "POST", "/api/region", self.region_body(rng)
            elif kind == "transform":
                method, path, body = "POST", "/api/transform", self.transform_body(rng)
            elif kind in ("commit", "undo", "redo"):
                method, path, body = "POST", "/api/" + kind, None
            else:
                name, data = rng.choice(self.uploads if kind == "load" else self.broken)
                method, path, body = "POST", f"/api/load?name={name}", data
            status, _, _ = c.request(method, path, body,
                                     "application/json" if kind in ("region", "transform")
                                     else "application/octet-stream")
            self.tally.count("mutation " + kind)
            if status < 300:
                self.accepted.append((method, path, body))
                self.tally.count("accepted " + kind)
                if kind == "load":
                    # The next regions pick vertices of the new mesh: wait for it, read it.
                    st = wait_idle(c)
                    if st["state"] == "ready" and "error" not in st:
                        _, _, data = c.request("GET", "/api/mesh/positions")
                        self.positions = floats(data)

    def region_body(self, rng):
        p = self.positions
        n = len(p) // 3
        lo = [min(p[k::3]) for k in range(3)]
        hi = [max(p[k::3]) for k in range(3)]
        diag = math.dist(lo, hi)
        center = rng.randrange(n)
        cx = p[3 * center: 3 * center + 3]
        r = diag * rng.uniform(0.05, 0.3)
        d2 = [sum((p[3 * v + k] - cx[k]) ** 2 for k in range(3)) for v in range(n)]
        support = [v for v in range(n) if d2[v] <= r * r]
        handles = [[v for v in support if d2[v] <= (r / 4) ** 2]]
        if rng.random() < 0.2 and len(support) > 10:
            # A second handle at the support's far end, disjoint from the first.
            far = max(support, key=lambda v: d2[v])
            fx = p[3 * far: 3 * far + 3]
            second = [v for v in support if v not in set(handles[0]) and
                      sum((p[3 * v + k] - fx[k]) ** 2 for k in range(3)) <= (r / 5) ** 2]
            if second:
                handles.append(second)
        return json.dumps({"support": support, "handles": handles, "k": rng.choice([1, 2, 3])})

    def transform_body(self, rng):
        angle = math.radians(rng.uniform(-30, 30))
        axis = [rng.gauss(0, 1) for _ in range(3)]
        norm = math.sqrt(sum(a * a for a in axis)) or 1.0
        x, y, z = (a / norm for a in axis)
        c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
        rot = [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
               [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
               [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]
        scale = rng.uniform(0.8, 1.25)
        p = self.positions
        diag = math.dist([min(p[k::3]) for k in range(3)], [max(p[k::3]) for k in range(3)])
        matrix = []
        for i in range(3):
            matrix += [scale * v for v in rot[i]] + [rng.uniform(-0.05, 0.05) * diag]
        return json.dumps({"handle": rng.choice([0, 0, 0, 1]), "matrix": matrix})

    # Requests that read, or that cannot change anything whatever the state: no lock.
    def read(self, c, rng):
        kind = rng.choice(["status", "poll", "positions", "indices", "movable", "region", "base",
                           "export", "pick"])
        self.tally.count("read " + kind)
        if kind == "status":
            c.request("GET", "/api/status")
        elif kind == "poll":
            c.request("GET", f"/api/status?wait={rng.randrange(0, 300)}")
        elif kind in ("positions", "indices"):
            c.request("GET", f"/api/mesh/{kind}")
        elif kind in ("movable", "region"):
            c.request("GET", f"/api/{kind}")
        elif kind == "base":
            c.request("GET", "/api/base/" + rng.choice(["positions", "indices", "areas"]))
        elif kind == "export":
            c.request("GET", "/api/export?format=" + rng.choice(["ply", "obj", "stl"]))
        else:
            d = [rng.gauss(0, 1) for _ in range(3)]
            body = {"origin": [-5 * v for v in d], "direction": d,
                    "radius": rng.choice([0, 0.005, 0.02, 0.1]),
                    "brush": rng.choice(["geodesic", "sphere"])}
            c.request("POST", "/api/pick", json.dumps(body), "application/json")

    PROBES = [
        ("POST", "/api/region", '{"support": [1, 2', 400),
        ("POST", "/api/region", '{"support": [0], "handles": [[0]], "k": 7}', None),
        ("POST", "/api/region", '{"support": [0], "handles": [[0]], "colour": 1}', None),
        ("POST", "/api/transform", '{"handle": 99, "matrix": [1,0,0,0,0,1,0,0,0,0,1,0]}', None),
        ("POST", "/api/transform", '{"handle": 0, "matrix": [1,0,0]}', None),
        ("POST", "/api/transform", '{"handle": 0, "matrix": [-1,0,0,0,0,1,0,0,0,0,1,0]}', None),
        ("POST", "/api/transform", '{"handle": 0, "matrix": [1e400,0,0,0,0,1,0,0,0,0,1,0]}', 400),
        ("POST", "/api/pick", '{"origin": [0,0,"x"], "direction": [0,0,1]}', 400),
        ("POST", "/api/load?name=mesh.doc", "x", 400),
        ("POST", "/api/load", "OFF\n", 400),
        ("GET", "/api/status?wait=soon", None, 400),
        ("GET", "/api/export?format=doc", None, None),
        ("GET", "/api/nowhere", None, 404),
        ("DELETE", "/api/status", None, 405),
        ("PUT", "/api/region", "{}", 405),
        ("GET", "/api/transform", None, 405),
    ]

    def probe(self, c, rng):
        method, path, body, expected = rng.choice(self.PROBES)
        status, _, data = c.request(method, path, body, "application/json")
        self.tally.count("probe")
        if status < 300 or (expected is not None and status != expected):
            raise Violation(f"probe {method} {path} {body!r}: {status} {data[:200]!r}")

    def oversize(self, c):
        self.tally.count("probe oversize")
        body = b"x" * (self.args.upload_mb * 1024 * 1024 + 1)
        for ctype in ("application/octet-stream", None):
            conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
            headers = {"Content-Type": ctype} if ctype else {}
            try:
                conn.request("POST", "/api/load?name=big.ply", body=body, headers=headers)
                r = conn.getresponse()
                data = r.read()
            except (ConnectionError, BrokenPipeError):
                continue  # the server may close before reading all of a refused body
            finally:
                conn.close()
            c.check("POST", "/api/load (oversize)", r, data)
            if r.status != 413:
                raise Violation(f"an oversize upload got {r.status}")

    def hang_up(self, rng):
        self.tally.count("hang-up")
        kind = rng.randrange(3)
        s = socket.create_connection(("127.0.0.1", self.port), timeout=30)
        try:
            if kind == 0:
                s.sendall(b"GET /api/mesh/positions HTTP/1.1\r\nHost: x\r\n\r\n")
                s.recv(rng.randrange(1, 64))
                if rng.random() < 0.5:
                    s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            elif kind == 1:
                s.sendall(b"POST /api/reg")
            else:
                s.sendall(b"POST /api/load?name=a.off HTTP/1.1\r\nHost: x\r\nContent-Length: "
                          b"100000\r\nContent-Type: application/octet-stream\r\n\r\nOFF\n")
        finally:
            s.close()

    def client(self, index):
        rng = random.Random(self.args.seed * 1000 + index)
        c = Client(self.port, self.tally)
        try:
            while time.time() < self.deadline:
                roll = rng.random()
                if roll < 0.35:
                    self.mutate(c, rng)
                elif roll < 0.75:
                    self.read(c, rng)
                elif roll < 0.93:
                    self.probe(c, rng)
                elif roll < 0.995:
                    self.hang_up(rng)
                else:
                    self.oversize(c)
        except Exception as e:  # a violation or an unexpected failure ends this client
            self.violations.append(f"client {index}: {type(e).__name__}: {e}")


def final_state(c):
    st = wait_idle(c)
    for key in ("base", "frame_ms"):
        st.pop(key, None)
    if "region" in st:
        st["region"].pop("set_region_ms", None)
    _, _, positions = c.request("GET", "/api/mesh/positions")
    _, _, indices = c.request("GET", "/api/mesh/indices")
    _, region = c.json("GET", "/api/region") if st["state"] == "ready" else (0, None)
    return {"status": st, "positions": positions, "indices": indices, "region": region}


def replay(args, accepted, web_root):
    """A second server given only the accepted state-changing requests, one at a time."""
    server = Server(args.cli, args.mesh, args.upload_mb, web_root)
    try:
        c = Client(server.port, Tally())
        wait_idle(c)
        for method, path, body in accepted:
            ctype = "application/octet-stream" if "load" in path else "application/json"
            status, _, data = c.request(method, path, body, ctype)
            if status >= 300:
                raise Violation(f"replay: {method} {path} was refused: {status} {data[:200]!r}")
            if path.startswith("/api/load") or path == "/api/region":
                wait_idle(c)
        return final_state(c)
    finally:
        server.stop()


def sample_memory(server, samples, stop):
    t0 = time.time()
    while not stop.is_set():
        try:
            samples.append((time.time() - t0, server.rss_bytes()))
        except OSError:
            return
        stop.wait(1.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", required=True, help="the remora binary")
    ap.add_argument("--mesh", required=True, help="the mesh the server starts with")
    ap.add_argument("--seconds", type=float, default=600)
    ap.add_argument("--clients", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--upload-mb", type=int, default=16)
    ap.add_argument("--report", help="write the report as JSON here")
    args = ap.parse_args()
    with open(args.mesh, "rb") as f:
        mesh_bytes = f.read()
    web_root = tempfile.mkdtemp(prefix="remora-soak-web-")
    with open(os.path.join(web_root, "index.html"), "w") as f:
        f.write("<html></html>\n")

    # The memory bound's terms: an idle server, what a load of the mesh adds to it, and the
    # largest region (all of the mesh, k = 3, two handles).
    server = Server(args.cli, None, args.upload_mb, web_root)
    idle_rss = server.rss_bytes()
    c = Client(server.port, Tally())
    c.request("POST", "/api/load?name=soak" + os.path.splitext(args.mesh)[1], mesh_bytes)
    wait_idle(c)
    load_rss = server.rss_bytes() - idle_rss
    _, _, data = c.request("GET", "/api/mesh/positions")
    n = len(data) // 12
    everything = json.dumps({"support": list(range(n)), "handles": [[0], [n - 1]], "k": 3})
    c.request("POST", "/api/region", everything, "application/json")
    if "error" in wait_idle(c):
        raise RuntimeError("the calibration region failed")
    region_rss = server.rss_bytes() - idle_rss - load_rss
    server.stop()
    upload = args.upload_mb * 1024 * 1024
    # The history keeps MAX_EDITORS editors alive and a bake builds one more; an editor holds its
    # region, the REGIONS_KEPT it keeps for an undo and, during a region job, the one being
    # prepared. Each client can have one upload in flight, held by httplib, the request and the
    # session (3 copies).
    editor_rss = load_rss + (REGIONS_KEPT + 2) * region_rss
    bound = idle_rss + (MAX_EDITORS + 1) * editor_rss + args.clients * 3 * upload

    server = Server(args.cli, args.mesh, args.upload_mb, web_root)
    samples, stop = [], threading.Event()
    sampler = threading.Thread(target=sample_memory, args=(server, samples, stop))
    sampler.start()
    c = Client(server.port, Tally())
    wait_idle(c)
    _, _, data = c.request("GET", "/api/mesh/positions")
    soak = Soak(args, server.port, mesh_bytes, floats(data))
    started = time.time()
    threads = [threading.Thread(target=soak.client, args=(i,)) for i in range(args.clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    duration = time.time() - started
    try:
        end = final_state(c)
    except Exception as e:
        soak.violations.append(f"final state: {e}")
        end = None
    stop.set()
    sampler.join()
    exit_code = server.stop()
    if exit_code != 0:
        soak.violations.append(f"remora serve exited with {exit_code} on SIGTERM")

    rss = [r for _, r in samples]
    peak = max(rss) if rss else 0
    cut = 2 * len(rss) // 3
    early, late = (max(rss[:cut]) if cut else 0), (max(rss[cut:]) if rss[cut:] else 0)
    if peak > bound:
        soak.violations.append(f"resident memory {peak / 2**20:.0f} MiB over the bound "
                               f"{bound / 2**20:.0f} MiB")
    # `remora serve` keeps the memory it frees for reuse, so its resident memory is the heap's
    # high-water mark: it rises in steps as new combinations of editors, jobs and uploads meet,
    # and the bound, not its shape, is the criterion. The growth is reported.
    same = None
    if end is not None:
        again = replay(args, soak.accepted, web_root)
        same = again == end
        if not same:
            diff = [k for k in end if end[k] != again[k]]
            soak.violations.append(f"the replay of {len(soak.accepted)} accepted requests ends "
                                   f"elsewhere: {diff}; {end['status']} vs {again['status']}")
    report = {
        "seconds": round(duration, 1),
        "clients": args.clients,
        "requests": soak.tally.counts,
        "accepted_state_changes": len(soak.accepted),
        "memory_mib": {"idle": round(idle_rss / 2**20, 1), "one_load": round(load_rss / 2**20, 1),
                       "largest_region": round(region_rss / 2**20, 1),
                       "one_editor_at_most": round(editor_rss / 2**20, 1),
                       "bound": round(bound / 2**20, 1), "peak": round(peak / 2**20, 1),
                       "first_two_thirds_peak": round(early / 2**20, 1),
                       "last_third_peak": round(late / 2**20, 1),
                       "final": round(rss[-1] / 2**20, 1) if rss else 0,
                       "samples": len(rss),
                       "peak_per_30_s": [round(max(rss[i:i + 30]) / 2**20) for i in
                                         range(0, len(rss), 30)]},
        "replay_equal": same,
        "violations": soak.violations,
    }
    text = json.dumps(report, indent=2)
    print(text)
    if args.report:
        with open(args.report, "w") as f:
            f.write(text + "\n")
    return 0 if not soak.violations else 1


if __name__ == "__main__":
    sys.exit(main())
