"""Joint curves of several motions on one axis: the ``--plot`` of ``blend``, ``transition`` and ``stretch``."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .figure import save, subplots


def plot_curves(series: Sequence[tuple[str, object, np.ndarray | None]], path: str | os.PathLike, title: str = "",
                xlabel: str = "time (s)", n_joints: int = 3, weights: np.ndarray | None = None) -> Path:
    """The ``n_joints`` most moving joint rotations (degrees from the first motion's mean pose) of each
    ``(label, motion, x)``; ``x`` ``(T,)`` is where each frame goes on the horizontal axis (``None``: seconds).
    The first series is drawn as lines, the others as thinner lines; ``weights`` ``(T,)`` of the first series
    (e.g. a transition's weight of the second take) are drawn in a panel below."""
    from ..cycle.extract import metric_features
    from ..features import pose_matrix
    from ..rotations import mean_rotations

    first = series[0][1]
    ref = mean_rotations(first.rotations)
    names = pose_matrix(first[:1], rep="quatlog", root="drop", reference=ref)[1].columns
    feats = [metric_features(m, ref) for _, m, _ in series]
    cols = np.argsort(np.ptp(feats[0], axis=0))[::-1][:n_joints]
    rows = 2 if weights is not None else 1
    fig, axes = subplots(rows, 1, figsize=(11, 4.2 if rows == 1 else 5.6), squeeze=False, sharex=True,
                         gridspec_kw={"height_ratios": [3, 1][:rows]})
    ax = axes[0, 0]
    styles = ["-", "--", ":", "-."]
    for s, ((label, motion, x), F) in enumerate(zip(series, feats, strict=True)):
        xs = np.arange(motion.n_frames) * motion.frame_time if x is None else np.asarray(x, dtype=float)
        for n, col in enumerate(cols):
            ax.plot(xs, np.degrees(F[:, col]), styles[s % 4], color=f"C{n}", lw=2.0 if s == 0 else 1.2,
                    alpha=1.0 if s == 0 else 0.8, label=f"{names[col]} ({label})")
    ax.set(ylabel="rotation vs mean pose (deg)", title="most moving joint curves")
    ax.legend(fontsize=7, loc="upper right", ncol=max(1, len(series)))
    if weights is not None:
        x0 = series[0][2]
        xs = np.arange(len(weights)) * series[0][1].frame_time if x0 is None else x0
        axes[1, 0].plot(xs, weights, "k-")
        axes[1, 0].set(ylabel="weight of the second", ylim=(-0.05, 1.05))
    axes[-1, 0].set(xlabel=xlabel)
    if title:
        fig.suptitle(title)
    return save(fig, path)
