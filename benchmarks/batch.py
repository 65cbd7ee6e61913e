"""Throughput of ``mocycle batch loop`` (issue 16) against one process per take and against the bare compute.

    python benchmarks/batch.py [--data DIR] [--takes N] [--workers N] [--repeat K] [--rounds R] [--no-shell]

Over the Bandai Namco takes of ../shared/data/bandai (all of them, or the first N), three ways, in one run:

* **shell loop**: ``for f in ...; do mocycle loop "$f" -o OUT; done`` in bash, one process per take (what a
  user does today): per-take time = wall / takes;
* **batch**: ``mocycle batch loop DIR -o OUT`` (LocalCluster, one single-threaded worker per core), the whole
  command from start to exit: per-take time = wall / takes;
* **in-process**: ``mocycle.tasks.loop.run`` on every take in this process, BLAS on one thread, after one
  warm-up take: per-take time = the sum of the wall times / takes (one core).

``--repeat K`` makes the library of batch and in-process K copies of the takes (a library of 3000 takes
is what the issue has in mind: the start-up of the cluster is shared by more takes); the shell loop runs
each take once (one process per take costs the same whatever the library's size).

``--rounds R`` runs in-process and batch R times in turn (which one goes first alternates) and prints each
round's ratio and the medians: on a shared machine the load moves between the parts of one round.

Goals: batch <= 0.5x the shell loop, and within 1.3x of the in-process time. The machine's load average is
printed before each part (other jobs share the cores; the ratios are measured in the same run). Because wall
times on a shared machine swing with the others' load, the CPU seconds of each way are printed too (this
process for in-process; the child processes and all their workers, from ``getrusage``, for the others):
their ratios say what the wall ratios would be on a machine of our own, up to the parallel speed-up of the
batch's workers. Exit 0 either way: a benchmark, not a test.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

from threadpoolctl import threadpool_info, threadpool_limits

HERE = Path(__file__).resolve().parent
DATA = HERE.parent.parent / "shared" / "data" / "bandai"


def load() -> str:
    return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg()) + f" on {os.cpu_count()} cores"


def mocycle_command() -> list[str]:
    return [sys.executable, "-m", "mocycle"]


def children_cpu() -> float:
    """CPU seconds (user + system) of the finished child processes and their own children."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def shell_loop(files: list[Path], out: Path) -> tuple[float, int]:
    """Wall seconds of the bash loop, and how many of its takes wrote a loop."""
    out.mkdir(parents=True, exist_ok=True)
    cmd = " ".join(map(shlex.quote, mocycle_command()))
    script = "".join(f"{cmd} loop {shlex.quote(str(f))} -o {shlex.quote(str(out / f.name))} >/dev/null 2>&1; "
                     for f in files)
    t0 = time.perf_counter()
    subprocess.run(["bash", "-c", script], check=False)
    return time.perf_counter() - t0, len(list(out.glob("*.bvh")))


def batch(folder: Path, out: Path, workers: int | None) -> tuple[float, str]:
    args = [*mocycle_command(), "batch", "loop", str(folder), "-o", str(out), "--json"]
    args += ["--workers", str(workers)] if workers else []
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"mocycle batch failed ({r.returncode}): {r.stderr.strip()}")
    return wall, r.stdout


def in_process(files: list[Path]) -> tuple[float, dict]:
    from mocycle import tasks
    from mocycle.batch.take import status_of
    from mocycle.errors import MocycleError

    options = tasks.loop.Options()
    statuses: dict[str, object] = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            tasks.loop.run(files[0], options)  # warm-up: imports, first calls (loads every BLAS/OpenMP)
        except MocycleError:
            pass
    # limited after the warm-up: threadpool_limits pins only the libraries loaded when it is called
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pools = sorted({(p["internal_api"], p["num_threads"]) for p in threadpool_info()})
        statuses["threads"] = pools
        total, cpu0 = 0.0, time.process_time()
        for f in files:
            t0 = time.perf_counter()
            try:
                tasks.loop.run(f, options)
                status = "ok"
            except MocycleError as exc:
                status = status_of(exc)
            total += time.perf_counter() - t0
            statuses[status] = statuses.get(status, 0) + 1
    return total, time.process_time() - cpu0, statuses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=DATA, help="folder of .bvh takes (default: the Bandai set)")
    parser.add_argument("--takes", type=int, default=None, help="only the first N takes")
    parser.add_argument("--workers", type=int, default=None, help="batch workers (default: one per core)")
    parser.add_argument("--repeat", type=int, default=1, help="batch and in-process: K copies of every take")
    parser.add_argument("--rounds", type=int, default=1, help="in-process and batch this many times in turn "
                                                                 "(the ratios of each round, and their median)")
    parser.add_argument("--no-shell", action="store_true", help="leave out the shell loop (minutes of one "
                                                                  "process per take)")
    args = parser.parse_args()
    files = sorted(args.data.glob("*.bvh"))[: args.takes]
    if not files:
        raise SystemExit(f"no .bvh files in {args.data} (the shared data is not here)")
    n_shell = len(files)
    n = n_shell * args.repeat
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        folder = tmp / "in"
        library = []
        for k in range(args.repeat):  # the batch reads exactly these takes
            (folder / f"copy{k}").mkdir(parents=True)
            for f in files:
                library.append(folder / f"copy{k}" / f.name)
                library[-1].symlink_to(f.resolve())
        print(f"{n_shell} takes from {args.data}" + (f", {args.repeat} copies of each for batch and in-process"
                                                     if args.repeat > 1 else "") + "; mocycle loop, default options")
        rounds = []
        for r in range(args.rounds):  # in-process and batch in turn, the first of the two alternating
            parts = {}
            for part in (("in-process", "batch") if r % 2 == 0 else ("batch", "in-process")):
                print(f"{part:<11} ({load()})" + (f" round {r + 1}" if args.rounds > 1 else ""), flush=True)
                if part == "in-process":
                    compute, cpu_in, statuses = in_process(library)
                    parts[part] = compute, cpu_in
                    print(f"  {compute:.2f} s, {compute / n:.3f} s per take (CPU {cpu_in / n:.3f} s); "
                          f"statuses {statuses}")
                else:
                    c0 = children_cpu()
                    wall_batch, summary = batch(folder, tmp / f"batch{r}", args.workers)
                    cpu_batch = children_cpu() - c0
                    parts[part] = wall_batch, cpu_batch
                    s = json.loads(summary)
                    print(f"  {wall_batch:.2f} s, {wall_batch / n:.3f} s per take (CPU {cpu_batch / n:.3f} s); "
                          f"{s['workers']} workers ({s['worker_start']}); ok {s['ok']}, no periodic motion "
                          f"{s['no-periodic-motion']}, refused {s['refused']}, error {s['error']}; "
                          f"{s['task_seconds']:.2f} s in the tasks")
            rounds.append((*parts["in-process"], *parts["batch"]))
        if not args.no_shell:
            print(f"shell loop  ({load()})", flush=True)
            c0 = children_cpu()
            wall_shell, written = shell_loop(files, tmp / "shell")
            cpu_shell = children_cpu() - c0
            print(f"  {wall_shell:.2f} s, {wall_shell / n_shell:.3f} s per take (CPU {cpu_shell / n_shell:.3f} s); "
                  f"{written} loops written")
    print(f"after       ({load()})")
    wall_ratios = [wall_batch / compute for compute, _, wall_batch, _ in rounds]
    cpu_ratios = [cpu_batch / cpu_in for _, cpu_in, _, cpu_batch in rounds]
    wall_batch = statistics.median(w for _, _, w, _ in rounds)
    cpu_batch = statistics.median(c for _, _, _, c in rounds)
    if not args.no_shell:
        print(f"batch / shell loop: {wall_batch / n / (wall_shell / n_shell):.2f}x wall per take (goal <= 0.5x), "
              f"{cpu_batch / n / (cpu_shell / n_shell):.2f}x CPU")
    if len(rounds) > 1:
        print("batch / in-process by round: " + ", ".join(f"{w:.2f}x" for w in wall_ratios) + " wall; "
              + ", ".join(f"{c:.2f}x" for c in cpu_ratios) + " CPU")
    print(f"batch / in-process: {statistics.median(wall_ratios):.2f}x wall per take (goal <= 1.3x), "
          f"{statistics.median(cpu_ratios):.2f}x CPU" + (f" (medians of {len(rounds)} rounds)" if len(rounds) > 1
                                                          else ""))


if __name__ == "__main__":
    main()
