"""Fuzz the studio's HTTP API for a while: random JSON bodies, paths, methods and headers against a real
``mocycle studio`` (uvicorn on 127.0.0.1, its own process), counting the answers and watching its memory.

    python benchmarks/studio_fuzz.py [--minutes N] [--seed S] [--frames F]

The library: a generated walk of ``--frames`` frames, a 240-frame wandering take, a file linking to
/etc/passwd, a file whose name is not UTF-8 and a file that is not BVH.  Each request is one of:

* a request the page makes (loop, plane, relayout, stroke, job status, cancel, downloads) with valid bodies,
  so that real work is done and held (loops, authored animations);
* such a request with a field replaced by a random JSON value, a field dropped, or a random JSON body
  (deep nesting, huge and negative integers, floats, strings, booleans, nulls);
* raw bodies: random bytes, ``[`` x 100000, invalid UTF-8, a ``Content-Length`` of up to 64 MiB;
* random paths (ids that exist, were evicted or never existed, odd suffixes, percent-escapes), methods,
  and headers (``Host``, ``Origin``, ``Sec-Fetch-Site``, ``Content-Type``, the token right, wrong or absent).

Prints requests sent, the count of each status, every 500 (with the request), and the server's resident
memory (VmRSS) at start, after the first minute, at its highest and at the end; exit 1 if any 500 was seen.

    python benchmarks/studio_fuzz.py --attacks [--take PATH]

runs instead the memory attacks of issues 30 and 36 against a studio serving ``PATH`` (default: CMU 07_01 on
the 100-joint iClone rig from ../shared/data, else a generated 2000-frame walk): a 1 GiB body, 60 loop jobs of
20 cycles, 68 strokes as long as the studio allows (and one longer), 40 parallel slow downloads of a 100-cycle
loop, 300 connections that never end their request head, 50 clients that leave mid-body, then SIGTERM; with
the server's RSS after each.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def make_library(folder: Path, frames: int) -> None:
    from mocycle import write
    from mocycle.datasets import synthetic_nonperiodic, synthetic_walk

    write(synthetic_walk(n_frames=frames).motion, folder / "walk.bvh")
    write(synthetic_nonperiodic(n_frames=240).motion, folder / "wander.bvh")
    os.symlink("/etc/passwd", folder / "passwd.bvh")
    (folder / "notbvh.bvh").write_text("this is not a BVH file\n")
    odd = os.fsdecode(str(folder).encode() + b"/bad\xffname.bvh")
    write(synthetic_walk(n_frames=120, seed=3).motion, Path(odd))


def random_json(rng: random.Random, depth: int = 0):
    kind = rng.randrange(12 if depth < 4 else 8)
    if kind == 0:
        return None
    if kind == 1:
        return rng.choice([True, False])
    if kind == 2:
        return rng.choice([0, -1, 1, 2**31, 2**63, 2**70, -(2**70), 10**300, rng.randrange(-1000, 1000)])
    if kind == 3:
        return rng.choice([0.5, -0.0, 1e9, 1e308, -1e308, 3.14, rng.uniform(-1e6, 1e6)])
    if kind in (4, 5):
        return rng.choice(["", "no", "yes", "maybe", "true", "1", "auto", "lock", "pca", "\x00", "<script>",
                           "a" * 1000, "é" * 10, "\u202e"])
    if kind == 6:
        return "x" * rng.randrange(0, 200)
    if kind == 7:
        return rng.choice([[], {}, [[]], [[0, 0]], [0, 1, 2]])
    if kind in (8, 9):
        return [random_json(rng, depth + 1) for _ in range(rng.randrange(0, 6))]
    return {rng.choice(["keyframes", "markers", "points", "times_s", "optimize", "force", "method", "cycles",
                        "feet", "plant", "root", "model", "x", ""]): random_json(rng, depth + 1)
            for _ in range(rng.randrange(0, 6))}


class Fuzzer:
    def __init__(self, url: str, token: str, rng: random.Random):
        import httpx

        self.url, self.token, self.rng = url.rstrip("/"), token, rng
        self.host = re.match(r"https?://([^/]+)", url).group(1)
        self.http = httpx.Client(timeout=120)
        self.takes: list[str] = []
        self.planes: dict[str, tuple[list[int], list[list[float]]]] = {}
        self.jobs: list[str] = []
        self.strokes: list[str] = []
        self.status = collections.Counter()
        self.errors: list[str] = []
        self.sent = 0

    # ------------------------------------------------------------ one request
    def send(self, method: str, path: str, body=None, raw: bytes | None = None, headers: dict | None = None,
             good: bool = True):
        h = {"X-Mocycle-Token": self.token, "Origin": f"http://{self.host}"} if good else {}
        if body is not None or raw is not None:
            h["Content-Type"] = "application/json"
        h.update(headers or {})
        h = {k: v for k, v in h.items() if v is not None}
        content = raw if raw is not None else (None if body is None else json.dumps(body).encode())
        try:
            r = self.http.request(method, self.url + path, content=content, headers=h)
        except Exception as exc:  # the connection itself failed: count it, it is a finding too
            self.status[f"not sent or no answer ({type(exc).__name__})"] += 1
            self.sent += 1
            return None
        self.sent += 1
        self.status[r.status_code] += 1
        if r.status_code >= 500:
            self.errors.append(f"{r.status_code} {method} {path[:80]} {h} {(content or b'')[:200]!r} -> {r.text[:300]}")
        return r

    # ------------------------------------------------------------ the page's own requests, valid
    def setup(self):
        takes = self.send("GET", "/api/takes").json()["takes"]
        self.takes = [t["id"] for t in takes if t["status"] not in ("refused",)]
        self.readable = [t["id"] for t in takes if t["name"] in ("walk.bvh", "wander.bvh")]

    def plane(self, tid: str):
        from mocycle.studio.payload import unpack

        q = {"ratio": self.rng.choice(["0.05", "0.1", "0.03"]), "optimize": "1" if self.rng.random() < 0.05 else "0"}
        r = self.send("GET", f"/api/takes/{tid}/plane?" + "&".join(f"{k}={v}" for k, v in q.items()))
        if r is not None and r.status_code == 200:
            header, arrays = unpack(r.content)
            pts = arrays["points"].astype(float)
            self.planes[tid] = (header["keyframes"], pts[header["keyframes"]].tolist(), pts.tolist())

    def valid(self):
        rng = self.rng
        tid = rng.choice(self.readable)
        what = rng.randrange(7)
        if tid not in self.planes or what == 0:
            return self.plane(tid)
        key, markers, pts = self.planes[tid]
        if what == 1:
            r = self.send("POST", f"/api/takes/{tid}/loop", {"root": "motion", "cycles": rng.randrange(1, 8),
                                                                 "force": rng.random() < 0.3})
            if r is not None and r.status_code == 202:
                self.jobs.append(r.json()["id"])
        elif what == 2:
            r = self.send("POST", f"/api/takes/{tid}/relayout", {"keyframes": key, "markers": markers,
                                                                     "optimize": rng.random() < 0.1})
            if r is not None and r.status_code == 202:
                self.jobs.append(r.json()["id"])
        elif what in (3, 4):
            n = rng.randrange(2, min(len(pts), 2000))
            r = self.send("POST", f"/api/takes/{tid}/strokes", {
                "keyframes": key, "markers": markers, "points": pts[:n],
                "times_s": [i / rng.choice([30, 60, 120]) for i in range(n)], "feet": rng.choice(["keep", "lock"])})
            if r is not None and r.status_code == 200:
                self.strokes.append(r.json()["id"])
        elif what == 5 and self.jobs:
            j = rng.choice(self.jobs)
            self.send(rng.choice(["GET", "DELETE"]), f"/api/jobs/{j}")
            self.send("GET", f"/api/jobs/{j}/" + rng.choice(["motion", "loop.bvh", "loop.glb"]))
        elif what == 6 and self.strokes:
            s = rng.choice(self.strokes)
            self.send("GET", f"/api/strokes/{s}" + rng.choice(["/motion", ".bvh", ".glb"]))

    # ------------------------------------------------------------ hostile requests
    def mutated(self):
        rng = self.rng
        tid = rng.choice(self.takes + ["t99", "x", "t-1"])
        route = rng.choice(["loop", "relayout", "strokes"])
        base = {"loop": {"root": "motion", "cycles": 2, "force": False}, "relayout": {}, "strokes": {}}[route]
        if tid in self.planes and route != "loop":
            key, markers, pts = self.planes[tid]
            base = {"keyframes": key, "markers": markers}
            if route == "strokes":
                base |= {"points": pts[:50], "times_s": [i / 60 for i in range(50)]}
        body = dict(base)
        for _ in range(rng.randrange(1, 3)):
            choice = rng.randrange(3)
            if choice == 0 and body:
                body.pop(rng.choice(list(body)))
            elif choice == 1 and body:
                body[rng.choice(list(body))] = random_json(rng)
            else:
                field = rng.choice(list(body) or ["keyframes"])
                if isinstance(body.get(field), list) and body[field]:
                    lst = list(body[field])
                    lst[rng.randrange(len(lst))] = random_json(rng)
                    body[field] = lst
        if rng.random() < 0.1:
            body = random_json(rng)
        self.send("POST", f"/api/takes/{tid}/{route}", body)

    def raw(self):
        rng = self.rng
        tid = rng.choice(self.takes)
        path = f"/api/takes/{tid}/" + rng.choice(["loop", "relayout", "strokes"])
        kind = rng.randrange(6)
        if kind == 0:
            self.send("POST", path, raw=b"[" * rng.choice([100, 1000, 100_000]))
        elif kind == 1:
            self.send("POST", path, raw=bytes(rng.randrange(256) for _ in range(rng.randrange(1, 300))))
        elif kind == 2:
            self.send("POST", path, raw=b'{"keyframes": "\xff\xfe"}')
        elif kind == 3:
            self.declared(path, rng.choice([9 << 20, 64 << 20, 1 << 30]))
        elif kind == 4:
            self.send("POST", path, raw=b" " * rng.choice([1 << 20, 9 << 20]))
        else:
            self.send("POST", path, raw=b'{"keyframes": [' + b"1" * 5000 + b"]}")

    def declared(self, path: str, length: int):
        """A POST that declares ``length`` bytes and sends one (over a socket: httpx will not send it)."""
        import socket

        host, port = self.host.rsplit(":", 1)
        head = (f"POST {path} HTTP/1.1\r\nHost: {self.host}\r\nContent-Type: application/json\r\n"
                f"X-Mocycle-Token: {self.token}\r\nContent-Length: {length}\r\nConnection: close\r\n\r\n")
        self.sent += 1
        try:
            with socket.create_connection((host, int(port)), timeout=60) as sock:
                sock.sendall(head.encode() + b"[")
                answer = sock.recv(65536)
            code = int(answer.split()[1])
        except (OSError, ValueError, IndexError) as exc:
            self.status[f"not sent or no answer ({type(exc).__name__})"] += 1
            return
        self.status[code] += 1
        if code >= 500:
            self.errors.append(f"{code} POST {path} Content-Length {length} -> {answer[:300]!r}")

    def paths(self):
        rng = self.rng
        ids = self.takes + self.jobs[-5:] + self.strokes[-5:] + ["t999", "j0", "j99999999", "s0", "s1", "j1",
                                                                   "%2e%2e", "..", "t0%00", "é", "a" * 300]
        i = rng.choice(ids)
        ratio = rng.choice(["x", "-1", "1e9", "nan", "0.05"])
        suffix = rng.choice(["bvh", "glb", "fbx", "", "x" * 50])
        path = rng.choice([f"/api/takes/{i}/motion", f"/api/takes/{i}/plane?ratio={ratio}",
                           f"/api/jobs/{i}", f"/api/jobs/{i}/motion", f"/api/jobs/{i}/loop.{suffix}",
                           f"/api/strokes/{i}.{suffix}", f"/api/strokes/{i}/motion",
                           "/static/../app.py", "/static/%2e%2e/app.py", "/static/vendor/../../app.py", "/",
                           f"/api/takes/{i}/plane?optimize={rng.choice(['no', 'maybe', '1', 'true'])}",
                           f"/api/takes/{i}/plane?projection={rng.choice(['umap', 'pca', 'mds', ''])}&bogus=1"])
        self.send(rng.choice(["GET", "GET", "POST", "DELETE", "PUT", "PATCH", "OPTIONS", "HEAD"]), path,
                  body=rng.choice([None, {}, random_json(rng)]))

    def headers(self):
        rng = self.rng
        tid = rng.choice(self.takes)
        port = self.host.split(":")[-1]
        h = {"Host": rng.choice([self.host, "attacker.example", "localhost:1", "127.0.0.1", "[::1]:" + port,
                                 "localhost:" + port, "", "a:b:c", None]),
             "Origin": rng.choice([None, f"http://{self.host}", "http://attacker.example", "null",
                                   "https://" + self.host]),
             "Sec-Fetch-Site": rng.choice([None, "same-origin", "cross-site", "same-site", "none"]),
             "Content-Type": rng.choice(["application/json", "text/plain", "application/x-www-form-urlencoded",
                                         "application/json; charset=utf-8", "multipart/form-data", None]),
             "X-Mocycle-Token": rng.choice([self.token, None, "wrong", self.token + "x", ""]),
             "Cookie": rng.choice([None, "mocycle_token=" + self.token, 'a="b', "mocycle_token=wrong"])}
        method, path = rng.choice([("POST", f"/api/takes/{tid}/loop"), ("GET", "/api/takes"), ("GET", "/"),
                                   ("DELETE", "/api/jobs/j1"), ("POST", f"/api/takes/{tid}/strokes")])
        self.send(method, path, body={"root": "motion"} if method == "POST" else None, headers=h, good=False)

    def step(self):
        r = self.rng.random()
        if r < 0.35:
            self.valid()
        elif r < 0.6:
            self.mutated()
        elif r < 0.7:
            self.raw()
        elif r < 0.85:
            self.paths()
        else:
            self.headers()


def start(paths, env):
    proc = subprocess.Popen([sys.executable, "-m", "mocycle", "studio", *map(str, paths), "--no-browser", "--port",
                             "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    url = proc.stdout.readline().split()[3]
    import httpx

    token = re.search(r'name="mocycle-token" content="([^"]+)"', httpx.get(url, timeout=60).text).group(1)
    while True:
        data = httpx.get(url + "api/takes", timeout=60).json()
        if data["done"] == data["total"]:
            return proc, url, token, data["takes"]
        time.sleep(0.5)


def attacks(take: Path, env, only_36: bool = False) -> int:
    """The issues' memory attacks against a real server; the server's RSS after each (``only_36``: issue 36's)."""
    import socket

    import httpx

    from mocycle.studio.payload import unpack

    proc, url, token, takes = start([take], env)
    rows = [("library analysed", "", rss_mb(proc.pid))]
    try:
        host = re.match(r"http://([^/]+)/", url).group(1)
        h = {"X-Mocycle-Token": token, "Content-Type": "application/json"}
        c = httpx.Client(base_url=url.rstrip("/"), headers=h, timeout=600)
        tid = takes[0]["id"]
        if only_36:
            rows += files_that_lie_attacks(proc, c, host, token, tid)
            return 0
        # 1 GiB body, declared and then streamed until the server stops reading
        sent = 0
        with socket.create_connection(tuple(host.rsplit(":", 1)), timeout=60) as sock:
            sock.sendall(f"POST /api/takes/{tid}/strokes HTTP/1.1\r\nHost: {host}\r\nContent-Type: "
                         f"application/json\r\nX-Mocycle-Token: {token}\r\nContent-Length: {1 << 30}\r\n\r\n"
                         .encode())
            chunk = b" " * (1 << 20)
            try:
                for _ in range(1024):
                    sock.sendall(chunk)
                    sent += len(chunk)
            except OSError:
                pass
            try:
                answer = sock.recv(65536).split(b"\r\n")[0].decode()
            except OSError as exc:
                answer = f"connection closed ({exc})"
        rows.append(("a 1 GiB body (Content-Length: 1073741824)", f"{answer}; {sent >> 20} MiB sent before the "
                     "server closed", rss_mb(proc.pid)))
        # 60 loop jobs of 20 cycles
        t0 = time.monotonic()
        codes = collections.Counter()
        for _ in range(60):
            r = c.post(f"/api/takes/{tid}/loop", json={"cycles": 20, "root": "motion", "force": True})
            codes[r.status_code] += 1
            if r.status_code == 202:
                j = r.json()
                while j["status"] in ("queued", "running"):
                    time.sleep(0.1)
                    j = c.get(f"/api/jobs/{j['id']}").json()
                codes[j["status"]] += 1
        first = c.get("/api/jobs/j2/loop.bvh")
        rows.append(("60 loop jobs of 20 cycles, one after another", f"{dict(codes)}; the first job now "
                     f"{first.status_code} in {time.monotonic() - t0:.0f} s", rss_mb(proc.pid)))
        # strokes as long as allowed, and one longer
        header, arrays = unpack(c.get(f"/api/takes/{tid}/plane", params={"optimize": 0}).content)
        key = header["keyframes"]
        pts = arrays["points"].astype(float)
        fps = next(t for t in c.get("/api/takes").json()["takes"] if t["id"] == tid)["facts"]["fps"]

        def stroke(frames):
            return c.post(f"/api/takes/{tid}/strokes", json={
                "keyframes": key, "markers": pts[key].tolist(), "points": [pts[0].tolist(), pts[-1].tolist()],
                "times_s": [0, (frames - 1) / fps], "feet": "keep"})

        long = stroke(17_971)
        rows.append(("a stroke of 17,971 frames", f"{long.status_code}: {long.json().get('error', '')}",
                     rss_mb(proc.pid)))
        t0 = time.monotonic()
        codes = collections.Counter(stroke(12_000).status_code for _ in range(68))
        gone = c.get("/api/strokes/s1/motion")
        rows.append(("68 strokes of 12,000 frames", f"{dict(codes)}; the first stroke now {gone.status_code} "
                     f"in {time.monotonic() - t0:.0f} s", rss_mb(proc.pid)))
        rows += files_that_lie_attacks(proc, c, host, token, tid)
        return 0
    finally:
        t0 = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        proc.wait(60)
        err = proc.stderr.read()
        rows.append(("SIGTERM", f"exit {proc.returncode} in {time.monotonic() - t0:.1f} s; tracebacks on the "
                     f"server's stderr over the whole run: {err.count('Traceback')}", float("nan")))
        _print_attacks(take, takes, rows)


def _print_attacks(take: Path, takes, rows) -> None:
    print(f"studio memory attacks on {take.name} ({takes[0]['facts'].get('joints')} joints, "
          f"{takes[0]['facts'].get('frames')} frames)")
    print("| attack | answer | server RSS after, MB |\n|---|---|---|")
    for what, answer, mb in rows:
        print(f"| {what} | {answer} | {mb:.0f} |")


def files_that_lie_attacks(proc, c, host: str, token: str, tid: str) -> list[tuple[str, str, float]]:
    """Issue 36's attacks: 40 parallel downloads of a 100-cycle loop (the server's RSS sampled meanwhile), 300
    connections that never finish their request head, 50 clients that leave mid-body."""
    import socket
    import threading

    import httpx

    rows = []
    j = c.post(f"/api/takes/{tid}/loop", json={"cycles": 100, "root": "motion", "force": True}).json()
    while j["status"] in ("queued", "running"):
        time.sleep(0.1)
        j = c.get(f"/api/jobs/{j['id']}").json()
    before = rss_mb(proc.pid)
    sizes, peak, done = [], [before], threading.Event()

    def download():
        with httpx.stream("GET", f"{c.base_url}/api/jobs/{j['id']}/loop.bvh", headers=c.headers, timeout=600) as r:
            n = 0
            for piece in r.iter_bytes(1 << 16):
                n += len(piece)
                time.sleep(0.002)  # slow readers: the server must not buffer the rest for each
            sizes.append(n)

    def watch():
        while not done.is_set():
            peak.append(rss_mb(proc.pid))
            time.sleep(0.05)

    watcher = threading.Thread(target=watch)
    watcher.start()
    t0 = time.monotonic()
    threads = [threading.Thread(target=download) for _ in range(40)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(600)
    done.set()
    watcher.join()
    rows.append((f"40 parallel slow downloads of the {max(sizes, default=0) / 2**20:.1f} MiB loop.bvh of a 100-cycle "
                 f"loop", f"{len(sizes)} × 200 in {time.monotonic() - t0:.0f} s; RSS before {before:.0f} MB, at most "
                 f"{max(peak):.0f} MB during", rss_mb(proc.pid)))
    address = tuple(host.rsplit(":", 1))
    slow = []
    for _ in range(300):
        sock = socket.create_connection((address[0], int(address[1])))
        sock.sendall(b"GET /api/takes HTTP/1.1\r\nHost: " + host.encode() + b"\r\n")
        slow.append(sock)
    time.sleep(12)
    closed = 0
    for sock in slow:
        sock.setblocking(False)
        try:
            closed += sock.recv(100) == b""
        except BlockingIOError:
            pass
        except OSError:
            closed += 1
        sock.close()
    rows.append(("300 connections sending a request head but never its end", f"{closed} of 300 closed by the server "
                 "within 12 s", rss_mb(proc.pid)))
    for _ in range(50):
        sock = socket.create_connection((address[0], int(address[1])))
        sock.sendall(f"POST /api/takes/{tid}/loop HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\n"
                     f"X-Mocycle-Token: {token}\r\nContent-Length: 1000\r\n\r\n{{\"cycles\"".encode())
        sock.close()
    time.sleep(1)
    alive = c.get("/api/takes").status_code
    rows.append(("50 clients leaving mid-body", f"the server answers {alive} after them", rss_mb(proc.pid)))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--frames", type=int, default=1000, help="frames of the walk the valid requests work on")
    ap.add_argument("--attacks", action="store_true", help="the issue's memory attacks instead of the fuzz")
    ap.add_argument("--only-36", action="store_true", help="with --attacks: only issue 36's (downloads, slow heads, "
                                                          "clients that leave)")
    ap.add_argument("--take", type=Path, default=REPO.parent / "shared" / "data" / "cmu-iclone" / "07_01.bvh")
    args = ap.parse_args(argv)
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    if args.attacks:
        take = args.take
        if not take.exists():
            from mocycle import write
            from mocycle.datasets import synthetic_walk

            take = Path(tempfile.mkdtemp(prefix="mocycle-studio-attacks-")) / "walk_2000.bvh"
            write(synthetic_walk(n_frames=2000).motion, take)
        return attacks(take, env, args.only_36)
    with tempfile.TemporaryDirectory(prefix="mocycle-studio-fuzz-") as tmp:
        folder = Path(tmp)
        make_library(folder, args.frames)
        proc = subprocess.Popen([sys.executable, "-m", "mocycle", "studio", str(folder), "--no-browser", "--port", "0"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        try:
            line = proc.stdout.readline()
            url = line.split()[3]
            import httpx

            page = httpx.get(url, timeout=60).text
            token = re.search(r'name="mocycle-token" content="([^"]+)"', page).group(1)
            while True:  # the library's analysis first (it is part of the start, not of the load)
                data = httpx.get(url + "api/takes", timeout=60).json()
                if data["done"] == data["total"]:
                    break
                time.sleep(0.5)
            fz = Fuzzer(url, token, random.Random(args.seed))
            fz.setup()
            rss = {"start": rss_mb(proc.pid)}
            peak = rss["start"]
            by_minute = []
            t0 = time.monotonic()
            last = t0
            while time.monotonic() - t0 < 60 * args.minutes:
                fz.step()
                now = time.monotonic()
                if now - last > 5:
                    last = now
                    peak = max(peak, rss_mb(proc.pid))
                    if "1 min" not in rss and now - t0 > 60:
                        rss["1 min"] = rss_mb(proc.pid)
                    if now - t0 > 60 * (len(by_minute) + 1):
                        by_minute.append(rss_mb(proc.pid))
                    if proc.poll() is not None:
                        fz.errors.append(f"the server stopped (exit {proc.returncode})")
                        break
            rss["end"] = rss_mb(proc.pid)
            rss["peak"] = max(peak, rss["end"])
            elapsed = time.monotonic() - t0
        finally:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
        tracebacks = proc.stderr.read().count("Traceback")
    print(f"studio fuzz: {fz.sent} requests in {elapsed / 60:.1f} min (seed {args.seed}, walk of {args.frames} frames)")
    print("| status | requests |\n|---|---|")
    for code, n in sorted(fz.status.items(), key=lambda kv: str(kv[0])):
        print(f"| {code} | {n} |")
    print(f"server RSS MB: start {rss['start']:.0f}, after 1 min {rss.get('1 min', float('nan')):.0f}, "
          f"peak {rss['peak']:.0f}, end {rss['end']:.0f}; tracebacks on the server's stderr: {tracebacks}")
    print("server RSS MB at the end of each minute: " + " ".join(f"{m:.0f}" for m in by_minute))
    print(f"500s and failures: {len(fz.errors)}")
    for e in fz.errors[:20]:
        print("  " + e)
    return 1 if fz.errors else 0


if __name__ == "__main__":
    sys.exit(main())
