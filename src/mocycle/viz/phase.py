"""The ``mocycle phase --plot`` figure (paper 001, Figures 3-4)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import MocycleError
from .data import phase_plot_data
from .figure import check_png, save, subplots

COLOURS = ["tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange"]


def plot_phase(result, path: str | os.PathLike, title: str = "") -> Path:
    """Persistence diagram with the chosen classes, coordinate per frame, PCA projection coloured by phase.

    ``result`` must keep its point cloud: ``find_phase(motion, keep_features=True)``.
    """
    check_png(path)
    data = phase_plot_data(result)
    if data["xy"] is None:
        raise MocycleError("plot_phase needs the point cloud: call find_phase(..., keep_features=True)")
    fig, (ax_dgm, ax_phase, ax_pca) = subplots(1, 3, figsize=(15, 4.6))
    bars = data["barcode"]
    if bars.size:
        top = float(np.max(bars)) * 1.05
        ax_dgm.scatter(bars[:, 0], bars[:, 1], s=12, c="0.5", label="H1 bars")
        ax_dgm.plot([0, top], [0, top], "k--", lw=0.8)
        for k, c in enumerate(data["classes"]):
            ax_dgm.scatter([c["birth"]], [c["death"]], s=90, facecolors="none", edgecolors=COLOURS[k % 5], lw=2,
                           label=f"class {k}: period {c['period_frames']:.1f} frames")
        ax_dgm.set_xlim(0, top)
        ax_dgm.set_ylim(0, top)
    ax_dgm.set(xlabel="birth", ylabel="death", title="H1 persistence diagram")
    ax_dgm.legend(fontsize=8, loc="lower right")
    for k, c in enumerate(data["classes"]):
        ax_phase.plot(data["frames"], c["coords"], ".", ms=2, color=COLOURS[k % 5], label=f"class {k}")
        for s, e in c["excitation"]:
            ax_phase.axvspan(s, e, color=COLOURS[k % 5], alpha=0.08)
    ax_phase.set(xlabel="frame", ylabel="circular coordinate (cycles)", ylim=(0, 1),
                 title="coordinate per frame (shaded: excitation)")
    if data["classes"]:
        ax_phase.legend(fontsize=8, loc="upper right")
    xy = data["xy"]
    ax_pca.plot(xy[:, 0], xy[:, 1], "-", color="0.85", lw=0.6, zorder=0)
    points = ax_pca.scatter(xy[:, 0], xy[:, 1], c=data["phase"], cmap="hsv", s=6, vmin=0, vmax=1)
    fig.colorbar(points, ax=ax_pca, label="phase of class 0")
    ax_pca.set(xlabel="PC 1", ylabel="PC 2", title="poses (PCA) coloured by phase")
    if title:
        fig.suptitle(title)
    return save(fig, path)
