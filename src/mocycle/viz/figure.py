"""Drawing figures without a screen and without half-written files.

Figures are :class:`matplotlib.figure.Figure` objects made directly, not through
``pyplot``: nothing here selects a backend (``matplotlib.use``) or registers a
window, so importing mocycle inside Blender or Jupyter leaves their backend alone.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

from matplotlib.figure import Figure

from ..errors import MocycleError
from ..io.atomic import atomic_write


def check_png(path: str | os.PathLike) -> Path:
    """Refuse a plot path that is not a ``.png`` file (before anything is drawn)."""
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise MocycleError(f"{path}: plots are written as .png files")
    return path


def save(fig: Figure, path: str | os.PathLike, dpi: int = 110) -> Path:
    """Render ``fig`` to PNG in memory, then write it in one step."""
    path = check_png(path)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    try:
        return atomic_write(path, buf.getvalue())
    except OSError as exc:
        raise MocycleError(f"{path}: cannot write the plot ({exc.strerror or exc})") from None


def subplots(nrows: int = 1, ncols: int = 1, *, figsize: tuple[float, float] | None = None, **kwargs):
    """A new :class:`Figure` and its axes, like ``pyplot.subplots`` but outside pyplot's state."""
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols, **kwargs)
