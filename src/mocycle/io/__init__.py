"""Reading and writing motion files.  Nothing else lives here.

``read(path)`` picks the reader from the file name: ``.bvh``, or ``.amc``
(the ``.asf`` skeleton is then found beside it or given as ``asf=``).
``write(motion, path)`` writes BVH.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import MotionFileError
from ..motion import Motion
from .asfamc import read_amc, read_asf, read_asfamc
from .bvh import parse_bvh, read_bvh, write_bvh

__all__ = ["parse_bvh", "read", "read_amc", "read_asf", "read_asfamc", "read_bvh", "write", "write_bvh"]


def read(path: str | os.PathLike, *, asf: str | os.PathLike | None = None, fps: float = 120.0) -> Motion:
    """Read a motion file (``.bvh``, or ``.amc`` with its ``.asf``) into a :class:`Motion`.

    ``fps`` is used for AMC files only (they do not store it; CMU: 120).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".bvh":
        return read_bvh(p)
    if suffix == ".amc":
        if asf is None:
            candidates = sorted(p.parent.glob("*.asf")) + sorted(p.parent.glob("*.ASF"))
            stem = p.stem.split("_")[0]
            named = [c for c in candidates if c.stem == stem]
            if len(named) == 1:
                asf = named[0]
            elif len(candidates) == 1:
                asf = candidates[0]
            else:
                raise MotionFileError(
                    "cannot tell which .asf skeleton goes with this .amc; pass it explicitly", p
                )
        return read_asfamc(asf, p, fps=fps)
    raise MotionFileError(f"unknown motion file type {suffix or '(none)'!r}; expected .bvh or .amc", p)


def write(motion: Motion, path: str | os.PathLike) -> Path:
    """Write ``motion`` as BVH (the only output format for now)."""
    p = Path(path)
    if p.suffix.lower() != ".bvh":
        raise MotionFileError(f"can only write .bvh files; got {p.suffix or '(no suffix)'!r}", p)
    return write_bvh(motion, p)
