"""The ``mocycle loop --plot`` figure: input and cycle in PCA, phase per frame, joint curves."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from sklearn.decomposition import PCA

from .figure import save, subplots


def plot_loop(motion, cycle, path: str | os.PathLike, title: str = "", n_joints: int = 3) -> Path:
    """Three panels: 2-D PCA of the input's poses and the closed cycle; the phase of every frame; the
    ``n_joints`` most moving joint curves over two repetitions of the cycle with the input frames on top."""
    from ..cycle.extract import metric_features
    from ..features import pose_matrix
    from ..rotations import mean_rotations

    ref = mean_rotations(motion.rotations)
    Y = metric_features(motion, ref)
    names = pose_matrix(motion[:1], rep="quatlog", root="drop", reference=ref)[1].columns
    C = metric_features(cycle.motion("inplace"), ref)
    frames = cycle.axis.frames()
    fig, (ax_pca, ax_phase, ax_curves) = subplots(1, 3, figsize=(16, 4.6))

    pca = PCA(n_components=2).fit(Y[frames])
    yi, yc = pca.transform(Y), pca.transform(np.vstack([C, C[:1]]))
    ax_pca.plot(yi[:, 0], yi[:, 1], "-", color="0.85", lw=0.6, zorder=0)
    pts = ax_pca.scatter(yi[frames, 0], yi[frames, 1], c=np.mod(cycle.positions / cycle.n_frames, 1), cmap="hsv",
                         s=6, vmin=0, vmax=1, label="input frames")
    ax_pca.plot(yc[:, 0], yc[:, 1], "k-", lw=2, label=f"cycle ({cycle.n_frames} frames)")
    ax_pca.plot(yc[:1, 0], yc[:1, 1], "ko", ms=6)
    fig.colorbar(pts, ax=ax_pca, label="phase")
    ax_pca.set(xlabel="PC 1", ylabel="PC 2", title="poses (PCA): input and cycle")
    ax_pca.legend(fontsize=8, loc="lower right")

    ax_phase.plot(np.arange(len(cycle.periodic.coords)), cycle.periodic.coords, ".", ms=2, color="0.6",
                  label="circular coordinate")
    ax_phase.plot(frames, np.mod(cycle.axis.x[frames], 1.0), ".", ms=2, color="tab:red",
                  label=f"time axis ({cycle.axis.method})")
    for s, e in cycle.axis.regions:
        ax_phase.axvspan(s, e, color="tab:red", alpha=0.06)
    ax_phase.set(xlabel="frame", ylabel="phase (cycles)", ylim=(0, 1),
                 title=f"phase per frame: {cycle.n_periods:.2f} periods of {cycle.period_frames:.1f} frames")
    ax_phase.legend(fontsize=8, loc="upper right")

    spread = np.ptp(Y[frames], axis=0)
    cols = np.argsort(spread)[::-1][:n_joints]
    t2 = np.arange(2 * cycle.n_frames)
    for n, col in enumerate(cols):
        colour = f"C{n}"
        ax_curves.plot(t2, np.degrees(np.tile(C[:, col], 2)), "-", color=colour, lw=2,
                       label=names[col])
        ax_curves.plot(cycle.positions, np.degrees(Y[frames, col]), ".", ms=2, color=colour, alpha=0.5)
        ax_curves.plot(cycle.positions + cycle.n_frames, np.degrees(Y[frames, col]), ".", ms=2, color=colour,
                       alpha=0.5)
    ax_curves.axvline(cycle.n_frames, color="k", lw=0.8, ls="--")
    ax_curves.set(xlabel="cycle frame (two repetitions; dashed: the wrap)", ylabel="rotation vs mean pose (deg)",
                  title=f"{cycle.method}{' ' + cycle.model if cycle.model else ''}: cycle (lines), input (dots)")
    ax_curves.legend(fontsize=8, loc="upper right")
    if title:
        fig.suptitle(title)
    return save(fig, path)
