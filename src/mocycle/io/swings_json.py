"""The swings records as JSON (what ``mocycle swings -o FILE.json`` writes), read back with every field checked.

The document is :meth:`~mocycle.swings.Segmentation.to_dict`'s: ``skeleton_bvh`` (BVH hierarchy text),
``frames``, ``frame_time``, ``threshold``, ``window_s``, ``params``, ``joints`` (names), ``swings`` and
``holds`` (lists of records) and ``translation_keys`` (``{"joint": {"frames": [...], "values": [[x, y, z],
...]}}``).  Types are checked before any array is made, sizes against the take (``limits.check_frames``), and
the columns go through the same checks as a ``.mosw`` file (:func:`~mocycle.segmentation.checked_segmentation`):
a damaged document gives one :class:`~mocycle.errors.MotionFileError` naming the file.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..errors import MotionFileError
from ..segmentation import segmentation_from_dict


def read_swings_json(path: str | os.PathLike):
    """The :class:`~mocycle.swings.Segmentation` in a swings JSON file."""
    p = Path(path)
    try:
        text = p.read_bytes()
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", p) from None
    return parse_swings_json(text, p)


def parse_swings_json(text: bytes, path: str | os.PathLike | None = None):
    """The :class:`~mocycle.swings.Segmentation` in the bytes of a swings JSON file; ``path`` names it in
    errors."""
    try:
        data = json.loads(text.decode("utf-8"), parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise MotionFileError(f"not a JSON file ({type(exc).__name__}: {exc})"[:300], path) from None
    if not (isinstance(data, dict) and "skeleton_bvh" in data and "swings" in data):
        raise MotionFileError("not a JSON file mocycle reads: expected the swings records that "
                              "'mocycle swings -o FILE.json' writes (with 'skeleton_bvh' and 'swings')", path)
    return segmentation_from_dict(data, path)


def _no_constant(name: str):
    raise ValueError(f"{name} is not a number")
