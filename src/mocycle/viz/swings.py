"""The ``mocycle swings --plot`` figure (paper 003, Figure 16): one row per joint, swings as bars in time."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .figure import save, subplots


def plot_swings(seg, path: str | os.PathLike, title: str = "") -> Path:
    """One row per segmented joint; each swing a bar from its start to its end time (s), coloured by the
    angle it turns through and numbered by its index (0-based in time order, what ``edit --swing`` takes);
    holds as thin grey lines."""
    import matplotlib as mpl

    joints = list(seg.joints)
    dt = seg.frame_time
    fig, ax = subplots(figsize=(11, 0.32 * max(len(joints), 3) + 1.4))
    angles = [abs(np.degrees(s.end_angle - s.start_angle)) for s in seg.swings if s.joint in joints]
    norm = mpl.colors.Normalize(vmin=0, vmax=max(angles) if angles else 1.0)
    cmap = mpl.colormaps["Reds"]
    for row, j in enumerate(joints):
        y = len(joints) - 1 - row
        for h in seg.holds_of(j):
            ax.plot([h.start * dt, h.end * dt], [y, y], color="0.75", lw=1)
        for k, s in enumerate(seg.swings_of(j)):
            turn = abs(np.degrees(s.end_angle - s.start_angle))
            ax.broken_barh([(s.start * dt, max(s.end - s.start, 1) * dt)], (y - 0.35, 0.7),
                           facecolors=cmap(0.25 + 0.75 * norm(turn)), edgecolors="darkred", linewidth=0.4)
            ax.text(0.5 * (s.start + s.end) * dt, y, str(k), ha="center", va="center", fontsize=6)
    ax.set_yticks(range(len(joints)))
    ax.set_yticklabels([seg.skeleton.names[j] for j in reversed(joints)], fontsize=8)
    ax.set_xlim(0, max((seg.n_frames - 1) * dt, dt))
    ax.set_ylim(-0.8, len(joints) - 0.2)
    ax.set(xlabel="time (s); numbers: swing index per joint (edit --swing)",
           title=title or f"{seg.n_swings} swings, Acceptable Swing Error {seg.threshold:g}")
    sm = mpl.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(sm, ax=ax, label="swing angle (deg)", pad=0.01)
    return save(fig, path)
