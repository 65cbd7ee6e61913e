"""Joint curves of several motions on one axis: the ``--plot`` of ``blend``, ``transition`` and ``stretch``."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .data import curves_plot_data
from .figure import check_png, save, subplots


def plot_curves(series: Sequence[tuple[str, object, np.ndarray | None]], path: str | os.PathLike, title: str = "",
                xlabel: str = "time (s)", n_joints: int = 3, weights: np.ndarray | None = None) -> Path:
    """The most moving joint rotations of each ``(label, motion, x)`` (see :func:`~.data.curves_plot_data`);
    the first series as thick lines, the others dashed or dotted; ``weights`` ``(T,)`` of the first series
    (e.g. a transition's weight of the second take) in a panel below."""
    check_png(path)
    data = curves_plot_data(series, n_joints)
    rows = 2 if weights is not None else 1
    fig, axes = subplots(rows, 1, figsize=(11, 4.2 if rows == 1 else 5.6), squeeze=False, sharex=True,
                         gridspec_kw={"height_ratios": [3, 1][:rows]})
    ax = axes[0, 0]
    styles = ["-", "--", ":", "-."]
    for s, item in enumerate(data["series"]):
        for n, name in enumerate(data["names"]):
            ax.plot(item["x"], item["degrees"][:, n], styles[s % 4], color=f"C{n}", lw=2.0 if s == 0 else 1.2,
                    alpha=1.0 if s == 0 else 0.8, label=f"{name} ({item['label']})")
    ax.set(ylabel="rotation vs mean pose (deg)", title="most moving joint curves")
    ax.legend(fontsize=7, loc="upper right", ncol=max(1, len(data["series"])))
    if weights is not None:
        axes[1, 0].plot(data["series"][0]["x"], weights, "k-")
        axes[1, 0].set(ylabel="weight of the second", ylim=(-0.05, 1.05))
    axes[-1, 0].set(xlabel=xlabel)
    if title:
        fig.suptitle(title)
    return save(fig, path)
