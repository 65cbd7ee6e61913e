"""Reading and writing at the scale of a capture day: an hour of 120 fps capture, side by side in one run.

    PYTHONPATH=$PWD/src python benchmarks/session_io.py [--only build,parsers,outputs,json,resample]
        [--repeat 3] [--workdir /tmp/mocycle-session-io] [--baseline REV] [--data ../shared/data]

Sections:

* ``build``: the files.  An hour at 120 fps on the 22-joint Bandai rig: Bandai dataset-2 and dataset-1 takes
  joined end to end (``mocycle.datasets.join_takes``) to 108,000 frames at 30 fps, then ``Motion.resample(120)``
  (431,997 frames, 132 channels); the 31-joint CMU rig: cmu/01_01 joined to 432,000 frames at 120 fps (96
  channels); a 300-frame take (the hour's first 300 frames at 30 fps).  Without the shared data, synthetic
  takes (``mocycle.datasets``) are joined instead.  Written once into ``--workdir``, reused after.
* ``parsers``: the frame rows of each file parsed by ``np.loadtxt``, pyarrow.csv (one thread and its default),
  pandas' C engine, polars (one thread and its default), ``np.fromstring(sep=" ")`` and ``bytes.split`` +
  ``float``, and the whole ``read_bvh`` of this tree (with polars, and without: ``np.loadtxt``) and of
  ``--baseline`` (default ``main``).  Every measurement runs in a fresh process (thread counts are set before
  the libraries load; numpy's huge-page advice off, as the command line runs, unless ``NUMPY_MADVISE_HUGEPAGE``
  is set), the parsers interleaved, ``--repeat`` rounds; the first round checks that every array
  is bit for bit ``np.loadtxt``'s and every ``read_bvh`` motion of this tree bit for bit its ``np.loadtxt``
  path's (the baseline's: "its own" when its Euler conversion differs in the last bits).  Prints wall and
  CPU seconds (min and median) and ``read_bvh`` over the fastest parser, one-thread and any-thread.
* ``outputs``: 558 and 5,000 small files written with ``io.atomic.atomic_write`` into one folder: the
  folder's leftovers listed once per process (now) against listed at every write (as before).
* ``json``: a 558-part report (a real ``loop`` report's facts, 558 times) as ``json_text`` writes it, against
  what it did before (the facts walked in Python, then ``json.dumps(indent=2)``'s pure-Python encoder).
* ``resample``: the 30 fps hour resampled to 120 fps: the frame count and the seconds.

Needs pyarrow, pandas and polars for the parser comparison (``pip install pyarrow pandas polars``); a parser
that is missing is listed as such.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_DATA = ROOT.parent / "shared" / "data"
HOUR_30 = 108_000  # frames of an hour at 30 fps

# --------------------------------------------------------------------------------------------- build


def build(args) -> dict[str, Path]:
    """The three files (made once into the work folder)."""
    work = args.workdir
    work.mkdir(parents=True, exist_ok=True)
    files = {"300 frames (22 joints)": work / "take300.bvh", "hour 22 joints": work / "hour22.bvh",
             "hour 31 joints": work / "hour31.bvh", "hour 30 fps": work / "hour22_30fps.bvh"}
    if all(p.is_file() for p in files.values()):
        return files
    from mocycle.datasets import join_takes
    from mocycle.io import read_bvh, write_bvh

    bandai = sorted((args.data / "bandai2").glob("*.bvh")) + sorted((args.data / "bandai").glob("*.bvh"))
    cmu = args.data / "cmu" / "01_01.bvh"
    if bandai and cmu.is_file():
        takes = [read_bvh(p) for p in bandai]
        # Bandai takes share their joints; their rest offsets differ, and every joint's position channels
        # override them: one skeleton for all
        takes22 = [t.replace(skeleton=takes[0].skeleton) for t in takes if t.n_frames > 20]
        takes31 = [read_bvh(cmu)]
        source = "shared data (bandai2 + bandai takes; cmu/01_01)"
    else:
        from mocycle.datasets import synthetic_run, synthetic_walk, synthetic_wave

        takes22 = [synthetic_walk(n_frames=600, fps=30, seed=1).motion, synthetic_run(n_frames=400, fps=30).motion,
                   synthetic_wave(n_frames=360, fps=30).motion]
        takes31 = [synthetic_walk(n_frames=2400, fps=120, seed=2).motion]
        source = f"synthetic takes ({args.data} not found)"
    print(f"building the files from {source} into {work}", flush=True)

    def joined(takes, frames):
        chosen, total = [], 0
        for take in itertools.cycle(takes):
            chosen.append(take)
            total += take.n_frames - 10
            if total >= frames + 20:
                break
        return join_takes(chosen, [str(k) for k in range(len(chosen))]).motion[:frames]

    t0 = time.perf_counter()
    hour30 = joined(takes22, HOUR_30)
    write_bvh(hour30, files["hour 30 fps"])
    write_bvh(hour30[:300], files["300 frames (22 joints)"])
    write_bvh(hour30.resample(120), files["hour 22 joints"])
    del hour30
    hour31 = joined(takes31, 4 * HOUR_30)
    write_bvh(hour31, files["hour 31 joints"])
    del hour31
    for name, p in files.items():
        print(f"  {name}: {p.stat().st_size / 1e6:,.0f} MB", flush=True)
    print(f"  built in {time.perf_counter() - t0:.0f} s", flush=True)
    return files


# --------------------------------------------------------------------------------------------- parsers

# Each runs in a child process: ``python session_io.py --child NAME PATH`` prints {"wall", "cpu", "digest"}.
PARSERS = {  # name: (environment, what it is)
    "np.loadtxt": ({}, "numpy's C loadtxt"),
    "pyarrow 1 thread": ({}, "pyarrow.csv.read_csv(use_threads=False), columns copied into one array"),
    "pyarrow": ({}, "pyarrow.csv.read_csv, its default threads"),
    "pandas C": ({}, "pandas.read_csv(engine='c', sep=' ')"),
    "polars 1 thread": ({"POLARS_MAX_THREADS": "1"}, "polars.read_csv, one thread"),
    "polars": ({"POLARS_MAX_THREADS": ""}, "polars.read_csv, its default threads"),
    "np.fromstring": ({}, "np.fromstring(text, sep=' ')"),
    "split + float": ({}, "np.array(bytes.split(), dtype=float)"),
    "read_bvh": ({"POLARS_MAX_THREADS": "1"}, "this tree's read_bvh as the command line runs it: one polars "
                                              "thread in each of its helper threads"),
    "read_bvh any threads": ({"POLARS_MAX_THREADS": ""}, "this tree's read_bvh, polars' default threads"),
    "read_bvh no polars": ({}, "this tree's read_bvh without polars (np.loadtxt)"),
    "read_bvh baseline": ({}, "the baseline's read_bvh"),
}
READERS = ("read_bvh", "read_bvh any threads", "read_bvh no polars", "read_bvh baseline")
ONE_THREAD = ("np.loadtxt", "pyarrow 1 thread", "pandas C", "polars 1 thread", "np.fromstring", "split + float")


def _data_start(path: Path) -> tuple[int, int, int]:
    """(lines, bytes) of the header and the channel count of the first row."""
    lines = size = 0
    with open(path, "rb") as fh:
        for raw in fh:
            lines += 1
            size += len(raw)
            if raw.strip().lower().replace(b" ", b"").replace(b"\t", b"").startswith(b"frametime"):
                return lines, size, len(fh.readline().split())
    raise SystemExit(f"{path}: no Frame Time line")


def _parse(name: str, path: Path):
    """The array (or motion) ``name`` makes of ``path``, and the wall and CPU seconds of making it."""
    import numpy as np

    lines, offset, n = _data_start(path)
    if name.startswith("read_bvh"):
        import mocycle.io.bvh as bvh

        if name == "read_bvh no polars":
            bvh.bvh_rows.wanted = lambda n_bytes: False
        else:  # this tree's and the baseline's alike: a process with polars loaded takes a little longer
            import polars  # noqa: F401  (imported before the clock starts, like the parsers' libraries)
        t0, c0 = time.perf_counter(), time.process_time()
        result = bvh.read_bvh(path)
    elif name.startswith("pyarrow"):
        import pyarrow as pa
        import pyarrow.csv as pc

        t0, c0 = time.perf_counter(), time.process_time()
        with open(path, "rb") as fh:
            fh.seek(offset)
            table = pc.read_csv(fh, read_options=pc.ReadOptions(autogenerate_column_names=True,
                                                                use_threads=name == "pyarrow"),
                                parse_options=pc.ParseOptions(delimiter=" ", quote_char=False),
                                convert_options=pc.ConvertOptions(column_types={f"f{i}": pa.float64()
                                                                                for i in range(n)}))
        result = np.empty((table.num_rows, n))
        for c, column in enumerate(table.columns):
            result[:, c] = column.to_numpy()
    elif name == "pandas C":
        import pandas as pd

        t0, c0 = time.perf_counter(), time.process_time()
        with open(path, "rb") as fh:
            fh.seek(offset)
            result = pd.read_csv(fh, sep=" ", header=None, dtype=np.float64, engine="c").to_numpy()
    elif name.startswith("polars"):
        import polars as pl

        t0, c0 = time.perf_counter(), time.process_time()
        with open(path, "rb") as fh:
            fh.seek(offset)
            data = fh.read()
        result = pl.read_csv(data, has_header=False, separator=" ", quote_char=None,
                             schema={f"c{i}": pl.Float64 for i in range(n)}).to_numpy()
    else:
        t0, c0 = time.perf_counter(), time.process_time()
        if name == "np.loadtxt":
            result = np.loadtxt(path, dtype=np.float64, ndmin=2, comments=None, skiprows=lines, encoding="latin-1")
        else:
            with open(path, "rb") as fh:
                fh.seek(offset)
                data = fh.read()
            if name == "np.fromstring":
                result = np.fromstring(data, sep=" ").reshape(-1, n)
            else:
                result = np.array(data.split(), dtype=np.float64).reshape(-1, n)
    return result, time.perf_counter() - t0, time.process_time() - c0


def _digest(result) -> str:
    h = hashlib.sha1()
    if hasattr(result, "rotations"):
        for array in (result.rotations, result.translations_at(0)):
            h.update(array.tobytes())
        for j in result.tracked_joints:
            h.update(result.joint_translations(j).tobytes())
    else:
        import numpy as np

        h.update(np.ascontiguousarray(result).tobytes())
    return h.hexdigest()[:12]


def child(name: str, path: str, digest: bool) -> None:
    try:
        result, wall, cpu = _parse(name, Path(path))
    except ImportError as exc:
        print(json.dumps({"missing": str(exc)}))
        return
    print(json.dumps({"wall": wall, "cpu": cpu, "digest": _digest(result) if digest else None}))


def _baseline_tree(rev: str, work: Path) -> Path:
    """The baseline's ``src`` unpacked with ``git archive`` (once per revision)."""
    sha = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", rev], capture_output=True, text=True,
                         check=True).stdout.strip()
    target = work / f"baseline-{sha}"
    if not (target / "src" / "mocycle").is_dir():
        target.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", sha, "src"], capture_output=True,
                                 check=True).stdout
        with tempfile.TemporaryFile() as fh:
            fh.write(archive)
            fh.seek(0)
            with tarfile.open(fileobj=fh) as tar:
                tar.extractall(target, filter="data")
    return target / "src"


def _run_child(name: str, path: Path, baseline_src: Path, digest: bool) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "POLARS_MAX_THREADS"}
    # every child without numpy's huge-page advice, as the command line runs (mocycle.threads): on a machine
    # that cannot give huge pages it triples the first touch of every large array, the parsers' included
    env.setdefault("NUMPY_MADVISE_HUGEPAGE", "0")
    extra, _ = PARSERS[name]
    env.update({k: v for k, v in extra.items() if v})
    src = baseline_src if name == "read_bvh baseline" else ROOT / "src"
    env["PYTHONPATH"] = os.pathsep.join([str(src), env.get("PYTHONPATH", "")])
    out = subprocess.run([sys.executable, __file__, "--child", name, str(path)] + (["--digest"] if digest else []),
                         capture_output=True, text=True, env=env, cwd=str(ROOT.parent))
    if out.returncode:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def parsers(args, files: dict[str, Path]) -> None:
    baseline_src = _baseline_tree(args.baseline, args.workdir)
    names = [n for n in PARSERS if not args.parsers or n in args.parsers]
    print(f"\n## BVH frame rows: every parser in a fresh process, interleaved, {args.repeat} rounds "
          f"(load {os.getloadavg()[0]:.1f}; baseline {args.baseline}; NUMPY_MADVISE_HUGEPAGE="
          f"{os.environ.get('NUMPY_MADVISE_HUGEPAGE', '0')})", flush=True)
    for label, path in files.items():
        if label == "hour 30 fps":
            continue
        runs: dict[str, list] = {n: [] for n in names}
        digests, missing = {}, {}
        small = label.startswith("300")
        # a small file's read is milliseconds: five times the rounds, so a tenth of a millisecond shows
        for r in range(args.repeat * (5 if small else 1)):
            for name in names:
                if name in missing:
                    continue
                got = _run_child(name, path, baseline_src, digest=r == 0)
                if "missing" in got or "error" in got:
                    missing[name] = got.get("missing") or got.get("error")
                    continue
                runs[name].append((got["wall"], got["cpu"]))
                if r == 0:
                    digests[name] = got["digest"]
        _, _, n = _data_start(path)
        print(f"\n{label}: {path.name}, {path.stat().st_size / 1e6:,.1f} MB, {n} channels")
        print("| parser | wall s min | wall s median | CPU s min | CPU s median | same bits |")
        print("|---|---:|---:|---:|---:|---|")
        # arrays against np.loadtxt's; this tree's motions against its own np.loadtxt path (the baseline's
        # against itself: its Euler conversion may differ in the last bits, as 6e69423's did)
        want = {"array": digests.get("np.loadtxt"), "motion": digests.get("read_bvh no polars")}
        for name in names:
            if name in missing:
                print(f"| {name} | {missing[name][:60]} | | | | |")
                continue
            wall, cpu = [w for w, _ in runs[name]], [c for _, c in runs[name]]
            same = digests.get(name) == want["motion" if name in READERS else "array"]
            mark = "yes" if same else "its own" if name == "read_bvh baseline" else "NO"
            d = 4 if small else 3
            print(f"| {name} | {min(wall):.{d}f} | {statistics.median(wall):.{d}f} | {min(cpu):.{d}f} | "
                  f"{statistics.median(cpu):.{d}f} | {mark} |")
        medians = {name: statistics.median(w for w, _ in runs[name]) for name in names if runs[name]}
        # the goal: read_bvh (which parses and converts on every core it may use) within 1.3x the fastest
        # parser with any threads; the fastest one-thread parser for reference
        for reader, pool, what in (("read_bvh", ONE_THREAD, "one-thread parser"),
                                   ("read_bvh", [n for n in medians if n not in READERS], "parser, any threads"),
                                   ("read_bvh any threads", [n for n in medians if n not in READERS],
                                    "parser, any threads")):
            present = [n for n in pool if n in medians]
            if small or not present or reader not in medians:
                continue
            fastest = min(present, key=medians.get)
            ratio = medians[reader] / medians[fastest]
            goal = f"; goal <= 1.3x: {'met' if ratio <= 1.3 else 'NOT met'}" if "any" in what else ""
            print(f"{reader} / fastest {what} ({fastest}): {ratio:.2f}x (median wall{goal})")
        if "read_bvh baseline" in medians and "read_bvh" in medians:
            base = medians["read_bvh baseline"]
            ratio = medians["read_bvh"] / base
            print(f"read_bvh / baseline read_bvh: {ratio:.2f}x"
                  + (f" (goal <= 1: {'met' if ratio <= 1 else 'NOT met'})" if small else "")
                  + f"; without polars: {medians.get('read_bvh no polars', float('nan')) / base:.2f}x")


# --------------------------------------------------------------------------------------------- outputs


def outputs(args) -> None:
    from mocycle.io import atomic

    print("\n## Writing many outputs into one folder (io.atomic.atomic_write, 2 kB each)", flush=True)
    print("| outputs | listed once (now) s | listed at every write (before) s | before / now |")
    print("|---:|---:|---:|---:|")
    text = "x" * 2048
    for n in (558, 5000):
        times = {"now": [], "before": []}
        for _ in range(args.repeat):
            for mode in ("now", "before"):
                with tempfile.TemporaryDirectory(dir=args.workdir) as tmp:
                    atomic._leftovers.clear()
                    t0 = time.perf_counter()
                    for k in range(n):
                        if mode == "before":
                            atomic._leftovers.clear()  # as before: the folder listed at every write
                        atomic.atomic_write(Path(tmp) / f"take{k:05d}.loop.bvh", text)
                    times[mode].append(time.perf_counter() - t0)
        now, before = statistics.median(times["now"]), statistics.median(times["before"])
        print(f"| {n:,} | {now:.3f} | {before:.3f} | {before / now:.1f}x |", flush=True)


# --------------------------------------------------------------------------------------------- json


def _report_facts() -> dict:
    """A 558-part report: the facts of a real ``loop`` report on a synthetic walk, one per part."""
    from mocycle.datasets import synthetic_walk
    from mocycle.tasks import loop

    report = loop.run(synthetic_walk(n_frames=480, fps=60, seed=1).motion)
    part = dict(report.facts)
    return {"file": "session.bvh", "frames": 431_997, "parts": [dict(part, part=k) for k in range(558)]}


def json_section(args) -> None:
    from mocycle.text import _cleaned, json_text

    facts = _report_facts()
    before = json.dumps(_cleaned(facts), indent=2, allow_nan=False)
    assert json_text(facts) == before, "json_text changed the text"
    times = {"now": [], "before": []}
    for _ in range(max(args.repeat, 5)):
        t0 = time.perf_counter()
        json_text(facts)
        times["now"].append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        json.dumps(_cleaned(facts), indent=2, allow_nan=False)
        times["before"].append(time.perf_counter() - t0)
    now, old = statistics.median(times["now"]), statistics.median(times["before"])
    print(f"\n## JSON of a 558-part report ({len(before) / 1e6:.2f} MB, indent 2, the same text)")
    print(f"json_text: {now:.3f} s (min {min(times['now']):.3f}); before (Python walk + json.dumps' "
          f"pure-Python encoder): {old:.3f} s (min {min(times['before']):.3f}); {old / now:.1f}x")


# --------------------------------------------------------------------------------------------- resample


def resample(args, files) -> None:
    from mocycle.io import read_bvh

    m = read_bvh(files["hour 30 fps"])
    t0 = time.perf_counter()
    up = m.resample(120)
    dt = time.perf_counter() - t0
    print(f"\n## Resampling the hour: {m.n_frames:,} frames at {m.frame_time!r} s to 120 fps: {up.n_frames:,} "
          f"frames (expected {(m.n_frames - 1) * 4 + 1:,}) in {dt:.1f} s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="build,parsers,outputs,json,resample")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workdir", type=Path, default=Path(tempfile.gettempdir()) / "mocycle-session-io")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--baseline", default="main", help="git revision whose read_bvh is timed beside")
    ap.add_argument("--parsers", default="", help="comma-separated subset of the parsers (default: all)")
    ap.add_argument("--files", default="", help="comma-separated subset of the files: small,22,31")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    ap.add_argument("--digest", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(*args.child, args.digest)
        return 0
    args.parsers = [p.strip() for p in args.parsers.split(",") if p.strip()]
    only = set(args.only.split(","))
    files = build(args)
    if args.files:
        keys = {"small": "300 frames (22 joints)", "22": "hour 22 joints", "31": "hour 31 joints"}
        files = {keys[k]: files[keys[k]] for k in args.files.split(",")} | {"hour 30 fps": files["hour 30 fps"]}
    if "parsers" in only:
        parsers(args, files)
    if "outputs" in only:
        outputs(args)
    if "json" in only:
        json_section(args)
    if "resample" in only:
        resample(args, files)
    return 0


if __name__ == "__main__":
    sys.exit(main())
