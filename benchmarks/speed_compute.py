"""Speed of the rotation maths and of the phase at scale (issue 15, goals 4 and 5), as ratios measured in one run.

    python benchmarks/speed_compute.py [--only rotation,phase] [--repeats 5] [--baseline e5d3fa2]
                                       [--sizes 300,1000,3000,10000,30000,100000] [--data DIR]

Run it with one BLAS thread (``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1``) and, for the DREiMac
column, with the python of a venv that has the ``bench`` extra (DREiMac, numba), e.g.
``PYTHONPATH=$PWD/src /work/benchvenv/bin/python benchmarks/speed_compute.py``.

**rotation**: every job runs in a fresh process, the baseline's and today's alternately (``--repeats``
rounds), so both see the same machine load; the baseline is the ``src`` of ``--baseline`` (a git
revision, unpacked by ``git archive`` into a temporary folder).  Each process runs its job once to warm
up, then three times; the figures are the median and min-max of all timed runs, wall time and (below
it) the processes' CPU time, which moves less when other work shares the machine.  Jobs: ``loop`` on the
100-joint iClone rig (cmu-iclone/07_01) and the 22-joint Bandai rig (walk, normal), per frame;
``stretch`` (factor 2, cmu-iclone/02_01); swing ``playback`` (cmu/01_01, segmented once outside the
timing); the keyframes' all-pairs pose distance matrix (every second frame of cmu/01_01).

**phase**: seeded synthetic walks (``mocycle.datasets.synthetic_walk``, 1 degree of noise, seed 7) of
each size; per size, alternately: ``find_phase(motion)`` (everything: features, coordinates, periods; on a
fresh ``motion.replace()`` each round, so nothing a motion caches, e.g. its heading frame, carries over),
``CircularCoordinates`` on the prepared point cloud of ``benchmarks/phase.py`` and DREiMac's
``CircularCoords`` on the same cloud.  DREiMac 0.3 compiles its numba helpers again on every call; its
*warm* time is the call minus numba's compile events.  Period error: the found period against the
walk's true one (find_phase: its period; DREiMac: the slope of its unwrapped coordinate); "equal or
better" allows 0.05 percentage points.

The last lines print each goal as a ratio with ``met`` / ``NOT met`` and the load average.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
DEFAULT_DATA = REPO.parent / "shared" / "data"
BASELINE = "e5d3fa2"
SIZES = (300, 1000, 3000, 10_000, 30_000, 100_000)
RUNS_PER_PROCESS = 3
LOOP_RATIO_GOAL = 1.5
SPEEDUP_GOAL = 2.0
PHASE_GOAL = 5.0
BIG = 30_000  # phase sizes from here on are timed once (a 100k-frame DREiMac run takes many seconds)
LINEAR_EXPONENT = 1.05  # "linear": time grows at most like N^1.05 from 10k to 100k frames
PERIOD_TIE = 0.05  # period errors (percent) this close count as equal

JOBS = {  # name -> (job, take under --data)
    "loop iClone": ("loop", "cmu-iclone/07_01.bvh"),
    "loop Bandai": ("loop", "bandai/dataset-1_walk_normal_001.bvh"),
    "stretch": ("stretch", "cmu-iclone/02_01.bvh"),
    "playback": ("playback", "cmu/01_01.bvh"),
    "distance matrix": ("distance", "cmu/01_01.bvh"),
}


# -- rotation: one job in this process (the worker) -------------------------------------------------------------------
def _job(kind: str, path: str):
    """A no-argument callable doing one run of ``kind`` on the take at ``path``, and the take's frame count."""
    from mocycle.io import read

    motion = read(path)
    if kind == "loop":
        from mocycle.tasks import loop

        return (lambda: loop.run(motion)), motion.n_frames
    if kind == "stretch":
        from mocycle.warp import stretch_motion

        return (lambda: stretch_motion(motion, 2.0)), motion.n_frames
    if kind == "playback":
        from mocycle.swings import playback, segment

        seg = segment(motion, threshold=0.4)
        return (lambda: playback(seg)), motion.n_frames
    if kind == "distance":
        from mocycle.keyframes.distance import pose_distance_matrix

        q, w = motion.rotations[::2], np.ones(motion.n_joints)  # every 2nd frame: 1376 x 1376 pairs
        return (lambda: pose_distance_matrix(q, w)), q.shape[0]
    raise ValueError(kind)


def worker(kind: str, path: str) -> None:
    """Print ``{"frames": n, "seconds": [...]}`` for one warm-up and :data:`RUNS_PER_PROCESS` timed runs."""
    warnings.simplefilter("ignore")
    fn, frames = _job(kind, path)
    from mocycle.io import read

    q = read(path).rotations  # joints that turn at all: what the per-joint figure divides by
    moving = int((np.abs(np.einsum("tjk,jk->tj", q, q[0])).min(axis=0) < 1 - 1e-9).sum())
    fn()
    times, cpu = [], []
    for _ in range(RUNS_PER_PROCESS):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    print(json.dumps({"frames": frames, "moving_joints": moving, "seconds": times, "cpu": cpu}))


def baseline_src(rev: str, into: Path) -> Path | None:
    """The ``src`` folder of git revision ``rev`` unpacked under ``into`` (None when git cannot)."""
    try:
        blob = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", rev, "src"], check=True,
                              capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError) as exc:
        print(f"no baseline: git archive {rev} failed ({exc})")
        return None
    tar = into / "base.tar"
    tar.write_bytes(blob)
    with tarfile.open(tar) as t:
        t.extractall(into)  # noqa: S202 - our own repository's archive
    return into / "src"


def run_worker(src: Path, kind: str, path: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src), "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
           "MKL_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", kind, str(path)], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fmt(values: list[float], scale: float = 1.0, unit: str = "s") -> str:
    v = [x * scale for x in values]
    return f"{statistics.median(v):8.4f} {unit} ({min(v):.4f}-{max(v):.4f})"


def rotation(data: Path, repeats: int, rev: str) -> list[tuple[str, float, float, bool]]:
    """Time the jobs (baseline and today alternately); returns the goal lines (name, value, goal, met)."""
    today = REPO / "src"
    with tempfile.TemporaryDirectory() as tmp:
        base = baseline_src(rev, Path(tmp))
        variants = {"today": today} | ({f"{rev}": base} if base else {})
        times: dict[tuple[str, str], list[float]] = {}
        cpu: dict[tuple[str, str], list[float]] = {}
        frames: dict[str, int] = {}
        moving: dict[str, int] = {}
        for _ in range(repeats):
            for name, (kind, take) in JOBS.items():
                path = data / take
                if not path.is_file():
                    continue
                for label, src in variants.items():
                    r = run_worker(src, kind, path)
                    times.setdefault((name, label), []).extend(r["seconds"])
                    cpu.setdefault((name, label), []).extend(r["cpu"])
                    frames[name] = r["frames"]
                    moving[name] = r["moving_joints"]
    print(f"\n## Rotation maths ({repeats} rounds x {RUNS_PER_PROCESS} runs per process; baseline {rev})")
    print(f"{'job':<16} {'frames':>6}  " + "  ".join(f"{v:<30}" for v in variants))
    for name in JOBS:
        if name not in frames:
            print(f"{name:<16} skipped: {JOBS[name][1]} not under {data}")
            continue
        cells = [_fmt(times[(name, v)]) for v in variants]
        print(f"{name:<16} {frames[name]:>6}  " + "  ".join(f"{c:<30}" for c in cells))
    print("CPU time of the same runs (process_time; moves less than wall time on a busy machine):")
    for name in JOBS:
        if name in frames:
            cells = [_fmt(cpu[(name, v)]) for v in variants]
            print(f"{name:<16} {frames[name]:>6}  " + "  ".join(f"{c:<30}" for c in cells))
    goals = []

    def med(name, v):
        return statistics.median(times[(name, v)])

    if {"loop iClone", "loop Bandai"} <= frames.keys():
        for v in variants:
            per = {n: [t / frames[n] * 1e3 for t in times[(n, v)]] for n in ("loop iClone", "loop Bandai")}
            print(f"loop per frame ({v}): iClone {_fmt(per['loop iClone'], unit='ms')}, "
                  f"Bandai {_fmt(per['loop Bandai'], unit='ms')}")
        ratio = (med("loop iClone", "today") / frames["loop iClone"]) / (med("loop Bandai", "today")
                                                                         / frames["loop Bandai"])
        goals.append(("loop per frame, iClone / Bandai", ratio, LOOP_RATIO_GOAL, ratio <= LOOP_RATIO_GOAL))
        ratio = (statistics.median(cpu[("loop iClone", "today")]) / frames["loop iClone"]) / (
            statistics.median(cpu[("loop Bandai", "today")]) / frames["loop Bandai"])
        goals.append(("  (CPU time) loop per frame, iClone / Bandai", ratio, LOOP_RATIO_GOAL, ratio <= LOOP_RATIO_GOAL))
        # not the goal, the figure that tells whether the bigger rig costs more per joint: loop's work is
        # linear in the joints that move (fit, projection, metrics), so per frame the ratio cannot fall far
        # below the ratio of moving joints, printed with it
        per_joint = {n: med(n, "today") / (frames[n] * moving[n]) for n in ("loop iClone", "loop Bandai")}
        ratio = per_joint["loop iClone"] / per_joint["loop Bandai"]
        print(f"moving joints: iClone {moving['loop iClone']}, Bandai {moving['loop Bandai']} "
              f"(ratio {moving['loop iClone'] / moving['loop Bandai']:.2f}); loop per moving joint and frame: "
              f"iClone {per_joint['loop iClone'] * 1e6:.2f} us, Bandai {per_joint['loop Bandai'] * 1e6:.2f} us, "
              f"ratio {ratio:.2f}")
    if base:
        for name in ("loop iClone", "stretch", "playback", "distance matrix"):
            if name in frames:
                speedup = med(name, rev) / med(name, "today")
                goal = SPEEDUP_GOAL if name in ("stretch", "playback") else 1.0
                goals.append((f"{name}: {rev} / today", speedup, goal, speedup >= goal))
                speedup = statistics.median(cpu[(name, rev)]) / statistics.median(cpu[(name, "today")])
                goals.append((f"  (CPU time) {name}: {rev} / today", speedup, goal, speedup >= goal))
    return goals


# -- phase --------------------------------------------------------------------------------------------------------
def dreimac_warm(X: np.ndarray) -> tuple[float, np.ndarray | None]:
    """(seconds of a DREiMac call minus its numba compilation, its coordinate in cycles)."""
    sys.path.insert(0, str(HERE))
    import phase as bench_phase

    total, compiling, coord = bench_phase.timed_dreimac(X)
    return total - compiling, coord


def phase(sizes: list[int], repeats: int) -> list[tuple[str, float, float, bool]]:
    sys.path.insert(0, str(HERE))
    import phase as bench_phase

    from mocycle.phase import find_phase

    try:
        import dreimac  # noqa: F401
        import numba  # noqa: F401
        have_dreimac = True
    except Exception as exc:  # ImportError or a broken build
        have_dreimac = False
        print(f"DREiMac not available ({type(exc).__name__}: {exc}); run with the bench venv's python")
    print(f"\n## Phase at scale ({repeats} rounds per size, 1 from {BIG} frames; seconds, median (min-max); "
          "period error in %)")
    print(f"{'frames':>7}  {'find_phase':<28} {'CircularCoordinates':<28} {'DREiMac warm':<28} "
          f"{'DREiMac/fp':>10} {'fp err':>7} {'DM err':>7}")
    results = {}
    for n in sizes:
        walk = bench_phase.synthetic(n)
        true_period = float(np.nanmedian(walk.period_frames))
        X = bench_phase.prepare(walk.motion)
        t = {"fp": [], "cc": [], "dm": []}
        fp_err = dm_err = np.nan
        if have_dreimac:
            dreimac_warm(X)  # numba's first import and compile, outside the figures
        for _ in range(repeats if n < BIG else 1):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fresh = walk.motion.replace()  # the same arrays, nothing cached on the motion by an earlier call
                t0 = time.perf_counter()
                res = find_phase(fresh)
                t["fp"].append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                bench_phase.run_mocycle(X)
                t["cc"].append(time.perf_counter() - t0)
                if have_dreimac:
                    secs, coord = dreimac_warm(X)
                    t["dm"].append(secs)
                    dm_err = abs(bench_phase.unwrap_period(coord) / true_period - 1) * 100
            fp_err = abs(res.classes[0].period_frames / true_period - 1) * 100 if res.classes else np.inf
        results[n] = t
        ratio = statistics.median(t["dm"]) / statistics.median(t["fp"]) if t["dm"] else np.nan
        print(f"{n:>7}  {_fmt(t['fp']):<28} {_fmt(t['cc']):<28} "
              f"{_fmt(t['dm']) if t['dm'] else 'n/a':<28} {ratio:>10.2f} {fp_err:>7.3f} {dm_err:>7.3f}",
              flush=True)
        results[n]["err"] = (fp_err, dm_err)
    goals = []
    if 10_000 in results and 100_000 in results:
        for key, label in (("fp", "find_phase"), ("cc", "CircularCoordinates")):
            k = np.log(statistics.median(results[100_000][key]) / statistics.median(results[10_000][key])) / np.log(10)
            goals.append((f"{label} time exponent, 10k -> 100k frames", k, LINEAR_EXPONENT, k <= LINEAR_EXPONENT))
    if have_dreimac:
        for n, t in results.items():
            ratio = statistics.median(t["dm"]) / statistics.median(t["fp"])
            fp_err, dm_err = t["err"]
            goals.append((f"DREiMac warm / find_phase at {n} frames", ratio, PHASE_GOAL, ratio >= PHASE_GOAL))
            goals.append((f"period error find_phase - DREiMac at {n} frames (%)", fp_err - dm_err, PERIOD_TIE,
                          fp_err <= dm_err + PERIOD_TIE))
    return goals


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="rotation,phase", help="comma-separated: rotation, phase")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved rounds (default 5)")
    parser.add_argument("--baseline", default=BASELINE, help="git revision the rotation jobs are compared with")
    parser.add_argument("--sizes", default=",".join(str(s) for s in SIZES), help="phase: frame counts")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the shared data folder")
    parser.add_argument("--worker", nargs=2, metavar=("JOB", "TAKE"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(*args.worker)
        return 0
    parts = {p.strip() for p in args.only.split(",") if p.strip()}
    unknown = parts - {"rotation", "phase"}
    if unknown:
        parser.error(f"--only takes rotation and/or phase; got {', '.join(sorted(unknown))}")
    print(f"load average at start: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} "
          f"on {os.cpu_count()} cores; BLAS threads: {os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    goals = []
    if "rotation" in parts:
        goals += rotation(args.data, args.repeats, args.baseline)
    if "phase" in parts:
        goals += phase([int(s) for s in args.sizes.split(",")], max(1, min(args.repeats, 3)))
    print("\n## Goals (issue 15)")
    for name, value, goal, met in goals:
        print(f"{name:<58} {value:8.2f}  goal {goal:g}  {'met' if met else 'NOT met'}")
    print(f"load average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
