"""The ``mocycle swings --plot`` figure (paper 003, Figure 16): one row per joint, swings as bars in time."""

from __future__ import annotations

import os
from pathlib import Path

from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize

from .data import swings_plot_data
from .figure import check_png, save, subplots


def plot_swings(seg, path: str | os.PathLike, title: str = "") -> Path:
    """One row per segmented joint; each swing a bar from its start to its end time (s), coloured by the
    angle it turns through; holds as thin grey lines."""
    check_png(path)
    data = swings_plot_data(seg)
    rows = data["rows"]
    fig, ax = subplots(figsize=(11, 0.32 * max(len(rows), 3) + 1.4))
    norm = Normalize(vmin=0, vmax=data["max_turn_deg"])
    cmap = colormaps["Reds"]
    for i, row in enumerate(rows):
        y = len(rows) - 1 - i
        for h in row["holds"]:
            ax.plot([h["start_s"], h["end_s"]], [y, y], color="0.75", lw=1)
        for s in row["swings"]:
            ax.broken_barh([(s["start_s"], s["duration_s"])], (y - 0.35, 0.7),
                           facecolors=cmap(0.25 + 0.75 * norm(s["turn_deg"])), edgecolors="darkred", linewidth=0.4)
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels([r["name"] for r in reversed(rows)], fontsize=8)
    ax.set_xlim(0, data["duration_s"])
    ax.set_ylim(-0.8, len(rows) - 0.2)
    ax.set(xlabel="time (s)",
           title=title or f"{data['n_swings']} swings, Acceptable Swing Error {data['threshold']:g}")
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="swing angle (deg)", pad=0.01)
    return save(fig, path)
