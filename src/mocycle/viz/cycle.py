"""The ``mocycle loop --plot`` figure: input and cycle in PCA, phase per frame, joint curves."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .data import loop_plot_data
from .figure import check_png, save, subplots


def plot_loop(motion, cycle, path: str | os.PathLike, title: str = "", n_joints: int = 3) -> Path:
    """Three panels: 2-D PCA of the input's poses and the closed cycle; the phase of every frame; the
    ``n_joints`` most moving joint curves over two repetitions of the cycle with the input frames on top."""
    check_png(path)
    d = loop_plot_data(motion, cycle, n_joints)
    frames, N = d["frames"], d["n_frames"]
    fig, (ax_pca, ax_phase, ax_curves) = subplots(1, 3, figsize=(16, 4.6))

    yi, yc = d["input_xy"], d["cycle_xy"]
    ax_pca.plot(yi[:, 0], yi[:, 1], "-", color="0.85", lw=0.6, zorder=0)
    pts = ax_pca.scatter(yi[frames, 0], yi[frames, 1], c=d["input_phase"], cmap="hsv", s=6, vmin=0, vmax=1,
                         label="input frames")
    ax_pca.plot(yc[:, 0], yc[:, 1], "k-", lw=2, label=f"cycle ({N} frames)")
    ax_pca.plot(yc[:1, 0], yc[:1, 1], "ko", ms=6)
    fig.colorbar(pts, ax=ax_pca, label="phase")
    ax_pca.set(xlabel="PC 1", ylabel="PC 2", title="poses (PCA): input and cycle")
    ax_pca.legend(fontsize=8, loc="lower right")

    if d["coords"] is not None:
        ax_phase.plot(np.arange(len(d["coords"])), d["coords"], ".", ms=2, color="0.6", label="circular coordinate")
    ax_phase.plot(frames, d["axis_phase"], ".", ms=2, color="tab:red", label=f"time axis ({d['axis_method']})")
    for s, e in d["regions"]:
        ax_phase.axvspan(s, e, color="tab:red", alpha=0.06)
    ax_phase.set(xlabel="frame", ylabel="phase (cycles)", ylim=(0, 1),
                 title=f"phase per frame: {d['n_periods']:.2f} periods of {d['period_frames']:.1f} frames")
    ax_phase.legend(fontsize=8, loc="upper right")

    t2 = np.arange(2 * N)
    for n, curve in enumerate(d["curves"]):
        colour = f"C{n}"
        ax_curves.plot(t2, curve["cycle_deg"], "-", color=colour, lw=2, label=curve["name"])
        for shift in (0, N):
            ax_curves.plot(d["positions"] + shift, curve["input_deg"], ".", ms=2, color=colour, alpha=0.5)
    ax_curves.axvline(N, color="k", lw=0.8, ls="--")
    ax_curves.set(xlabel="cycle frame (two repetitions; dashed: the wrap)", ylabel="rotation vs mean pose (deg)",
                  title=f"{d['method']}{' ' + d['model'] if d['model'] else ''}: cycle (lines), input (dots)")
    ax_curves.legend(fontsize=8, loc="upper right")
    if title:
        fig.suptitle(title)
    return save(fig, path)
