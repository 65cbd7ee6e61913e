"""Look at the loops of a take: a stick-figure filmstrip of each loop written by ``mocycle loop --part all``.

    python benchmarks/filmstrip.py TAKE.bvh LOOPS.json OUT.png [--poses 8] [--cycles 2]

``LOOPS.json`` is what ``mocycle loop TAKE -o OUT.bvh --part all --root motion --json`` printed (its loops name
their files).  The figure shows, on top, the take's hips path seen from above with each loop's frames drawn
over it in its colour (where it was cut from), then one row per loop: ``--poses`` poses over ``--cycles``
cycles of the written loop, seen from the side (across its direction of travel), with the frame where the loop
wraps marked, and the feet's height over the same cycles (a skate or a pop at the seam shows there).
Uses only ``mocycle.read`` and ``Motion.world_positions()``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import mocycle


def _up(motion) -> int:
    """The vertical axis index (mocycle's own reading of the take's up)."""
    from mocycle.axes import vertical_axis

    return int(np.argmax(np.abs(vertical_axis(motion))))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("take", type=Path)
    ap.add_argument("loops", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--poses", type=int, default=8)
    ap.add_argument("--cycles", type=int, default=2)
    args = ap.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    take = mocycle.read(args.take)
    doc = json.loads(args.loops.read_text())
    loops = doc.get("loops") or []
    up = _up(take)
    h = [a for a in range(3) if a != up]
    W = take.world_positions()
    travel = take.travel_joint
    colours = plt.cm.tab10(np.arange(max(1, len(loops))) % 10)
    fig = plt.figure(figsize=(2.0 * args.poses, 2.6 * (len(loops) + 2)))
    ax = fig.add_subplot(len(loops) + 2, 1, (1, 2))
    ax.plot(W[:, travel, h[0]], W[:, travel, h[1]], color="0.75", lw=1)
    for loop, c in zip(loops, colours, strict=False):
        a, b = loop["frames"]
        ax.plot(W[a:b, travel, h[0]], W[a:b, travel, h[1]], color=c, lw=3,
                label=f"part {loop['part']} {loop['kind']} {a}-{b}")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="best")
    ax.set_title(f"{args.take.name}: hips path from above, each loop's frames in its colour")
    parents = take.skeleton.parents
    for row, (loop, c) in enumerate(zip(loops, colours, strict=False)):
        m = mocycle.read(loop["output"])
        n = m.n_frames
        reps = mocycle.motion.concatenate([m] * args.cycles) if args.cycles > 1 else m
        P = reps.world_positions()
        if loop.get("root") == "motion" and args.cycles > 1:  # the file holds one cycle: move each on by its travel
            shift = np.asarray(loop["travel_per_cycle"], dtype=np.float64)
            for k in range(1, args.cycles):
                P[k * n:(k + 1) * n] += k * shift
        d = P[-1, travel] - P[0, travel]
        d[up] = 0.0
        frames = np.linspace(0, P.shape[0] - 1, args.poses).round().astype(int)
        body = float(np.ptp(P[0, travel:, up]))  # a static root far from the body (Bandai's) is no bone to draw
        moves = np.linalg.norm(d) > 0.1 * body   # on the spot: the poses side by side instead
        fwd = d / np.linalg.norm(d) if moves else np.eye(3)[h[0]]
        drawn = [(p, j) for j, p in enumerate(parents) if p >= 0 and
                 np.linalg.norm(P[0, j] - P[0, p]) < 0.75 * max(body, 1e-9)]
        axr = fig.add_subplot(len(loops) + 2, 2, 2 * (row + 2) + 1)
        for k, f in enumerate(frames):
            x = (P[f] - P[frames[0], travel]) @ fwd + (0.0 if moves else 0.6 * k * body)
            y = P[f, :, up]
            for p, j in drawn:
                axr.plot([x[p], x[j]], [y[p], y[j]], color=c, lw=1)
            axr.text(x[travel], y.max() * 1.02, str(f), fontsize=6, ha="center")
        axr.set_aspect("equal")
        axr.set_title(f"part {loop['part']} {loop['kind']}: {n} frames a cycle, {args.poses} poses over "
                      f"{args.cycles}", fontsize=8)
        axf = fig.add_subplot(len(loops) + 2, 2, 2 * (row + 2) + 2)
        feet = [j for j, name in enumerate(take.skeleton.names) if "foot" in name.lower() or "toe" in name.lower()]
        for j in feet:
            axf.plot(P[:, j, up], lw=1, label=take.skeleton.names[j])
        for k in range(1, args.cycles):
            axf.axvline(k * n, color="k", ls=":", lw=1)
        axf.set_title("feet heights (dotted: the seam)", fontsize=8)
        axf.tick_params(labelsize=6)
    fig.tight_layout()
    fig.savefig(args.out, dpi=70)
    print(f"wrote {args.out}: {len(loops)} loop(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
