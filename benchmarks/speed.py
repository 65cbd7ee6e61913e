"""Speed goals of issue 15, each as a ratio measured in one run (docs/performance.md).

    PYTHONPATH=$PWD/src python benchmarks/speed.py [--only startup,threads,read,rotation,phase] [--repeat N]
                                                    [--data DIR] [--frames N]

Every comparison runs both sides in the same run, interleaved (A B A B ...), and prints the median with the
min-max of each side, the ratio of the medians and the machine load (os.getloadavg) before and after:

* startup: ``mocycle --help`` against ``python -c "import numpy"`` (goal <= 1.5x) and ``mocycle loop`` of a
  30 fps walk of about 270 frames, whole process, against ``python -c "import numpy,
  scipy.spatial.transform"`` (goal <= 2x).  Wall time is the goal; the processes' CPU time is printed beside
  it because it moves less when other work shares the machine.  mocycle's modules are byte-compiled first, as
  ``pip install`` leaves them (this environment sets PYTHONDONTWRITEBYTECODE; the runs use a temporary
  PYTHONPYCACHEPREFIX).
* threads: the BLAS/OpenMP thread count a ``mocycle`` process runs with (threadpoolctl), and ``mocycle loop``
  with the default one thread against ``MOCYCLE_THREADS=0`` (the libraries' default, one per core).
* read: ``mocycle.read_bvh`` against ``np.loadtxt`` of the same file's numbers (goal <= 1.3x) and against
  pybvh (when installed) on the CMU, iClone and Bandai files; time against frames for a take repeated to
  ``--frames`` frames (goal: linear); peak memory of that read (tracemalloc, in its own process) over the
  float64 channel array (goal <= 4x).
* rotation, phase: ``benchmarks/speed_compute.py`` (when present) prints its own sections.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_DATA = ROOT.parent / "shared" / "data"
SECTIONS = ("startup", "threads", "read", "rotation", "phase")
GOALS = {"help": 1.5, "loop": 2.0, "read": 1.3, "memory": 4.0, "exponent": 1.15}


# ------------------------------------------------------------------ measuring
def load() -> str:
    return "load average " + " / ".join(f"{x:.2f}" for x in os.getloadavg()) + " (1, 5, 15 min)"


def run_process(cmd: list[str], env: dict) -> tuple[float, float]:
    """Wall and CPU seconds (user + system) of one process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if out.returncode != 0:
        raise SystemExit(f"failed ({out.returncode}): {' '.join(cmd)}\n{out.stderr}")
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def interleaved(named: dict, repeat: int) -> dict[str, list]:
    """Run each callable once to warm up, then ``repeat`` rounds of all of them in turn; their results."""
    for fn in named.values():
        fn()
    results: dict[str, list] = {name: [] for name in named}
    for _ in range(repeat):
        for name, fn in named.items():
            results[name].append(fn())
    return results


def summary(values: list[float]) -> str:
    return f"{statistics.median(values):7.3f} s ({min(values):.3f}-{max(values):.3f})"


def verdict(ratio: float, goal: float) -> str:
    return "met" if ratio <= goal else "NOT met"


# ------------------------------------------------------------------ start-up
def mocycle_command() -> list[str]:
    script = Path(sys.executable).with_name("mocycle")
    return [str(script)] if script.exists() else [sys.executable, "-m", "mocycle"]


def walk_take(data: Path, workdir: Path) -> Path:
    """A 30 fps walk of about 270 frames: the Bandai walk closest to 270 frames, else a synthetic one."""
    takes = []
    for path in sorted((data / "bandai").glob("*walk*.bvh")):
        with open(path, errors="replace") as fh:
            frames = next((int(line.split(":")[1]) for line in fh if line.strip().lower().startswith("frames")), 0)
        takes.append((abs(frames - 270), path))
    if takes:
        return min(takes)[1]
    from mocycle.datasets import synthetic_walk
    from mocycle.io import write

    return write(synthetic_walk(n_frames=270, fps=30).motion, workdir / "walk.bvh")


def startup(args, env: dict, workdir: Path) -> None:
    py, mocycle = [sys.executable], mocycle_command()
    walk = walk_take(args.data, workdir)
    out = workdir / "loop.bvh"
    commands = {
        "import numpy": py + ["-c", "import numpy"],
        "mocycle --help": mocycle + ["--help"],
        "import numpy, scipy.spatial.transform": py + ["-c", "import numpy, scipy.spatial.transform"],
        "mocycle loop": mocycle + ["loop", str(walk), "-o", str(out), "--force"],
    }
    runs = interleaved({k: (lambda c=c: run_process(c, env)) for k, c in commands.items()}, args.repeat)
    print(f"\n## Start-up ({args.repeat} interleaved runs; walk: {walk.name})")
    for name, values in runs.items():
        wall, cpu = [v[0] for v in values], [v[1] for v in values]
        print(f"  {name:40s} wall {summary(wall)}   cpu {statistics.median(cpu):.3f} s")
    for goal, (a, b) in {"help": ("mocycle --help", "import numpy"),
                         "loop": ("mocycle loop", "import numpy, scipy.spatial.transform")}.items():
        wall = statistics.median(v[0] for v in runs[a]) / statistics.median(v[0] for v in runs[b])
        cpu = statistics.median(v[1] for v in runs[a]) / statistics.median(v[1] for v in runs[b])
        print(f"  {a} / {b}: {wall:.2f}x wall, {cpu:.2f}x cpu (goal <= {GOALS[goal]}x: "
              f"{verdict(wall, GOALS[goal])})")


# ------------------------------------------------------------------ threads
_POOLS = r"""
import json, sys
sys.argv = ["mocycle"] + json.loads(sys.argv[1])
from mocycle.__main__ import main
try:
    main()
except SystemExit:
    pass
from threadpoolctl import threadpool_info
print("@@" + json.dumps([(p["internal_api"], p["num_threads"]) for p in threadpool_info()]))
"""


def threads(args, env: dict, workdir: Path) -> None:
    walk = walk_take(args.data, workdir)
    clean = {k: v for k, v in env.items() if k not in ("MOCYCLE_THREADS", "OMP_NUM_THREADS",
                                                        "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    print(f"\n## Threads (cores: {os.cpu_count()})")
    for label, extra in (("default", {}), ("MOCYCLE_THREADS=0", {"MOCYCLE_THREADS": "0"})):
        out = subprocess.run([sys.executable, "-c", _POOLS, json.dumps(["info", str(walk)])], capture_output=True,
                             text=True, env={**clean, **extra}, check=True).stdout
        pools = json.loads(out.rsplit("@@", 1)[1])
        print(f"  mocycle info, {label:18s} BLAS/OpenMP threads: "
              + ", ".join(f"{api} {n}" for api, n in pools))
    mocycle = mocycle_command()
    cmd = mocycle + ["loop", str(walk), "-o", str(workdir / "loop.bvh"), "--force"]
    runs = interleaved({"one thread (default)": lambda: run_process(cmd, clean),
                        "MOCYCLE_THREADS=0": lambda: run_process(cmd, {**clean, "MOCYCLE_THREADS": "0"})},
                       args.repeat)
    for name, values in runs.items():
        print(f"  mocycle loop, {name:22s} wall {summary([v[0] for v in values])}")
    a, b = (statistics.median(v[0] for v in runs[k]) for k in runs)
    print(f"  one thread / libraries' default: {a / b:.2f}x wall (goal: one thread by default, no slower)")


# ------------------------------------------------------------------ read
def data_start(path: Path) -> int:
    """Lines before the first frame row (the 'Frame Time:' line is the last of them)."""
    with open(path, "rb") as fh:
        for i, line in enumerate(fh):
            if line.strip().lower().replace(b" ", b"").startswith(b"frametime"):
                return i + 1
    raise SystemExit(f"{path}: no 'Frame Time:' line")


def repeated_take(source: Path, frames: int, target: Path) -> Path:
    """``source`` with its frame rows repeated to ``frames`` rows (a long synthetic take)."""
    lines = source.read_text().replace("\r\n", "\n").split("\n")
    start = data_start(source)
    rows = [line for line in lines[start:] if line.strip()]
    head = [("Frames: " + str(frames)) if line.strip().lower().startswith("frames") else line
            for line in lines[:start]]
    with open(target, "w") as fh:
        fh.write("\n".join(head) + "\n")
        for i in range(frames):
            fh.write(rows[i % len(rows)] + "\n")
    return target


_PEAK = r"""
import sys, tracemalloc
import numpy as np
from mocycle.io.bvh import read_bvh
path, start = sys.argv[1], int(sys.argv[2])
channels = np.loadtxt(path, skiprows=start, comments=None).nbytes
tracemalloc.start()
motion = read_bvh(path)
peak = tracemalloc.get_traced_memory()[1]
print(peak / channels, channels)
"""


def read(args, env: dict, workdir: Path) -> None:
    import numpy as np

    from mocycle.io.bvh import read_bvh

    try:
        import pybvh

        def pybvh_read(p):
            return pybvh.read_bvh_file(p, world_up="+y")
    except ImportError:
        pybvh_read = None
    files = [args.data / "cmu" / "01_01.bvh",
             max((args.data / "cmu-iclone").glob("*.bvh"), key=lambda p: p.stat().st_size, default=None),
             max((args.data / "bandai").glob("*.bvh"), key=lambda p: p.stat().st_size, default=None)]
    files = [f for f in files if f is not None and f.exists()]
    print(f"\n## BVH read ({args.repeat} interleaved runs each)")
    for path in files:
        start = data_start(path)
        tools = {"np.loadtxt": lambda p=path, s=start: timed(np.loadtxt, p, skiprows=s, comments=None),
                 "mocycle": lambda p=path: timed(read_bvh, p)}
        if pybvh_read is not None:
            tools["pybvh"] = lambda p=path: timed(pybvh_read, p)
        runs = interleaved_tolerant(tools, args.repeat)
        shape = np.loadtxt(path, skiprows=start, comments=None).shape
        print(f"  {path.parent.name}/{path.name}: {shape[0]} frames x {shape[1]} channels")
        for name, values in runs.items():
            print(f"    {name:10s} " + (summary(values) if isinstance(values, list) else values))
        ratio = statistics.median(runs["mocycle"]) / statistics.median(runs["np.loadtxt"])
        line = f"    mocycle / np.loadtxt: {ratio:.2f}x (goal <= {GOALS['read']}x: {verdict(ratio, GOALS['read'])})"
        if isinstance(runs.get("pybvh"), list):
            line += f"; pybvh / mocycle: {statistics.median(runs['pybvh']) / statistics.median(runs['mocycle']):.2f}x"
        print(line)
    source = args.data / "cmu" / "01_01.bvh"
    if not source.exists():
        return
    small, big = args.frames // 10, args.frames
    paths = {n: repeated_take(source, n, workdir / f"long{n}.bvh") for n in (small, big)}
    runs = interleaved({n: (lambda p=p: timed(read_bvh, p)) for n, p in paths.items()}, max(2, args.repeat // 3))
    t_small, t_big = statistics.median(runs[small]), statistics.median(runs[big])
    exponent = math.log(t_big / t_small) / math.log(big / small)
    print(f"  {source.name} repeated: {small} frames {summary(runs[small])}, {big} frames {summary(runs[big])}")
    print(f"    time grows as frames^{exponent:.2f} (goal: linear, exponent <= {GOALS['exponent']}: "
          f"{verdict(exponent, GOALS['exponent'])})")
    out = subprocess.run([sys.executable, "-c", _PEAK, str(paths[big]), str(data_start(paths[big]))], env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    peak, channels = float(out[0]), int(out[1])
    print(f"    peak memory of the {big}-frame read: {peak:.2f}x the float64 channel array ({channels / 2**20:.0f} MiB)"
          f" (goal <= {GOALS['memory']}x: {verdict(peak, GOALS['memory'])})")


def timed(fn, *args, **kwargs) -> float:
    t0 = time.perf_counter()
    fn(*args, **kwargs)
    return time.perf_counter() - t0


def interleaved_tolerant(named: dict, repeat: int) -> dict:
    """:func:`interleaved`, but a tool that fails is reported by its error instead of times."""
    working = {}
    failed = {}
    for name, fn in named.items():
        try:
            fn()
            working[name] = fn
        except Exception as exc:  # noqa: BLE001 - a competitor that cannot read the file
            failed[name] = f"cannot read it ({type(exc).__name__}: {str(exc)[:60]})"
    runs: dict = {name: [] for name in working}
    for _ in range(repeat):
        for name, fn in working.items():
            runs[name].append(fn())
    return {**runs, **failed}


# ------------------------------------------------------------------ main
def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default=",".join(SECTIONS), help=f"comma-separated: {', '.join(SECTIONS)}")
    parser.add_argument("--repeat", type=int, default=7, help="interleaved runs of each side (default 7)")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="../shared/data")
    parser.add_argument("--frames", type=int, default=100_000, help="frames of the long synthetic take")
    args = parser.parse_args(argv)
    chosen = [s.strip() for s in args.only.split(",") if s.strip()]
    unknown = sorted(set(chosen) - set(SECTIONS))
    if unknown:
        parser.error(f"--only: unknown section(s) {', '.join(unknown)}; known: {', '.join(SECTIONS)}")
    print(f"benchmarks/speed.py: {', '.join(chosen)}; {load()}; python {sys.version.split()[0]}")
    with tempfile.TemporaryDirectory(prefix="mocycle-speed-") as tmp:
        workdir = Path(tmp)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["PYTHONPYCACHEPREFIX"] = str(workdir / "pycache")
        env.setdefault("PYTHONPATH", str(ROOT / "src"))
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(ROOT / "src" / "mocycle")], env=env,
                       check=True, stdout=subprocess.DEVNULL)
        for name, section in (("startup", startup), ("threads", threads), ("read", read)):
            if name in chosen:
                section(args, env, workdir)
        shutil.rmtree(workdir / "pycache", ignore_errors=True)
    if {"rotation", "phase"} & set(chosen):
        compute = Path(__file__).with_name("speed_compute.py")
        if compute.exists():
            sys.path.insert(0, str(compute.parent))
            import speed_compute

            # only the options speed_compute knows: its sections and the shared data folder
            speed_compute.main(["--only", ",".join(x for x in chosen if x in ("rotation", "phase")),
                                "--data", str(args.data)])
        else:
            print("\n## Rotation maths, Phase at scale: benchmarks/speed_compute.py is not here yet")
    print(f"\n{load()}")


if __name__ == "__main__":
    main()
