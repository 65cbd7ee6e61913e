"""An hour of capture in a minute (issue 38): capture sessions of growing length looped part by part.

    python benchmarks/session_scale.py [--minutes 1,4,15,60] [--fps 120] [--workers 1,0] [--keep DIR]

Builds sessions of ``--minutes`` minutes at ``--fps`` with ``benchmarks/sessions.py``'s builder (Bandai takes of
``../shared/data`` drawn with a fixed seed and joined end to end, one performer's proportions; without the
shared data, the project's synthetic takes), then runs, each in a fresh process, as a user would:

    mocycle loop SESSION.bvh -o OUT/s.bvh --part all --root motion --json --workers N

for every N of ``--workers`` (0: the cores this process may use), side by side on the same file, and prints per size
and N: frames, the parts the JSON calls loopable, loops written, the loopable parts listed in ``not_looped`` with
their reason and those neither looped nor listed ("lost": 0 is the goal), CPU seconds (every process of the run),
wall seconds, peak memory (the sum of the proportional set sizes of the command and its worker processes, sampled
every 50 ms: pages they share counted once), and the largest resident set of any one of them, the stage times the
command reports (reading and cutting into parts, then per-part fitting, metrics, feet, writing, summed over the
parts), whether the files written are byte-identical to the one-worker run, and the growth exponents of CPU time and
peak memory between the last two sizes (1 = linear).
"""

from __future__ import annotations

import argparse
import filecmp
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from activities import default_data, mocycle_cmd  # noqa: E402
from sessions import real_sessions, synthetic_sessions  # noqa: E402


def _tree_rss(pid: int) -> int:
    """Memory of ``pid`` and its descendants (bytes): the sum of their proportional set sizes (from /proc)."""
    total, todo = 0, [pid]
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    while todo:
        p = todo.pop()
        try:  # proportional set size: a page shared by n processes counts 1/n in each (forked workers)
            with open(f"/proc/{p}/smaps_rollup") as f:
                total += next(int(line.split()[1]) * 1024 for line in f if line.startswith("Pss:"))
        except (OSError, StopIteration):
            pass
        todo += children.get(p, [])
    return total


def run(session: Path, out: Path, workers: int) -> dict:
    shutil.rmtree(out, ignore_errors=True)  # a kept folder of an earlier run: its files would be compared too
    out.mkdir(parents=True)
    cmd = mocycle_cmd() + ["loop", str(session), "-o", str(out / "s.bvh"), "--part", "all", "--root", "motion",
                           "--json"] + (["--workers", str(workers)] if workers else [])
    peak = [0]
    with tempfile.TemporaryFile() as so, tempfile.TemporaryFile() as se:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=so, stderr=se)
        stop = threading.Event()

        def sample():
            while not stop.is_set():
                peak[0] = max(peak[0], _tree_rss(p.pid))
                stop.wait(0.05)

        watcher = threading.Thread(target=sample, daemon=True)
        watcher.start()
        _, status, usage = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t0
        stop.set()
        watcher.join()
        so.seek(0)
        se.seek(0)
        text, err = so.read().decode(), se.read().decode(errors="replace")
    code = os.waitstatus_to_exitcode(status)
    doc = json.loads(text) if text.strip().startswith("{") else {}
    # every part the JSON calls loopable is looped or listed in not_looped with its reason
    parts = doc.get("parts") or []
    loopable = {k for k, part in enumerate(parts) if part.get("loop")}
    looped = {f.get("part") for f in doc.get("loops") or []}
    listed = {d.get("part") for d in doc.get("not_looped") or []}
    return {"loopable": len(loopable), "listed": len(loopable & listed), "lost": len(loopable - looped - listed),
            "code": code, "wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "peak_mb": peak[0] / 2**20,
            "max_rss_mb": usage.ru_maxrss / 1024,
            "loops": len(doc.get("loops") or []), "timings": doc.get("timings_s") or {},
            "error": "" if code in (0, 3) else err.strip().splitlines()[-1:]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", default="1,4,15,60")
    ap.add_argument("--fps", type=float, default=120.0)
    ap.add_argument("--workers", default="1,0", help="worker counts to compare (0: the cores this process may use)")
    ap.add_argument("--data", type=Path, default=None)
    ap.add_argument("--keep", type=Path, default=None)
    args = ap.parse_args(argv)
    minutes = [float(m) for m in args.minutes.split(",")]
    counts = [int(w) for w in args.workers.split(",")]
    print(f"command: {' '.join(mocycle_cmd())}; cores this process may use: {len(os.sched_getaffinity(0))}")
    with tempfile.TemporaryDirectory(prefix="mocycle-scale-") as tmp:
        root = args.keep or Path(tmp)
        (root / "sessions").mkdir(parents=True, exist_ok=True)
        data = args.data or default_data()
        t0 = time.perf_counter()
        if data.is_dir():
            sessions = [s for s in real_sessions(root / "sessions", data, minutes, args.fps, quick=True)
                        if "min_" in s.name]
        else:
            print(f"({data} not found: synthetic sessions)")
            sessions = synthetic_sessions(root / "sessions", quick=True)
        print(f"built {len(sessions)} session(s) in {time.perf_counter() - t0:.0f} s")
        rows = []
        for s in sessions:
            first = None
            for w in counts:
                out = root / "loops" / f"{s.name}_w{w}"
                r = run(s.path, out, w)
                same = "-"
                if first is None:
                    first = out
                else:
                    a, b = sorted(os.listdir(first)), sorted(os.listdir(out))
                    same = "yes" if a == b and all(filecmp.cmp(first / x, out / x, shallow=False) for x in a) \
                        else "NO"
                rows.append((s, w, r, same))
                print(f"  {s.name} workers {w or 'all'}: exit {r['code']}, {r['loops']} loops, {r['cpu']:.1f} CPU s, "
                      f"{r['wall']:.1f} s, {r['peak_mb']:.0f} MB {r['error'] or ''}", file=sys.stderr, flush=True)
    print()
    print(f"{'session':24} {'frames':>8} {'workers':>7} {'exit':>4} {'loopable':>8} {'loops':>5} {'listed':>6} "
          f"{'lost':>4} {'CPU s':>7} {'wall s':>7} {'peak MB':>8} {'max RSS':>8} {'same bytes':>10}  stages (s)")
    for s, w, r, same in rows:
        stages = ", ".join(f"{k} {v:.1f}" for k, v in r["timings"].items() if k != "total")
        print(f"{s.name:24} {s.frames:8d} {w or 'all':>7} {r['code']:4d} {r['loopable']:8d} {r['loops']:5d} "
              f"{r['listed']:6d} {r['lost']:4d} {r['cpu']:7.1f} "
              f"{r['wall']:7.1f} {r['peak_mb']:8.0f} {r['max_rss_mb']:8.0f} {same:>10}  {stages}")
    for w in counts:
        sized = [(s, r) for s, ww, r, _ in rows if ww == w]
        if len(sized) >= 2:
            (a, ra), (b, rb) = sized[-2], sized[-1]
            ratio = b.frames / a.frames
            print(f"workers {w or 'all'}: growth {a.name} -> {b.name}: CPU exponent "
                  f"{math.log(rb['cpu'] / ra['cpu']) / math.log(ratio):.2f}, memory exponent "
                  f"{math.log(rb['peak_mb'] / ra['peak_mb']) / math.log(ratio):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
