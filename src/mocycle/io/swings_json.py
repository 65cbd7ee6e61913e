"""The swings records as JSON (what ``mocycle swings -o FILE.json`` writes), read back with every field checked.

The document (:func:`swings_document`) is :meth:`~mocycle.swings.Segmentation.to_dict`'s values and
``skeleton_bvh`` (BVH hierarchy text):
``frames``, ``frame_time``, ``threshold``, ``window_s``, ``params``, ``joints`` (names), ``swings`` and
``holds`` (lists of records) and ``translation_keys`` (``{"joint": {"frames": [...], "values": [[x, y, z],
...]}}``).  Types are checked before any array is made, sizes against the take (``limits.check_frames``), and
the columns go through the same checks as a ``.mosw`` file (:func:`~mocycle.segmentation.checked_segmentation`):
a damaged document gives one :class:`~mocycle.errors.MotionFileError` naming the file.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import numpy as np

from ..errors import MocycleWarning, MotionFileError
from ..limits import check_frames, frame_time_problem
from ..segmentation import MAX_SKELETON_BYTES, Segmentation, checked_segmentation
from .bvh import bvh_skeleton, parse_bvh, skeleton_text


def swings_document(seg: Segmentation) -> dict:
    """The swings JSON document of ``seg`` (JSON-ready values; :func:`segmentation_from_dict` reads it back)."""
    # names BVH cannot hold changed (one warning), here and in "joints"; spaces kept (mocycle reads this text)
    skeleton = bvh_skeleton(seg.skeleton, one_word=False)
    return {**seg.to_dict(), "joints": [skeleton.names[j] for j in seg.joints],
            "skeleton_bvh": skeleton_text(skeleton)}


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


_SWING_INTS = ("joint", "start", "end")
_SWING_FLOATS = ("start_angle", "end_angle", "start_speed", "end_speed", "error")
_SWING_VECTORS = ("axis", "base")
_HOLD_INTS = ("joint", "start", "end")


def segmentation_from_dict(d: dict, path: str | os.PathLike | None = None) -> Segmentation:
    """A checked :class:`Segmentation` from a swings JSON document (:func:`swings_document`); ``path`` names the
    file in the error.  Types are checked before any array is made, sizes against the take
    (:func:`~mocycle.limits.check_frames`), and the columns by :func:`checked_segmentation`, as a ``.mosw``
    file's are."""

    def error(reason: str) -> MotionFileError:
        return MotionFileError(f"swings JSON is damaged: {reason}", path)

    if not isinstance(d, dict):
        raise error(f"expected an object; got {type(d).__name__}")
    text = _field(d, "skeleton_bvh", str, error)
    if len(text) > MAX_SKELETON_BYTES:
        raise error(f"its skeleton has {len(text):,} characters (at most {MAX_SKELETON_BYTES:,} expected)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MocycleWarning)
            skel = parse_bvh(text, path="(skeleton)").skeleton
    except MotionFileError as exc:
        raise error(f"its skeleton does not read as BVH ({exc})") from None
    J = skel.n_joints
    n_frames = _field(d, "frames", int, error)
    frame_time, threshold, window_s = (_field(d, k, float, error) for k in ("frame_time", "threshold", "window_s"))
    if n_frames < 1 or frame_time_problem(frame_time):
        raise error(f"{n_frames} frames of {frame_time!r} s (expected >= 1 frame and a positive frame time)")
    if not (np.isfinite(threshold) and np.isfinite(window_s)):
        raise error("its threshold or window is not a finite number")
    T = check_frames(n_frames, J, f"a swings file of {n_frames} frames", path)
    params = d.get("params", {})
    if not (isinstance(params, dict) and all(isinstance(v, (int, float, str, bool)) for v in params.values())):
        raise error("'params' must be an object of numbers and strings")
    names = _field(d, "joints", list, error)
    if not all(isinstance(n, str) and n in skel.names for n in names):
        raise error("'joints' must name joints of its skeleton")
    joints = [skel.names.index(n) for n in names]
    swings = _columns(_field(d, "swings", list, error), "swing", _SWING_INTS, _SWING_FLOATS, _SWING_VECTORS,
                      T * J, error)
    holds = _columns(_field(d, "holds", list, error), "hold", _HOLD_INTS, (), ("mean",), T * J, error)
    raw_keys = _field(d, "translation_keys", dict, error)
    if len(raw_keys) > J:
        raise error(f"{len(raw_keys)} translated joints; the skeleton has {J}")
    keys = {}
    for name, entry in raw_keys.items():
        if not (isinstance(name, str) and name.isdigit() and len(name) < 10 and isinstance(entry, dict)):
            raise error(f"translation keys must be joint numbers with frames and values; got {name!r}")
        frames = _field(entry, "frames", list, error)
        values = _field(entry, "values", list, error)
        if len(frames) > T or len(values) != len(frames):
            raise error(f"joint {name}'s translation keys: {len(frames)} frames and {len(values)} values "
                        f"(at most {T} expected, one value per frame)")
        keys[int(name)] = (_numbers(frames, f"joint {name}'s translation key frames", None, error, integers=True),
                           _numbers(values, f"joint {name}'s translation values", 3, error))
    return checked_segmentation(error, skel, T, frame_time, threshold, window_s, joints, swings, holds, keys,
                                params=params)


def _field(d: dict, key: str, kind: type, error):
    """``d[key]`` of type ``kind`` (``float`` takes an int too; ``int`` takes no bool)."""
    if key not in d:
        raise error(f"the field '{key}' is missing")
    v = d[key]
    if kind is float and isinstance(v, int) and not isinstance(v, bool):
        try:
            return float(v)
        except OverflowError:
            raise error(f"'{key}' is too large") from None
    if not isinstance(v, kind) or isinstance(v, bool):
        raise error(f"'{key}' must be {_KIND_NAMES[kind]}; got {type(v).__name__}")
    return v


_KIND_NAMES = {int: "an integer", float: "a number", str: "a string", list: "a list", dict: "an object"}


def _numbers(values: list, what: str, width: int | None, error, integers: bool = False) -> np.ndarray:
    """``values`` (a list of numbers, or of ``width``-lists of numbers) as float64 ``(n,)`` or ``(n, width)``,
    or int64 when ``integers`` (integral values within ±2^53)."""
    ok = (int, float)
    if width is None:
        good = all(type(v) in ok for v in values)
    else:
        good = all(type(v) in (list, tuple) and len(v) == width and all(type(x) in ok for x in v) for v in values)
    if not good:
        shape = "numbers" if width is None else f"lists of {width} numbers"
        raise error(f"{what} must be {shape}")
    try:
        a = np.array(values, dtype=np.float64).reshape((len(values),) if width is None else (len(values), width))
    except OverflowError:
        raise error(f"{what}: a number is too large") from None
    if integers:
        if not np.all(np.isfinite(a)) or np.any(np.abs(a) > 2.0**53) or np.any(a != np.round(a)):
            raise error(f"{what} must be whole numbers")
        return a.astype(np.int64)
    return a


def _columns(records: list, what: str, ints, floats, vectors, limit: int, error) -> dict:
    """The records' fields as columns (``(n,)`` int64 or float64, ``(n, 3)`` for the vectors)."""
    if len(records) > limit:
        raise error(f"{len(records):,} {what}s where at most {limit:,} fit the take")
    if not all(isinstance(r, dict) for r in records):
        raise error(f"every {what} must be an object")
    out = {}
    for name in (*ints, *floats, *vectors):
        try:
            values = [r[name] for r in records]
        except KeyError:
            raise error(f"a {what} has no '{name}'") from None
        out[name] = _numbers(values, f"the {what}s' '{name}'", 3 if name in vectors else None, error,
                             integers=name in ints)
    return out
