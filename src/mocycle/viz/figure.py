"""Saving matplotlib figures without a screen and without half-written files."""

from __future__ import annotations

import io
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed; must precede pyplot
import matplotlib.pyplot as plt  # noqa: E402

from ..errors import MocycleError  # noqa: E402
from ..io.atomic import atomic_write  # noqa: E402


def save(fig, path: str | os.PathLike, dpi: int = 110) -> Path:
    """Render ``fig`` to PNG in memory, then write it in one step; close the figure."""
    path = Path(path)
    if path.suffix.lower() != ".png":
        plt.close(fig)
        raise MocycleError(f"{path}: plots are written as .png files")
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
    try:
        return atomic_write(path, buf.getvalue())
    except OSError as exc:
        raise MocycleError(f"{path}: cannot write the plot ({exc.strerror or exc})") from None


def subplots(*args, **kwargs):
    return plt.subplots(*args, **kwargs)
