"""BVH read/write timings: mocycle against pybvh and bvhio, in one run.

    python benchmarks/io.py [--repeat N] [--data DIR]

Times reading and writing ../shared/data/cmu/01_01.bvh and the largest file in
../shared/data/cmu-iclone with each installed parser (median of N runs after
one warm-up), prints one table and whether the two reading goals are met,
then the ASF/AMC read time of cmu/01.asf + 01_01.amc (mocycle only).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from rich.console import Console
from rich.table import Table

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
READ_GOAL_MS = 100.0
SPEEDUP_GOAL = 5.0


def _mocycle():
    from mocycle.io.bvh import read_bvh, write_bvh

    return read_bvh, write_bvh


def _pybvh():
    import pybvh

    return (lambda p: pybvh.read_bvh_file(p, world_up="+y")), pybvh.write_bvh_file


def _bvhio():
    import bvhio

    # bvhio.writeBvh(path, container, percision=9): path first.
    return bvhio.readAsBvh, (lambda obj, p: bvhio.writeBvh(str(p), obj))


TOOLS: dict[str, Callable] = {"mocycle": _mocycle, "pybvh": _pybvh, "bvhio": _bvhio}


def median_ms(repeat: int, fn: Callable, *args) -> tuple[float, object]:
    """Median ms of ``fn(*args)`` over ``repeat`` runs after one warm-up, and its result."""
    result = fn(*args)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1000.0, result


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="timed runs per measurement (median)")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the shared data folder")
    args = ap.parse_args(argv)
    repeat = max(1, args.repeat)

    cmu = args.data / "cmu" / "01_01.bvh"
    iclone = sorted((args.data / "cmu-iclone").glob("*.bvh"), key=lambda p: p.stat().st_size)
    if not cmu.is_file() or not iclone:
        print(
            f"error: benchmark data not found: need {cmu} and *.bvh files in "
            f"{args.data / 'cmu-iclone'} (clone ../shared beside the repo or pass --data DIR)",
            file=sys.stderr,
        )
        return 2
    files = [cmu, iclone[-1]]

    from mocycle.io.bvh import read_bvh

    table = Table(title=f"BVH read/write, median of {repeat} runs after 1 warm-up")
    for col in ("file", "frames", "joints", "tool", "read ms", "write ms", "mocycle read speed-up"):
        table.add_column(col, justify="left" if col in ("file", "tool") else "right")

    read_ms: dict[tuple[Path, str], float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            motion = read_bvh(path)
            shape = (str(motion.n_frames), str(motion.n_joints))
            label = f"{path.parent.name}/{path.name}"
            rows = {}
            for name, load in TOOLS.items():
                try:
                    reader, writer = load()
                except ImportError:
                    rows[name] = ("not installed", "")
                    continue
                r_ms, obj = median_ms(repeat, reader, str(path))
                w_ms, _ = median_ms(repeat, writer, obj, Path(tmp) / f"{name}_{path.name}")
                read_ms[path, name] = r_ms
                rows[name] = (f"{r_ms:.1f}", f"{w_ms:.1f}")
            for name, (r, w) in rows.items():
                ratio = read_ms.get((path, name), 0) / read_ms[path, "mocycle"]
                table.add_row(label, *shape, name, r, w, f"{ratio:.1f}×" if ratio else "")
            table.add_section()

    console = Console(width=120)
    console.print(table)

    ours = read_ms[cmu, "mocycle"]
    print(
        f"mocycle read {cmu.name}: {ours:.1f} ms (goal < {READ_GOAL_MS:.0f} ms): "
        f"{'met' if ours < READ_GOAL_MS else 'NOT met'}"
    )
    others = [ms for (p, name), ms in read_ms.items() if p == cmu and name != "mocycle"]
    if others:
        speedup = min(others) / ours
        print(
            f"read speed-up vs fastest other parser: {speedup:.1f}× "
            f"(goal >= {SPEEDUP_GOAL:.0f}×): {'met' if speedup >= SPEEDUP_GOAL else 'NOT met'}"
        )
    else:
        print("read speed-up vs fastest other parser: no other parser installed")

    asf, amc = args.data / "cmu" / "01.asf", args.data / "cmu" / "01_01.amc"
    if asf.is_file() and amc.is_file():
        from mocycle.io.asfamc import read_asfamc

        ms, m = median_ms(repeat, read_asfamc, asf, amc)
        print(f"mocycle read {asf.name} + {amc.name} (ASF/AMC, {m.n_frames} frames): {ms:.1f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
