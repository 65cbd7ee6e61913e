"""``mocycle.read`` and ``mocycle.write``: every file mocycle reads or writes, chosen by its suffix.

:mod:`mocycle.io` reads and writes the files whose contents are records below it (motions, swing
segmentations) and encodes and decodes the others; it imports no algorithm.  A ``.mck`` file holds a
keyframe-compressed take, a :class:`~mocycle.keyframes.Compressed`, which rebuilds its frames with the
keyframe algorithms: this module, above both, makes it from the bytes :mod:`mocycle.io.mck` decodes
(:func:`mocycle.keyframes.read_compressed`).  Everything else goes to :func:`mocycle.io.read` and
:func:`mocycle.io.write` (the suffix table is there).
"""

from __future__ import annotations

import os
from pathlib import Path

from .io import AMC_FPS, write
from .io import read as _read

__all__ = ["read", "write"]


def read(path: str | os.PathLike, *, asf: str | os.PathLike | None = None, fps: float = AMC_FPS,
         take: str | None = None, sample_fps: float | None = None):
    """Read any file mocycle writes, chosen by its suffix: :func:`mocycle.io.read`, and a
    :class:`~mocycle.keyframes.Compressed` take for ``.mck`` (``.decompress()`` gives the motion).

    Examples
    --------
    >>> import mocycle, tempfile, pathlib
    >>> from mocycle.datasets import synthetic_walk
    >>> from mocycle.keyframes import compress
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> packed = compress(synthetic_walk(n_frames=120, fps=60).motion, count=6)
    >>> mocycle.read(mocycle.write(packed, folder / "walk.mck")).decompress().n_frames
    120
    """
    p = Path(path)
    if p.suffix.lower() == ".mck" and not p.is_dir():
        from .keyframes.compressed import read_compressed

        return read_compressed(p)
    return _read(p, asf=asf, fps=fps, take=take, sample_fps=sample_fps)
