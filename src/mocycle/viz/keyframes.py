"""The ``mocycle project --plot`` figure: the thesis' Figure 6.2 view of a take in 2-D.

Every pose is a point coloured by time (red → green → blue), consecutive frames
joined by a thin grey line, keyframes drawn bigger with a black border.  With a
second (optimised) projection the two are drawn side by side (as Figures 5.6-5.11).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.colors import LinearSegmentedColormap

from .data import projection_plot_data
from .figure import check_png, save, subplots

TIME_COLOURS = LinearSegmentedColormap.from_list("time", ["red", "green", "blue"])


def _panel(ax, points: np.ndarray, key_idx: np.ndarray, title: str):
    t = np.arange(len(points))
    ax.plot(points[:, 0], points[:, 1], "-", color="0.8", lw=0.5, zorder=0)
    sc = ax.scatter(points[:, 0], points[:, 1], c=t, cmap=TIME_COLOURS, s=6, zorder=1)
    ax.scatter(points[key_idx, 0], points[key_idx, 1], c=t[key_idx], cmap=TIME_COLOURS, vmin=0,
               vmax=max(len(points) - 1, 1), s=60, edgecolors="black", linewidths=1.2, zorder=2,
               label=f"{len(key_idx)} keyframes")
    ax.set(title=title, xticks=[], yticks=[])
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize=8)
    return sc


def plot_projection(points: np.ndarray, key_idx, path: str | os.PathLike, title: str = "",
                    optimized: np.ndarray | None = None, labels: tuple[str, str] = ("projection", "optimised"),
                    ) -> Path:
    """Write a PNG of the 2-D poses ``points`` ``(T, 2)`` with keyframes ``key_idx``; optionally next to
    ``optimized`` ``(T, 2)``."""
    data = projection_plot_data(points, key_idx, optimized, labels)
    check_png(path)
    panels = data["panels"]
    fig, axes = subplots(1, len(panels), figsize=(6.2 * len(panels), 5.6), squeeze=False)
    sc = None
    for ax, panel in zip(axes[0], panels, strict=True):
        sc = _panel(ax, panel["points"], data["key_idx"], panel["label"])
    fig.colorbar(sc, ax=list(axes[0]), label="frame", shrink=0.8)
    if title:
        fig.suptitle(title)
    return save(fig, path)
