"""Circular coordinates: mocycle against DREiMac and Dionysus 2, in one run.

    python benchmarks/phase.py [--quick] [--data DIR]

Every tool gets the same prepared point cloud: ``pose_matrix(motion,
rep="expmap", root_features="velocity", normalize=True, weights="bone")`` projected on
8 principal components.  Inputs: seeded synthetic walks of 300, 600, 1200 and
2400 frames (1 degree of angle noise) with their true phase, and the walks and
runs of ../shared/data (bandai dataset-1 walk/run takes, 30 fps; cmu-iclone
02_01-02_03, 05_01, 07_01-07_12, 60 fps).  ``--quick`` runs the synthetic
inputs only.

Per input and tool: seconds (median of 3 runs when one run takes under
``REPEAT_BELOW_S``, else 1 run); on synthetic inputs the mean circular error
of the coordinate against the true phase after the best rotation and
direction, raw and after a rank-uniform remap; on real takes the period from
the unwrapped coordinate (least-squares line) against the windowed
autocorrelation period.  Then the summary lines (speed-up, accuracy, scaling
to 10 000 frames, the 500-frame take).

Tools and the parameters chosen for them:

* mocycle: ``CircularCoordinates(n_landmarks=120, prime=47, n_classes=1,
  min_periods=None)`` (the raw coordinate is always kept); and, when it exists,
  ``mocycle.phase.find_phase(motion)`` (features + coordinates + periods).
* DREiMac: ``CircularCoords(X, n_landmarks=120, prime=47)`` and
  ``get_coordinates(perc=0.5, cocycle_idx=0)`` (its defaults; the same
  landmark count and prime as mocycle); when the class is too short for its
  standard range, ``standard_range=False`` is retried and noted.
* Dionysus 2: full Vietoris-Rips up to triangles (``fill_rips``) with the
  cutoff at the ``DIONYSUS_QUANTILE`` quantile of the pairwise distances,
  ``cohomology_persistence(f, 47, True)``, the longest H1 bar, and
  ``smooth`` on the filtration cut at the middle of that bar (the Dionysus
  tutorial's recipe).  Only up to ``DIONYSUS_MAX_FRAMES`` frames (it grows like
  N^3.5).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SYNTHETIC_FRAMES = (300, 600, 1200, 2400)
NOISE_DEG = 1.0
SEED = 7
PCA_DIMS = 8
N_LANDMARKS = 120
PRIME = 47
REPEAT_BELOW_S = 2.0  # a tool run faster than this is timed 3 times (median)
DIONYSUS_MAX_FRAMES = 600
DIONYSUS_QUANTILE = 0.15
SCALING_FRAMES = 10_000
TAKE_FRAMES = 500
SPEEDUP_GOAL = 10.0
TAKE_GOAL_S = 0.05
CMU_ICLONE_TAKES = ("02_01", "02_02", "02_03", "05_01", *(f"07_{i:02d}" for i in range(1, 13)))


class Skipped(Exception):
    """A tool that does not run on this input (the message says why)."""


# -- input preparation ----------------------------------------------------------------------------------------------
def prepare(motion) -> np.ndarray:
    """The point cloud every tool gets: expmap + root velocity, z-scored, bone-weighted, PCA 8."""
    from sklearn.decomposition import PCA

    from mocycle.features import pose_matrix

    X, _ = pose_matrix(motion, rep="expmap", root_features="velocity", normalize=True, weights="bone")
    return PCA(n_components=min(PCA_DIMS, *X.shape), svd_solver="full").fit_transform(X)


def synthetic(n_frames: int):
    from mocycle.datasets import synthetic_walk

    return synthetic_walk(n_frames, noise_deg=NOISE_DEG, seed=SEED)


def real_takes(data: Path) -> list[Path]:
    bandai = sorted((data / "bandai").glob("dataset-1_walk_*_001.bvh")) + \
        sorted((data / "bandai").glob("dataset-1_run_*_001.bvh"))
    iclone = [data / "cmu-iclone" / f"{name}.bvh" for name in CMU_ICLONE_TAKES]
    return bandai + [p for p in iclone if p.is_file()]


# -- the tools: each maps the prepared X (T, 8) to a coordinate (T,) in [0, 1) -------------------------------------
def run_mocycle(X: np.ndarray) -> np.ndarray:
    from mocycle.phase import CircularCoordinates

    est = CircularCoordinates(n_landmarks=N_LANDMARKS, prime=PRIME, scale="auto", n_classes=1,
                              min_periods=None).fit(X)
    if est.coords_.shape[1] == 0:
        raise Skipped(f"no class: {est.reason_}")
    return est.coords_[:, 0]


def run_dreimac(X: np.ndarray) -> np.ndarray:
    from dreimac import CircularCoords

    cc = CircularCoords(X, n_landmarks=min(N_LANDMARKS, X.shape[0]), prime=PRIME)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "n points not covered by a landmark"
        try:
            theta = cc.get_coordinates(perc=0.5, cocycle_idx=0)
        except Exception as exc:  # DREiMac raises a bare Exception for a class too short for its standard range
            if "too short" not in str(exc):
                raise
            theta = cc.get_coordinates(perc=0.5, cocycle_idx=0, standard_range=False)
            run_dreimac.note = "standard_range=False"
    return np.mod(np.asarray(theta) / (2 * np.pi), 1.0)


run_dreimac.note = ""


def run_dionysus(X: np.ndarray) -> np.ndarray:
    import dionysus as d
    from scipy.spatial.distance import pdist

    if X.shape[0] > DIONYSUS_MAX_FRAMES:
        raise Skipped("skipped (N^3.5)")
    cutoff = float(np.quantile(pdist(X), DIONYSUS_QUANTILE))
    f = d.fill_rips(np.ascontiguousarray(X, dtype=np.float32), 2, cutoff)
    p = d.cohomology_persistence(f, PRIME, True)
    dgms = d.init_diagrams(p, f)
    if len(dgms) < 2 or len(dgms[1]) == 0:
        raise Skipped(f"no H1 bar below the cutoff {cutoff:.3g}")
    bar = max(dgms[1], key=lambda pt: min(pt.death, cutoff) - pt.birth)
    cocycle = p.cocycle(bar.data)
    middle = (bar.birth + min(bar.death, cutoff)) / 2
    values = d.smooth(d.Filtration([s for s in f if s.data <= middle]), cocycle, PRIME)
    return np.mod(np.asarray(values, dtype=float), 1.0)


def timed_dreimac(X: np.ndarray) -> tuple[float, float, np.ndarray | None]:
    """(seconds of one DREiMac run, seconds of it spent in numba compilation, its coordinate in cycles).

    DREiMac 0.3 defines its ``@jit`` helpers inside ``get_coordinates``' callees, so numba compiles them
    again on every call; numba's ``numba:compile`` events measure that part.
    """
    from numba.core import event

    with event.install_recorder("numba:compile") as rec:
        t0 = time.perf_counter()
        coord = run_dreimac(X)
        total = time.perf_counter() - t0
    depth, start, compiling = 0, 0.0, 0.0
    for ts, ev in rec.buffer:  # nested compilations count once
        if ev.is_start:
            depth += 1
            start = ts if depth == 1 else start
        else:
            depth -= 1
            compiling += ts - start if depth == 0 else 0.0
    return total, compiling, coord


def dreimac_compile_seconds(X: np.ndarray) -> tuple[float, float]:
    """(seconds of one DREiMac run, seconds of it spent in numba compilation): :func:`timed_dreimac`."""
    total, compiling, _ = timed_dreimac(X)
    return total, compiling


TOOLS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "mocycle": run_mocycle,
    "DREiMac": run_dreimac,
    "dionysus": run_dionysus,
}


def available_tools() -> dict[str, str]:
    """Tool name -> '' when importable, else the reason it is not."""
    out = {"mocycle": ""}
    for name, module in (("DREiMac", "dreimac"), ("dionysus", "dionysus")):
        try:
            __import__(module)
            out[name] = ""
        except Exception as exc:  # ImportError, or a broken build
            out[name] = f"{type(exc).__name__}: {exc}"
    return out


def find_phase_function():
    """``mocycle.phase.find_phase`` when it exists (it may be written while this benchmark is)."""
    try:
        from mocycle.phase import find_phase
    except ImportError:
        try:
            from mocycle.phase.analysis import find_phase
        except ImportError:
            return None
    return find_phase


def acf_period_function():
    try:
        from mocycle.phase.period import autocorrelation_period
    except ImportError:
        return None
    return autocorrelation_period


# -- timing and measures ---------------------------------------------------------------------------------------------
def timed(fn: Callable, *args) -> tuple[float, object]:
    """Seconds of ``fn(*args)`` (median of 3 when one run is fast) and its result."""
    t0 = time.perf_counter()
    result = fn(*args)
    first = time.perf_counter() - t0
    if first >= REPEAT_BELOW_S:
        return first, result
    times = [first]
    for _ in range(2):
        t0 = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def circular_error_deg(coord: np.ndarray, truth: np.ndarray) -> float:
    """Mean |circular difference| in degrees after the best rotation and direction (both directions tried)."""
    ok = np.isfinite(truth)
    coord, truth = coord[ok], truth[ok]
    shifts = np.linspace(0.0, 1.0, 1440, endpoint=False)
    best = np.inf
    for sign in (1.0, -1.0):
        diff = sign * coord - truth
        # the circular mean is nearly optimal; a grid makes sure of the best L1 rotation
        mean = np.angle(np.mean(np.exp(2j * np.pi * diff))) / (2 * np.pi)
        for cand in (np.r_[mean], shifts):
            err = np.abs(_wrap(diff[:, None] - cand[None, :])).mean(axis=0)
            best = min(best, float(err.min()))
    return best * 360.0


def _wrap(x: np.ndarray) -> np.ndarray:
    return x - np.round(x)


def rank_uniform(coord: np.ndarray) -> np.ndarray:
    """Rank-uniform remap (KTH thesis eq. 3.20): the rank of each value over n."""
    return np.argsort(np.argsort(coord, kind="stable"), kind="stable") / coord.size


def unwrap_period(coord: np.ndarray) -> float:
    """Frames per cycle from a least-squares line through the unwrapped coordinate (either direction)."""
    unwrapped = np.unwrap(2 * np.pi * coord) / (2 * np.pi)
    slope = np.polyfit(np.arange(coord.size), unwrapped, 1)[0]
    return 1.0 / abs(slope) if slope != 0 else float("inf")


# -- one row per (input, tool) ---------------------------------------------------------------------------------------
@dataclass
class Row:
    input: str
    frames: int
    tool: str
    seconds: float = np.nan
    err_raw: float = np.nan
    err_rank: float = np.nan
    period: float = np.nan
    acf: float = np.nan
    note: str = ""


def run_tool(name: str, fn: Callable, X: np.ndarray, label: str, truth=None, acf=np.nan) -> Row:
    row = Row(label, X.shape[0], name, acf=acf)
    run_dreimac.note = ""
    try:
        row.seconds, coord = timed(fn, X)
    except Skipped as exc:
        row.note = str(exc)
        return row
    except Exception as exc:
        row.note = f"error: {type(exc).__name__}: {str(exc).strip()[:80]}"
        return row
    if name == "DREiMac":
        row.note = run_dreimac.note
    if truth is not None:
        row.err_raw = circular_error_deg(coord, truth)
        row.err_rank = circular_error_deg(rank_uniform(coord), truth)
    else:
        row.period = unwrap_period(coord)
    return row


def run_find_phase(find_phase, motion, label: str, truth=None) -> Row:
    row = Row(label, motion.n_frames, "mocycle find_phase")
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            row.seconds, res = timed(find_phase, motion)
    except Exception as exc:
        row.note = f"error: {type(exc).__name__}: {str(exc).strip()[:80]}"
        return row
    if caught:
        row.note = f"warning: {str(caught[0].message)[:70]}; "
    row.acf = res.autocorrelation_period_frames
    if not res.classes:
        row.note += f"no periodic motion: {res.reason[:70]}"
        return row
    cls = res.classes[0]
    if truth is not None:
        row.err_raw = circular_error_deg(cls.coords, truth)
        row.err_rank = circular_error_deg(rank_uniform(cls.coords), truth)
    else:
        row.period = cls.period_frames
    if len(res.classes) > 1:
        row.note += f"{len(res.classes)} classes"
    return row


def bench_input(label: str, motion, tools: dict[str, str], find_phase, acf_fn, truth=None) -> list[Row]:
    X = prepare(motion)
    acf = np.nan
    if truth is None and acf_fn is not None:
        try:  # the lower lag bound find_phase uses: a quarter of a second
            acf = float(acf_fn(X, min_lag=max(2, int(round(0.25 / motion.frame_time)))))
        except Exception:
            acf = np.nan
    rows = []
    for name, fn in TOOLS.items():
        if tools[name]:
            continue
        rows.append(run_tool(name, fn, X, label, truth, acf))
    if find_phase is not None:
        rows.append(run_find_phase(find_phase, motion, label, truth))
    return rows


# -- output ----------------------------------------------------------------------------------------------------------
def _fmt(x: float, spec: str) -> str:
    return "-" if not np.isfinite(x) else format(x, spec)


def print_table(title: str, header: tuple[str, ...], lines: list[tuple[str, ...]]) -> None:
    """A plain text table: input, tool and note left-aligned, numbers right-aligned."""
    widths = [max(len(h), *(len(line[i]) for line in lines)) if lines else len(h) for i, h in enumerate(header)]

    def fmt(cells):
        out = [c.ljust(w) if h in ("input", "tool", "note") else c.rjust(w)
               for h, c, w in zip(header, cells, widths, strict=True)]
        return "  ".join(out).rstrip()

    print(f"\n{title}")
    print(fmt(header))
    print("  ".join("-" * (len(h) if h == "note" else w) for h, w in zip(header, widths, strict=True)))
    for line in lines:
        print(fmt(line))
    print()


def synthetic_table(rows: list[Row]) -> None:
    print_table(f"Synthetic walks (noise {NOISE_DEG:g} deg, seed {SEED}): mean circular error against the true phase",
                ("input", "frames", "tool", "seconds", "raw err (deg)", "rank-uniform err (deg)", "note"),
                [(r.input, str(r.frames), r.tool, _fmt(r.seconds, ".3f"), _fmt(r.err_raw, ".2f"),
                  _fmt(r.err_rank, ".2f"), r.note) for r in rows])


def real_table(rows: list[Row], acf_name: str) -> None:
    print_table(f"Real takes: period (frames) from the unwrapped coordinate vs {acf_name}",
                ("input", "frames", "tool", "seconds", "period", "acf period", "ratio", "note"),
                [(r.input, str(r.frames), r.tool, _fmt(r.seconds, ".3f"), _fmt(r.period, ".1f"), _fmt(r.acf, ".1f"),
                  _fmt(r.period / r.acf, ".2f"), r.note) for r in rows])


def _by(rows: list[Row], tool: str) -> dict[str, Row]:
    return {r.input: r for r in rows if r.tool == tool}


def summary(rows: list[Row], synthetic_rows: list[Row], find_phase) -> None:
    mo, dr = _by(rows, "mocycle"), _by(rows, "DREiMac")
    ratios = [dr[k].seconds / mo[k].seconds for k in mo
              if k in dr and np.isfinite(dr[k].seconds) and np.isfinite(mo[k].seconds)]
    if ratios:
        print(f"mocycle vs DREiMac speed-up: median {statistics.median(ratios):.1f}×, min {min(ratios):.1f}× "
                      f"(goal >= {SPEEDUP_GOAL:g}×) over {len(ratios)} inputs")
    else:
        print("mocycle vs DREiMac speed-up: no input where both ran")

    if "DREiMac" in {r.tool for r in rows}:
        X = prepare(synthetic(600).motion)
        runs = sorted((dreimac_compile_seconds(X) for _ in range(3)), key=lambda tc: tc[0])
        total, compiling = runs[1]
        mo_secs, _ = timed(run_mocycle, X)
        print(f"DREiMac per call on the 600-frame walk: {total:.3f} s, of which {compiling:.3f} s numba "
                      f"compilation (its jit helpers are recompiled on every call); without compilation the "
                      f"speed-up there would be {(total - compiling) / mo_secs:.1f}×")

    def median_err(tool):
        errs = [r.err_raw for r in synthetic_rows if r.tool == tool and np.isfinite(r.err_raw)]
        return _fmt(statistics.median(errs) if errs else np.nan, ".2f")

    print(f"accuracy: mocycle raw error median {median_err('mocycle')} deg vs DREiMac "
                  f"{median_err('DREiMac')} deg (synthetic walks; dionysus {median_err('dionysus')} deg)")

    big = prepare(synthetic(SCALING_FRAMES).motion)
    secs, _ = timed(run_mocycle, big)
    print(f"scaling: mocycle time at {SCALING_FRAMES} frames: {secs:.2f} s")

    take = synthetic(TAKE_FRAMES).motion
    secs_est, _ = timed(run_mocycle, prepare(take))
    secs_prep, _ = timed(prepare, take)
    line = (f"mocycle on a {TAKE_FRAMES}-frame take: {secs_est:.3f} s (goal about {TAKE_GOAL_S:g} s) "
            f"for the estimator on the prepared X; input preparation {secs_prep:.3f} s")
    if find_phase is not None:
        secs_fp, _ = timed(find_phase, take)
        line += f"; find_phase end to end {secs_fp:.3f} s"
    print(line)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="synthetic inputs only")
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the shared data folder")
    args = ap.parse_args(argv)

    tools = available_tools()
    find_phase = find_phase_function()
    acf_fn = acf_period_function()
    for name, reason in tools.items():
        if reason:
            print(f"{name}: not installed ({reason})")
    print(f"find_phase: {'timed as the row mocycle find_phase' if find_phase else 'not available'}; "
                  f"autocorrelation period: {'mocycle.phase.period' if acf_fn else 'not available (NaN)'}")

    # warm-up (imports, numba compilation in DREiMac), not timed
    warm = prepare(synthetic(200).motion)
    for name, fn in TOOLS.items():
        if not tools[name]:
            try:
                fn(warm)
            except Exception:
                pass

    synthetic_rows: list[Row] = []
    for n in SYNTHETIC_FRAMES:
        take = synthetic(n)
        synthetic_rows += bench_input(f"synthetic walk {n}", take.motion, tools, find_phase, acf_fn,
                                      truth=np.asarray(take.phase, dtype=float))
    synthetic_table(synthetic_rows)

    real_rows: list[Row] = []
    if args.quick:
        print("--quick: real takes skipped")
    else:
        paths = real_takes(args.data)
        if not paths:
            print(f"real takes skipped: no walk/run BVH files under {args.data} "
                          "(clone ../shared beside the repo or pass --data DIR)")
        else:
            from mocycle.io import read_bvh

            for path in paths:
                motion = read_bvh(path)
                label = f"{path.parent.name} {path.stem.removeprefix('dataset-1_').removesuffix('_001')}"
                real_rows += bench_input(label, motion, tools, find_phase, acf_fn)
            acf_name = "windowed autocorrelation" if acf_fn else "autocorrelation (not available)"
            real_table(real_rows, acf_name)

    summary(synthetic_rows + real_rows, synthetic_rows, find_phase)
    return 0


if __name__ == "__main__":
    sys.exit(main())
