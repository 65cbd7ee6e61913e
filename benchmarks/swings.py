"""Joint swings (paper 003): playback error, compression, speed, threshold sweep and retrieval.

    python benchmarks/swings.py            # about a minute on 2 cores

Prints, per shared take, the Segmentation Error (the paper's: mean per-frame
Euclidean distance of the Euler DOF vectors, degrees), the paper's per-angle
figure (that distance / rotation DOFs; the paper reached 25.50 / 62 = 0.41°),
the mean geodesic error per joint, the compressed size against the raw float32
channels and the BVH text, and the seconds of segmentation; then a sweep of
the Acceptable Swing Error from 0 to 1 (the paper's Figure 18), the time to
segment a 1000-frame take, and precision@5 of query by example on the
Bandai Namco takes (walk, run, dash in 15 styles).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

from mocycle.io import read
from mocycle.swings import build_index, playback, playback_errors, precision_at_k, segment, size_report

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
TAKES = ["cmu/01_01.bvh", "cmu-iclone/02_01.bvh", "cmu-iclone/02_03.bvh", "cmu-iclone/02_05.bvh",
         "cmu-iclone/05_13.bvh", "cmu-iclone/07_12.bvh"]


def measure(motion, threshold=0.4):
    t0 = time.perf_counter()
    seg = segment(motion, threshold=threshold)
    secs = time.perf_counter() - t0
    errs = playback_errors(motion, playback(seg))
    size = size_report(seg, motion)
    return seg, errs, size, secs


def main() -> int:
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print(f"shared data {DATA} is absent; nothing to measure")
        return 0
    print("## per take (Acceptable Swing Error 0.4)")
    head = f"{'take':34s} {'frames':>6s} {'fps':>5s} {'swings':>6s} {'SegErr':>7s} {'/angle':>7s} {'rms':>6s} " \
           f"{'geod':>6s} {'raw':>6s} {'bvh':>6s} {'s':>6s}"
    print(head)
    rows = []
    bandai = sorted((DATA / "bandai").glob("*.bvh"))
    for name in TAKES:
        p = DATA / name
        if p.exists():
            rows.append((name, read(p)))
    groups: dict[str, list] = {}
    for p in bandai:
        groups.setdefault(p.stem.split("_")[1], []).append(read(p))
    results = []
    for name, m in rows:
        seg, e, s, secs = measure(m)
        results.append((e, s))
        print(f"{name:34s} {m.n_frames:6d} {m.fps:5.0f} {seg.n_swings:6d} {e['segmentation_error']:7.2f} "
              f"{e['per_angle_error_deg']:7.3f} {e['rms_angle_error_deg']:6.2f} {e['geodesic_error_deg']:6.2f} "
              f"{s['ratio_raw']:6.3f} {s['ratio_bvh']:6.3f} {secs:6.3f}")
    for content, ms in sorted(groups.items()):
        rs = [measure(m) for m in ms]
        n = np.mean([m.n_frames for m in ms])
        raw = sum(r[2]["compressed_bytes"] for r in rs) / sum(r[2]["raw_float32_bytes"] for r in rs)
        bvh = sum(r[2]["compressed_bytes"] for r in rs) / sum(r[2]["bvh_bytes"] for r in rs)
        results += [(r[1], r[2]) for r in rs]
        print(f"{'bandai ' + content + ' (15 styles, mean)':34s} {n:6.0f} {ms[0].fps:5.0f} "
              f"{np.mean([r[0].n_swings for r in rs]):6.0f} "
              f"{np.mean([r[1]['segmentation_error'] for r in rs]):7.2f} "
              f"{np.mean([r[1]['per_angle_error_deg'] for r in rs]):7.3f} "
              f"{np.mean([r[1]['rms_angle_error_deg'] for r in rs]):6.2f} "
              f"{np.mean([r[1]['geodesic_error_deg'] for r in rs]):6.2f} {raw:6.3f} {bvh:6.3f} "
              f"{np.mean([r[3] for r in rs]):6.3f}")
    allraw = sum(s["compressed_bytes"] for _, s in results) / sum(s["raw_float32_bytes"] for _, s in results)
    print(f"{'all takes':34s} per-angle mean {np.mean([e['per_angle_error_deg'] for e, _ in results]):.3f} deg, "
          f"geodesic mean {np.mean([e['geodesic_error_deg'] for e, _ in results]):.2f} deg, "
          f"size {allraw:.3f} of raw float32 (goal <= 0.25 at <= 0.41 deg per angle)")

    print("\n## Acceptable Swing Error sweep (paper Figure 18): mean over the takes above and 15 Bandai takes")
    sweep = [m for _, m in rows] + [groups[c][k] for c in sorted(groups) for k in range(0, 15, 3)]
    print(f"{'threshold':>9s} {'swings':>7s} {'SegErr':>7s} {'/angle':>7s} {'geod':>6s} {'raw':>6s}")
    for thr in np.round(np.arange(0.0, 1.01, 0.1), 2):
        rs = [measure(m, thr) for m in sweep]
        print(f"{thr:9.1f} {np.mean([r[0].n_swings for r in rs]):7.0f} "
              f"{np.mean([r[1]['segmentation_error'] for r in rs]):7.2f} "
              f"{np.mean([r[1]['per_angle_error_deg'] for r in rs]):7.3f} "
              f"{np.mean([r[1]['geodesic_error_deg'] for r in rs]):6.2f} "
              f"{np.mean([r[2]['ratio_raw'] for r in rs]):6.3f}")

    print("\n## speed: segmentation of 1000 frames (best of 5)")
    for name, m in rows[:2]:
        if m.n_frames >= 1000:
            part = m[:1000]
            best = min(measure_time(part) for _ in range(5))
            print(f"{name:34s} {part.n_joints} joints, {part.fps:.0f} fps: {best:.3f} s (goal < 0.2 s)")

    if len(bandai) >= 2:
        print("\n## retrieval: precision@5 on bandai (each take queries the other 44; chance ~0.32)")
        t0 = time.perf_counter()
        idx = build_index(DATA / "bandai")
        t1 = time.perf_counter()
        p = precision_at_k(idx, k=5)
        t2 = time.perf_counter()
        print(f"precision@5 {p['precision']:.3f}  by content "
              + ", ".join(f"{k} {v:.3f}" for k, v in sorted(p["by_label"].items()))
              + f"  (index {t1 - t0:.1f} s, {p['n_queries']} queries {t2 - t1:.1f} s)")
    return 0


def measure_time(motion) -> float:
    t0 = time.perf_counter()
    segment(motion)
    return time.perf_counter() - t0


if __name__ == "__main__":
    sys.exit(main())
