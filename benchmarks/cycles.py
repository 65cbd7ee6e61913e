"""Cycle extraction: every method on the walks and runs of ../shared/data, in one table.

    python benchmarks/cycles.py [--quick] [--data DIR]

Methods: harmonic regression M1 (FGLS-weighted), M2 (positions only), M3
(unweighted), all with K = 20 capped by the frames (``"auto"``); the centroid
cycle of paper 001 §4.4; the cut-and-cross-fade baseline.  Every method gets
the same phase (one ``find_phase`` per file) and the same time axis
(``"smooth"``).  Inputs: the Bandai Namco walks and runs (30 fps, 15 styles
each) and the cmu-iclone walks and run 02_01-02_03, 05_01, 07_01-07_12 (60 fps).
``--quick``: the synthetic walk and five real takes.

Per file and method (columns as in the KTH thesis' Tables A.2-B.3, units in
``mocycle.cycle.metrics``): periods found, template error (rad per frame) and
its offset, RMSE of h / h' / h'' (rad, rad/s, rad/s²), jerk of the cycle over
the input's, seam jump in pose and velocity (global median, and local), foot
sliding of the cycle and of the input (units/s), seconds (``extract_cycle``
with its ``find_phase``).  Then the medians per method and the issue's goals.

Speed: the whole ``mocycle loop`` job on a 500-frame 60 fps take (read the
BVH, find the phase, fit, write the BVH), median of 5 in one process; and the
``mocycle loop`` command as a new process (Python start-up and imports
included).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from mocycle.cycle import extract_cycle, loop_metrics
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read, write
from mocycle.phase import find_phase

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
METHODS = (("harmonic", "M1"), ("harmonic", "M2"), ("harmonic", "M3"), ("centroid", None), ("cut", None))
ICLONE = ["02_01", "02_02", "02_03", "05_01"] + [f"07_{i:02d}" for i in range(1, 13)]
QUICK = ["bandai/dataset-1_walk_normal_001.bvh", "bandai/dataset-1_run_normal_001.bvh",
         "bandai/dataset-1_walk_tired_001.bvh", "cmu-iclone/07_01.bvh", "cmu-iclone/02_03.bvh"]
COLUMNS = ("periods", "template", "offset", "rmse_h", "rmse_dh", "rmse_ddh", "jerk", "seam_p", "seam_v",
           "seam_pl", "seam_vl", "slide", "slide_in", "s")


def inputs(data: Path, quick: bool) -> list[tuple[str, object]]:
    takes: list[tuple[str, object]] = [("synthetic walk 500f 1deg", synthetic_walk(n_frames=500, noise_deg=1.0,
                                                                                  seed=3).motion)]
    if not data.is_dir():
        print(f"({data} not found: the real takes are skipped)")
        return takes
    if quick:
        paths = [data / p for p in QUICK]
    else:
        paths = sorted((data / "bandai").glob("dataset-1_walk_*.bvh")) + \
            sorted((data / "bandai").glob("dataset-1_run_*.bvh")) + \
            [data / "cmu-iclone" / f"{n}.bvh" for n in ICLONE]
    return takes + [(f"{p.parent.name}/{p.name.replace('dataset-1_', '')}", p) for p in paths if p.exists()]


def row(motion, phase, method, model) -> dict | str:
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cycle = extract_cycle(motion, method=method, model=model or "M1", phase=phase)
    except MocycleError as exc:
        return str(exc).split(":")[0]
    seconds = time.perf_counter() - t0 + phase.seconds  # the shared find_phase counts for every method
    m = loop_metrics(motion, cycle)
    return {"periods": cycle.n_periods, "template": m["template_error"], "offset": m["template_offset"],
            "rmse_h": m["rmse_h"], "rmse_dh": m["rmse_dh"], "rmse_ddh": m["rmse_ddh"], "jerk": m["jerk_ratio"],
            "seam_p": m["seam_pose"], "seam_v": m["seam_velocity"], "seam_pl": m["seam_pose_local"],
            "seam_vl": m["seam_velocity_local"], "slide": m["foot_sliding"], "slide_in": m["input_foot_sliding"],
            "s": seconds}


def fmt(v) -> str:
    if isinstance(v, (int, np.integer)):
        return f"{v:d}"
    return "nan" if not np.isfinite(v) else (f"{v:.3g}" if abs(v) < 1000 else f"{v:.0f}")


def speed(runs: int = 5) -> None:
    print("\n## speed: the whole mocycle loop job on a 500-frame take at 60 fps (22 joints)")
    with tempfile.TemporaryDirectory() as tmp:
        src = write(synthetic_walk(n_frames=500, noise_deg=1.0, seed=5).motion, Path(tmp) / "walk500.bvh")
        out = Path(tmp) / "cycle.bvh"
        times = []
        for _ in range(runs):
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                write(extract_cycle(read(src)).motion(), out)
            times.append(time.perf_counter() - t0)
        print(f"in one process (read + phase + M1 fit + write), median of {runs}: {statistics.median(times):.3f} s "
              f"(min {min(times):.3f} s; goal < 0.5 s)")
        exe = Path(sys.executable).with_name("mocycle")
        if exe.exists():
            walls = []
            for _ in range(3):
                t0 = time.perf_counter()
                subprocess.run([str(exe), "loop", str(src), "-o", str(out), "--json"], check=True,
                               capture_output=True)
                walls.append(time.perf_counter() - t0)
            print(f"`mocycle loop --json` as a new process (start-up, imports and the metrics included), median "
                  f"of 3: {statistics.median(walls):.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the synthetic walk and five real takes")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    args = parser.parse_args()
    results: dict[str, list[dict]] = {f"{m} {k or ''}".strip(): [] for m, k in METHODS}
    per_file: dict[str, dict[str, dict]] = {}
    head = f"{'file':32s} {'method':11s} " + " ".join(f"{c:>8s}" for c in COLUMNS)
    print("## every method on every take (template error and RMSE h in rad, h' rad/s, h'' rad/s^2, slide units/s)")
    print(head)
    for name, source in inputs(args.data, args.quick):
        motion = read(source) if isinstance(source, Path) else source
        phase = find_phase(motion)
        per_file[name] = {}
        for method, model in METHODS:
            label = f"{method} {model or ''}".strip()
            r = row(motion, phase, method, model)
            if isinstance(r, str):
                print(f"{name[:32]:32s} {label:11s} {r}")
                continue
            results[label].append(r)
            per_file[name][label] = r
            print(f"{name[:32]:32s} {label:11s} " + " ".join(f"{fmt(r[c]):>8s}" for c in COLUMNS))
        sys.stdout.flush()

    print("\n## median per method")
    print(f"{'method':11s} {'files':>5s} " + " ".join(f"{c:>8s}" for c in COLUMNS if c != "offset"))
    for label, rows in results.items():
        if rows:
            print(f"{label:11s} {len(rows):5d} " + " ".join(
                f"{fmt(float(np.median([r[c] for r in rows]))):>8s}" for c in COLUMNS if c != "offset"))

    print("\n## goals")
    m1 = {f: r["harmonic M1"] for f, r in per_file.items() if "harmonic M1" in r}
    bad = [f for f, r in m1.items() if not (r["seam_p"] <= 1.0 and r["seam_v"] <= 1.0)]
    misses = ", ".join(f"{f} ({m1[f]['seam_p']:.2f}, {m1[f]['seam_v']:.2f})" for f in bad)
    print(f"harmonic M1 seam jump <= 1.0 in pose and velocity: {len(m1) - len(bad)}/{len(m1)} files"
          + (f"; not on: {misses}" if bad else ""))
    bad_local = [f for f, r in m1.items() if not (r["seam_pl"] <= 1.5 and r["seam_vl"] <= 1.5)]
    print(f"harmonic M1 local seam ratios <= 1.5 (no pop next to the wrap): {len(m1) - len(bad_local)}/{len(m1)}")
    both = [f for f, r in per_file.items() if "harmonic M1" in r and "harmonic M2" in r]
    ratio = [per_file[f]["harmonic M1"]["template"] / per_file[f]["harmonic M2"]["template"] for f in both]
    within = sum(r <= 1.05 for r in ratio)
    print(f"M1 template error within 5% of M2: {within}/{len(ratio)} files (median M1/M2 {np.median(ratio):.3f}, "
          f"worst {max(ratio):.3f})")
    for other in ("harmonic M2", "centroid"):
        files = [f for f in both if other in per_file[f]]
        closer = sum(abs(np.log(per_file[f]["harmonic M1"]["jerk"])) < abs(np.log(per_file[f][other]["jerk"]))
                     for f in files)
        lower = sum(per_file[f]["harmonic M1"]["jerk"] < per_file[f][other]["jerk"] for f in files)
        print(f"M1 jerk closer to the input's than {other}'s (|log jerk ratio|): {closer}/{len(files)} files; "
              f"M1 jerk lower than {other}'s: {lower}/{len(files)}")
    speed()


if __name__ == "__main__":
    main()
