"""Cycle extraction on the walks, runs and dashes of ../shared/data: can the loops be trusted, and every method.

    python benchmarks/cycles.py [--quick] [--data DIR] [--only trust|methods]

**Trust** (issue 11), the ``mocycle loop`` defaults (harmonic M1, the library's loop checks) on every
Bandai walk, run and dash (45 takes) and the cmu-iclone walks and run: per take the cycle length against
the legs' own autocorrelation period (paper 004 eq. 1 on the legs' rotations: the gait period), the turn
per cycle against the take's turn rate (its heading trend's slope times the period), the root's height
change over 3 cycles of ``--root motion`` (% of the body height), and whether the take was refused and
why.  Then the goal lines: cycle within 5 % of the gait period; turn within max(10°, 25 %); height creep
under 1 % of the body height over 3 cycles; no exit-0 cycle longer than the take or fitting worse than
twice the best plain cut (:mod:`mocycle.cycle.checks`).

**Methods**:

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
from mocycle.cycle.checks import MAX_FIT_RATIO, best_cut_error, loop_checks
from mocycle.cycle.representation import vertical_axis
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError, NoPeriodicMotion
from mocycle.features import pose_matrix
from mocycle.io import read, write
from mocycle.phase import find_phase
from mocycle.phase.period import autocorrelation_period

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


# ------------------------------------------------------------------------------------------------ trust (issue 11)
TRUST_QUICK = QUICK + ["bandai/dataset-1_dash_happy_001.bvh", "bandai/dataset-1_run_chimpira_001.bvh"]
PERIOD_GOAL = 0.05      # cycle within 5 % of the gait period
TURN_GOAL = (10.0, 0.25)  # turn per cycle within max(10 degrees, 25 %) of the take's
CREEP_GOAL = 1.0        # % of the body height over 3 cycles


def trust_inputs(data: Path, quick: bool) -> list[Path]:
    if not data.is_dir():
        return []
    if quick:
        return [data / p for p in TRUST_QUICK if (data / p).exists()]
    bandai = sorted((data / "bandai").glob("dataset-1_*.bvh"))
    return bandai + [data / "cmu-iclone" / f"{n}.bvh" for n in ICLONE if (data / "cmu-iclone" / f"{n}.bvh").exists()]


def gait_period(motion) -> float:
    """The legs' own period (frames): windowed circular autocorrelation of the legs' rotations, lags >= 0.25 s."""
    X, _ = pose_matrix(motion, rep="quatlog", root_features="drop", joints="legs")
    if X.shape[0] < 8:
        return float("nan")
    return autocorrelation_period(X, min_lag=max(2, int(round(0.25 / motion.frame_time))))


def trust_row(motion) -> dict:
    """One take through the ``mocycle loop`` defaults: the issue-11 figures, refused or not and why."""
    row = {"frames": motion.n_frames, "gait": gait_period(motion)}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cycle = extract_cycle(motion)
    except NoPeriodicMotion as exc:
        return row | {"refused": str(exc), "why": "no periodic motion"}
    except MocycleError as exc:
        return row | {"refused": str(exc), "why": "error"}
    metrics = loop_metrics(motion, cycle)
    failed = loop_checks(motion, cycle, metrics)
    up = vertical_axis(motion)
    W = motion[:: max(1, motion.n_frames // 50)].world_positions(end_sites=True) @ up
    body = float(np.median(np.ptp(W, axis=1)))
    N = cycle.n_frames
    height = cycle.repeat(4, root="motion").world_positions()[:, cycle.space.travel] @ up
    space = cycle.space
    psi = space.heading_trend(space.heading(motion.rotation_matrices()[:, space.travel]), cycle.period_frames)
    rate = np.polyfit(np.arange(motion.n_frames), psi, 1)[0] if motion.n_frames > 1 else 0.0
    cut, _ = best_cut_error(motion, cycle)
    row |= {"cycle": N, "period": cycle.period_frames, "periods": cycle.n_periods,
            "turn": float(np.degrees(cycle.drift[3])), "take_turn": float(np.degrees(rate * cycle.period_frames)),
            "creep": float(100 * (height[3 * N] - height[0]) / body), "template": metrics["template_error"],
            "cut": cut, "seam": max(metrics["seam_pose_local"], metrics["seam_velocity_local"]),
            "refused": "; ".join(f"{f.name}: {f.reason}" for f in failed), "why": ", ".join(f.name for f in failed)}
    return row


def trust(data: Path, quick: bool) -> None:
    paths = trust_inputs(data, quick)
    print("## loops you can trust (issue 11): mocycle loop defaults (harmonic M1 + loop checks)")
    print("gait: the legs' autocorrelation period (frames); cycle: the loop's frames; turn: degrees per cycle, the")
    print("loop's and the take's (heading trend x period); creep: root height change over 3 cycles of --root motion,")
    print("% of the body height; fit: template error over the best plain cut's; seam: local seam ratio")
    print(f"{'take':30s} {'frames':>6s} {'gait':>6s} {'cycle':>6s} {'off%':>6s} {'turn':>6s} {'take':>6s} "
          f"{'creep%':>7s} {'fit':>5s} {'seam':>5s}  refused")
    rows = {}
    for p in paths:
        name = f"{p.parent.name}/{p.stem.replace('dataset-1_', '').replace('_001', '')}"
        r = trust_row(read(p))
        rows[name] = r
        if "cycle" not in r:
            print(f"{name[:30]:30s} {r['frames']:6d} {fmt(r['gait']):>6s} {'-':>6s} {'':6s} {'':6s} {'':6s} "
                  f"{'':7s} {'':5s} {'':5s}  {r['why']}")
        else:
            off = 100 * (r["cycle"] / r["gait"] - 1) if np.isfinite(r["gait"]) else float("nan")
            print(f"{name[:30]:30s} {r['frames']:6d} {fmt(r['gait']):>6s} {r['cycle']:6d} {off:6.1f} "
                  f"{r['turn']:6.1f} {r['take_turn']:6.1f} {r['creep']:7.3f} {r['template'] / r['cut']:5.2f} "
                  f"{r['seam']:5.2f}  {r['why'] or '-'}")
        sys.stdout.flush()
    made = {n: r for n, r in rows.items() if "cycle" in r}
    ok = {n: r for n, r in made.items() if not r["refused"]}
    errors = sum(r.get("why") == "error" for r in rows.values())
    print(f"\n## goals (trust): {len(rows)} takes, {len(ok)} loops written with exit 0, "
          f"{len(rows) - len(ok) - errors} refused (exit 3), {errors} bad input (exit 1)")
    period_off = [n for n, r in ok.items() if not abs(r["cycle"] / r["gait"] - 1) <= PERIOD_GOAL]
    listed = ", ".join(f"{n} ({made[n]['cycle']} vs {made[n]['gait']:.1f})" for n in period_off)
    print(f"cycle within {PERIOD_GOAL:.0%} of the gait period: {len(ok) - len(period_off)}/{len(ok)}"
          + (f"; off: {listed}" if period_off else ""))
    turn_off = [n for n, r in ok.items()
                if not abs(r["turn"] - r["take_turn"]) <= max(TURN_GOAL[0], TURN_GOAL[1] * abs(r["take_turn"]))]
    print(f"turn within max({TURN_GOAL[0]:g} deg, {TURN_GOAL[1]:.0%}) of the take's: "
          f"{len(ok) - len(turn_off)}/{len(ok)}"
          + (f"; off: {', '.join(turn_off)}" if turn_off else ""))
    creep = [abs(r["creep"]) for r in made.values()]
    print(f"height creep < {CREEP_GOAL:g}% of the body height over 3 cycles: "
          f"{sum(c < CREEP_GOAL for c in creep)}/{len(creep)} (largest {max(creep, default=0):.2g}%)")
    bad = [n for n, r in ok.items() if r["cycle"] > r["frames"] or r["template"] > MAX_FIT_RATIO * r["cut"]]
    print(f"exit-0 loops longer than the take or fitting worse than {MAX_FIT_RATIO:g}x the best plain cut: {len(bad)}"
          + (f" ({', '.join(bad)}; under the fit floor)" if bad else ""))
    refused = {n: r["refused"] for n, r in rows.items() if r["refused"]}
    print(f"refused: {len(refused)}" + "".join(f"\n  {n}: {why}" for n, why in refused.items()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the synthetic walk and a few real takes")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    parser.add_argument("--only", choices=("trust", "methods"), help="run one part only")
    args = parser.parse_args()
    if args.only != "methods":
        trust(args.data, args.quick)
        if args.only == "trust":
            return
        print()
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
