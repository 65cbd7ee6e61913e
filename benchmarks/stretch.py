"""Lengthening by time-frequency warping against plain time-scaling and naive concatenation, in one table.

    python benchmarks/stretch.py [--factor 2] [--data DIR]

Methods, each making a result ``factor`` times as long as its input:

* stretch: ``mocycle.warp.warp_curves`` (signals, window from ``fundamental_cycles`` and ``refine_window``) or
  ``mocycle.warp.stretch_motion`` (takes, window "auto": each joint group's largest cycle);
* resample: plain time-scaling (linear interpolation of the signal; ``Motion.resample`` by slerp for a
  take, played at the original frame rate);
* concat: the input repeated and cut to length (a take's travelling joint is shifted at each join so the
  character goes on from where it stopped, which is the fair version).

Inputs: the four synthetic signals of paper 004 §5.1 (a sum of periods 115, 57.5 and 23 frames; a fixed
period of 40 frames that does not end on a cycle; a pendulum whose amplitude decays quadratically; a
variable period 40 +- 8 frames with noise) and the walks of ../shared/data (the 15 bandai dataset-1 walks,
30 fps; cmu-iclone 02_01, 02_02, 05_01, 07_01-07_12, 60 fps; frame 0 of a cmu-iclone take is dropped when it
is a rest-pose glitch, a first step over 20 times the median step).

Figures, each as result / input:

* freq: the dominant frequency (peak of the summed power spectrum of the Hann-windowed, detrended curves,
  zero-padded 16 times, parabolic refinement).  Goal for stretch: within 5% of 1 (resampling halves it).
* amp: the RMS of the detrended curves.  Goal: within 10% of 1.
* jump: the largest frame-to-frame step (signals: |x[t+1] - x[t]|; takes: the largest angle between
  consecutive local rotations of any joint).  Goal: at most 1.5 (concatenation fails this at the joins).

Takes are measured on their rotation curves (``pose_matrix(rep="quatlog", root_features="drop")``).  Rows for a set
of takes give the median and, in brackets, the worst value; ``ok`` counts the takes meeting all three goals.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.signal import detrend

DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
FACTOR = 2.0
FREQ_TOL = 0.05
AMP_TOL = 0.10
JUMP_MAX = 1.5
PAD = 16
ICLONE_WALKS = ("02_01", "02_02", "05_01", *(f"07_{i:02d}" for i in range(1, 13)))
METHODS = ("stretch", "resample", "concat")


# -- the paper's §5.1 signals ---------------------------------------------------------------------------------------
def synthetic_signals(seed: int = 1) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(400.0)
    phase = np.cumsum(1.0 / (40.0 + 8.0 * np.sin(2 * np.pi * t / 400.0)))
    t_fixed, t_pend = np.arange(250.0), np.arange(300.0)
    return {
        "sum of periods (115, 57.5, 23)": np.sin(2 * np.pi * t / 115) + 0.5 * np.sin(2 * np.pi * t / 23 + 1)
        + 0.3 * np.sin(2 * np.pi * t / 57.5 + 2),
        "fixed period 40, ends mid-cycle": np.sin(2 * np.pi * t_fixed / 40 + 0.3),
        "pendulum, quadratic decay": (1 - t_pend / 360) ** 2 * np.cos(2 * np.pi * t_pend / 50),
        "variable period 40+-8, noise": np.sin(2 * np.pi * phase) + 0.1 * rng.normal(size=t.size),
    }


# -- measures -------------------------------------------------------------------------------------------------------
def dominant_frequency(X: np.ndarray) -> float:
    """Cycles per frame of the peak of the summed power spectrum of ``X`` (``(T, D)``)."""
    X = detrend(np.asarray(X, dtype=np.float64), axis=0)
    n = X.shape[0]
    P = np.sum(np.abs(np.fft.rfft(X * np.hanning(n)[:, None], n * PAD, axis=0)) ** 2, axis=1)
    k = int(np.argmax(P[1:])) + 1
    if k + 1 >= P.size:
        return k / (n * PAD)
    a, b, c = np.log(P[k - 1: k + 2] + 1e-300)
    curv = a - 2 * b + c
    return (k + (0.5 * (a - c) / curv if curv < 0 else 0.0)) / (n * PAD)


def amplitude(X: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(detrend(np.asarray(X, dtype=np.float64), axis=0) ** 2, axis=1))))


def signal_jump(x: np.ndarray) -> float:
    return float(np.abs(np.diff(x, axis=0)).max())


def rotation_jump(motion) -> float:
    """Largest angle (radians) between consecutive local rotations of any joint."""
    q = motion.rotations
    dots = np.abs(np.sum(q[1:] * q[:-1], axis=-1)).clip(0.0, 1.0)
    return float(2.0 * np.arccos(dots).max())


# -- methods on signals ---------------------------------------------------------------------------------------------
def signal_methods(x: np.ndarray, factor: float) -> dict[str, tuple[np.ndarray, float]]:
    from mocycle.warp import fundamental_cycles, warp_curves
    from mocycle.warp.stretch import refine_window

    n = int(round(x.size * factor))
    t0 = time.perf_counter()
    window = refine_window(x, fundamental_cycles(x[:, None])[0])
    stretched = warp_curves(x, factor, window)
    t1 = time.perf_counter()
    resampled = np.interp(np.linspace(0, x.size - 1, n), np.arange(x.size), x)
    t2 = time.perf_counter()
    concat = np.tile(x, int(np.ceil(factor)) + 1)[:n]
    t3 = time.perf_counter()
    return {"stretch": (stretched, t1 - t0), "resample": (resampled, t2 - t1), "concat": (concat, t3 - t2)}


# -- methods on takes -----------------------------------------------------------------------------------------------
def concat_motion(motion, factor: float):
    from mocycle.motion import concatenate

    n = int(round(motion.n_frames * factor))
    travel = motion.travel_joint
    p = motion.translations[:, travel]
    step = p[-1] - p[-2] if motion.n_frames > 1 else np.zeros(3)
    shift = p[-1] - p[0] + step
    copies = []
    for k in range(int(np.ceil(factor)) + 1):
        trans = motion.translations.copy()
        trans[:, travel] += k * shift
        copies.append(motion.replace(translations=trans))
    return concatenate(copies)[:n]


def take_methods(motion, factor: float) -> dict:
    from mocycle.warp import stretch_motion

    t0 = time.perf_counter()
    stretched, report = stretch_motion(motion, factor)
    t1 = time.perf_counter()
    resampled = motion.resample(motion.fps * factor).replace(frame_time=motion.frame_time)
    t2 = time.perf_counter()
    concat = concat_motion(motion, factor)
    t3 = time.perf_counter()
    return {"stretch": (stretched, t1 - t0), "resample": (resampled, t2 - t1), "concat": (concat, t3 - t2)}, report


def load_take(path: Path):
    from mocycle.io import read

    m = read(path)
    p = m.translations[:, m.travel_joint]
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if steps.size > 2 and steps[0] > 20 * max(float(np.median(steps)), 1e-9):
        m = m[1:]
    return m


def curves(motion) -> np.ndarray:
    from mocycle.features import pose_matrix

    X, _ = pose_matrix(motion, rep="quatlog", root_features="drop")
    return X


# -- table ----------------------------------------------------------------------------------------------------------
def ok(freq: float, amp: float, jump: float) -> bool:
    return abs(freq - 1) <= FREQ_TOL and abs(amp - 1) <= AMP_TOL and jump <= JUMP_MAX


def summary(values: list[float], worst_of) -> str:
    if len(values) == 1:
        return f"{values[0]:.3f}"
    return f"{statistics.median(values):.3f} [{worst_of(values):.3f}]"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factor", type=float, default=FACTOR)
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA)
    ap.add_argument("--windows", action="store_true", help="Also print the window of every group of every take.")
    args = ap.parse_args(argv)
    F = args.factor
    rows: list[tuple[str, str, str, str, str, str, str]] = []

    def far(target):
        return lambda vs: max(vs, key=lambda v: abs(v - target))

    for name, x in synthetic_signals().items():
        results = signal_methods(x, F)
        f0, a0, j0 = dominant_frequency(x[:, None]), amplitude(x[:, None]), signal_jump(x)
        for method in METHODS:
            y, sec = results[method]
            fr = dominant_frequency(y[:, None]) / f0
            am = amplitude(y[:, None]) / a0
            ju = signal_jump(y) / j0
            rows.append((name, method, f"{fr:.3f}", f"{am:.3f}", f"{ju:.3f}", "yes" if ok(fr, am, ju) else "no",
                         f"{1e3 * sec:.1f}"))

    sets = {
        "bandai walks": sorted((args.data / "bandai").glob("dataset-1_walk_*_001.bvh")),
        "cmu-iclone walks": [p for p in (args.data / "cmu-iclone" / f"{n}.bvh" for n in ICLONE_WALKS) if p.is_file()],
    }
    windows_note = []
    for set_name, paths in sets.items():
        if not paths:
            print(f"({set_name}: no files under {args.data}; skipped)", file=sys.stderr)
            continue
        per = {m: {"freq": [], "amp": [], "jump": [], "ok": 0, "sec": []} for m in METHODS}
        for path in paths:
            motion = load_take(path)
            results, report = take_methods(motion, F)
            windows_note.append(f"{path.stem}: {report.windows}")
            X = curves(motion)
            f0, a0, j0 = dominant_frequency(X), amplitude(X), rotation_jump(motion)
            for method in METHODS:
                out, sec = results[method]
                Y = curves(out)
                fr, am, ju = dominant_frequency(Y) / f0, amplitude(Y) / a0, rotation_jump(out) / j0
                d = per[method]
                d["freq"].append(fr)
                d["amp"].append(am)
                d["jump"].append(ju)
                d["ok"] += ok(fr, am, ju)
                d["sec"].append(sec)
        for method in METHODS:
            d = per[method]
            rows.append((f"{set_name} ({len(paths)})", method, summary(d["freq"], far(1.0)),
                         summary(d["amp"], far(1.0)), summary(d["jump"], max), f"{d['ok']}/{len(paths)}",
                         f"{1e3 * statistics.median(d['sec']):.1f}"))

    header = ("input", "method", "freq out/in", "amp out/in", "jump out/in", "ok", "ms")
    widths = [max(len(r[i]) for r in rows + [header]) for i in range(len(header))]
    print(f"factor {F:g}; goals: freq within {FREQ_TOL:.0%}, amp within {AMP_TOL:.0%}, jump <= {JUMP_MAX}x "
          f"(takes: median [worst])")
    line = " | ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))
    print(line)
    print("-|-".join("-" * w for w in widths))
    for r in rows:
        print(" | ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)))
    if args.windows:
        print("\n".join(windows_note))
    return 0


if __name__ == "__main__":
    sys.exit(main())
