"""The ``.mck`` keyframe file: bytes to and from the fields of a keyframe-compressed take.

Layout of a ``.mck`` file: the 5 bytes ``b"MOCK\\x01"`` then one zlib stream of a
length-prefixed UTF-8 JSON header (the skeleton as a one-frame rest-pose BVH text, frame count
and time, scheme, selection, projection, array shapes) followed by the arrays:

* keyframe indices (uint32),
* keyframe rotations as rotation vectors (float64, 3 numbers per joint, the ``3·dof``
  of formulas 5.2-5.3; they decode back to the same rotation within 1e-15),
* the translations of the joints whose translation moves: exact at the keyframes
  (float64) and for every frame as float32 (the ``+3`` per frame of formulas 5.2-5.3;
  the thesis stores the root trajectory and rebuilds only rotations),
* for the spatial scheme the 2-D point of every frame (float32, the ``+2`` of 5.3).

The keyframes come back exactly (same rotations, same translations).  The take itself, how it is
made and how its frames are rebuilt, is :mod:`mocycle.keyframes.compressed`'s (:func:`compress`,
:class:`Compressed`, :func:`read_compressed`); this module only encodes and decodes, and imports nothing
from there (io sits below every algorithm).
"""

from __future__ import annotations

import io
import json
import os
import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..defaults import KEY_SCHEMES as SCHEMES
from ..defaults import KEY_SELECTIONS, PROJECTIONS
from ..defaults import ONE_STEP_PROJECTIONS as ONE_STEP
from ..errors import MocycleWarning, MotionFileError
from ..limits import check_frames, frame_time_problem
from ..motion import Motion
from .atomic import atomic_write
from .bvh import format_bvh, parse_bvh
from .inflate import Inflater

MAGIC = b"MOCK\x01"


def encode(packed) -> bytes:
    """The bytes of a ``.mck`` file holding ``packed`` (a :class:`~mocycle.keyframes.Compressed`: its fields are
    read, nothing is computed)."""
    K, J = packed.key_quats.shape[:2]
    arrays = {
        "key_idx": packed.key_idx.astype("<u4"),
        "key_rotvec": Rotation.from_quat(packed.key_quats.reshape(-1, 4)).as_rotvec().reshape(K, J, 3)
        .astype("<f8"),
        "track_joints": packed.track_joints.astype("<u2"),
        "key_track": packed.track[packed.key_idx].astype("<f8"),
        "track": packed.track.astype("<f4"),
        "static": packed.static.astype("<f8"),
    }
    if packed.points is not None:
        arrays["points"] = packed.points.astype("<f4")
    header = {
        "skeleton": format_bvh(Motion.rest(packed.skeleton, 1)),
        "frame_time": packed.frame_time, "n_frames": packed.n_frames, "scheme": packed.scheme,
        "select": packed.select, "projection": packed.projection, "seed": packed.seed, "optimized": packed.optimized,
        "arrays": [[name, a.dtype.str, list(a.shape)] for name, a in arrays.items()],
    }
    buf = io.BytesIO()
    text = json.dumps(header, separators=(",", ":")).encode("utf-8")
    buf.write(struct.pack("<I", len(text)))
    buf.write(text)
    for a in arrays.values():
        buf.write(np.ascontiguousarray(a).tobytes())
    return MAGIC + zlib.compress(buf.getvalue(), 9)


def decode(data: bytes, path: str | os.PathLike | None = None) -> dict:
    """The fields of the take in :func:`encode`'s bytes, as keyword arguments of
    :class:`~mocycle.keyframes.Compressed`; every count, shape, index and value is checked (a damaged file
    raises :class:`~mocycle.errors.MotionFileError` naming ``path``)."""
    if not data.startswith(MAGIC):
        raise MotionFileError(f"not a mocycle keyframe file (expected it to start with {MAGIC!r})", path)
    z = Inflater(data[len(MAGIC):], path, "keyframe file")
    (n,) = z.unpack("<I", "the header length")
    if n > MAX_HEADER_BYTES:
        raise z.error(f"its header claims {n:,} bytes (at most {MAX_HEADER_BYTES:,} expected)")
    text = z.take(n, "the header")
    try:
        header = json.loads(text.decode("utf-8"), parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise z.error(f"its header is not valid UTF-8 JSON ({type(exc).__name__})") from None
    h = _check_header(header, z)
    skeleton = h["skeleton"]
    T, J = h["n_frames"], skeleton.n_joints
    shapes = dict(header_shapes(header, z))
    key_shape, track_shape = shapes.get("key_idx", ("", ()))[1], shapes.get("track_joints", ("", ()))[1]
    K = key_shape[0] if len(key_shape) == 1 else -1
    M = track_shape[0] if len(track_shape) == 1 else -1
    expected = {"key_idx": ("<u4", (K,)), "key_rotvec": ("<f8", (K, J, 3)), "track_joints": ("<u2", (M,)),
                "key_track": ("<f8", (K, M, 3)), "track": ("<f4", (T, M, 3)), "static": ("<f8", (J, 3))}
    if h["scheme"] == "spatial":
        expected["points"] = ("<f4", (T, 2))
    if list(shapes) != list(expected) or any(shapes[k] != (dt, shape) for k, (dt, shape) in expected.items()):
        got = ", ".join(f"{k} {dt}{list(sh)}" for k, (dt, sh) in shapes.items())
        want = ", ".join(f"{k} {dt}{list(sh)}" for k, (dt, sh) in expected.items())
        raise z.error(f"its arrays do not fit {T} frames of {J} joints: expected {want}; found {got}")
    check_frames(T, J, f"'n_frames: {T}'", path)
    arrays = {}
    for name, (dt, shape) in expected.items():
        size = int(np.prod(shape)) * np.dtype(dt).itemsize
        arrays[name] = np.frombuffer(z.take(size, name), dtype=dt).reshape(shape)
    z.finish()
    key_idx = arrays["key_idx"].astype(np.int64)
    if K < 2 or key_idx[0] != 0 or key_idx[-1] != T - 1 or np.any(np.diff(key_idx) <= 0):
        raise z.error(f"its {K} keyframe indices must increase from frame 0 to frame {T - 1}")
    tj = arrays["track_joints"].astype(np.int64)
    if np.any(tj >= J) or np.any(np.diff(tj) <= 0):
        raise z.error(f"its moving joints must be increasing joint numbers below {J}")
    for name, a in arrays.items():
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            raise z.error(f"{name} holds NaN or infinite values")
        if a.dtype.kind == "f" and a.size and np.abs(a).max() > MAX_VALUE:
            raise z.error(f"{name} holds values beyond ±{MAX_VALUE:g}")
    with np.errstate(all="ignore"):
        key_quats = Rotation.from_rotvec(arrays["key_rotvec"].reshape(-1, 3).astype(np.float64)).as_quat()
    track = arrays["track"].astype(np.float64)
    track[key_idx] = arrays["key_track"]
    points = arrays.get("points")
    return dict(skeleton=skeleton, frame_time=h["frame_time"], n_frames=T,
                key_idx=key_idx, key_quats=key_quats.reshape(K, J, 4), scheme=h["scheme"],
                select=h["select"], projection=h["projection"], seed=h["seed"],
                optimized=h["optimized"], points=None if points is None else points.astype(np.float64),
                track_joints=tj, track=track, static=arrays["static"].astype(np.float64))


#: The longest JSON header a ``.mck`` file may have (the skeleton text of ~100k joints fits).
MAX_HEADER_BYTES = 64 * 2**20
#: The largest magnitude a stored number may have (angles, file units, 2-D points): far above any take,
#: far below where squares overflow.
MAX_VALUE = 1e12


def _no_constant(name: str):
    raise ValueError(f"{name} is not a number")


def header_shapes(header: dict, z: Inflater):
    """``(name, (dtype, shape))`` of each array the header lists (checked: names, dtypes, small shapes)."""
    arrays = header.get("arrays")
    if not isinstance(arrays, list) or len(arrays) > 16:
        raise z.error("its header has no list of arrays")
    seen = set()
    for item in arrays:
        ok = (isinstance(item, list) and len(item) == 3 and isinstance(item[0], str) and isinstance(item[1], str)
              and isinstance(item[2], list) and len(item[2]) <= 4
              and all(type(d) is int and 0 <= d < 2**40 for d in item[2]))
        if not ok or item[0] in seen:
            raise z.error(f"its header lists a bad array entry {str(item)[:80]!r}")
        seen.add(item[0])
        yield item[0], (item[1], tuple(item[2]))


def _check_header(header, z: Inflater) -> dict:
    """The header's fields, checked: skeleton, frame count and time, scheme and options."""
    if not isinstance(header, dict):
        raise z.error("its header is not a JSON object")
    missing = [k for k in ("skeleton", "frame_time", "n_frames", "scheme", "select", "projection", "seed",
                           "optimized", "arrays") if k not in header]
    if missing:
        raise z.error(f"its header lacks {', '.join(missing)}")
    n_frames, frame_time = header["n_frames"], header["frame_time"]
    if type(n_frames) is not int or n_frames < 2:
        raise z.error(f"n_frames must be a whole number >= 2; found {str(n_frames)[:40]!r}")
    if type(frame_time) not in (int, float):
        raise z.error(f"frame_time must be a number of seconds; found {str(frame_time)[:40]!r}")
    problem = frame_time_problem(frame_time)
    if problem:
        raise z.error(problem)
    scheme = header["scheme"]
    if scheme not in SCHEMES:
        raise z.error(f"unknown scheme {str(scheme)[:40]!r}; expected one of {', '.join(SCHEMES)}")
    if header["select"] not in KEY_SELECTIONS:
        raise z.error(f"unknown keyframe selection {str(header['select'])[:40]!r}")
    projection, seed = header["projection"], header["seed"]
    if projection is not None and projection not in PROJECTIONS or seed is not None and seed not in ONE_STEP:
        raise z.error(f"unknown projection {str(projection)[:40]!r} or seed {str(seed)[:40]!r}")
    if not isinstance(header["optimized"], bool):
        raise z.error("optimized must be true or false")
    text = header["skeleton"]
    if not isinstance(text, str):
        raise z.error("its skeleton is not BVH text")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MocycleWarning)
            skeleton = parse_bvh(text, path="(skeleton)").skeleton
    except MotionFileError as exc:
        raise z.error(f"its skeleton does not read as BVH ({exc})") from None
    return {"skeleton": skeleton, "n_frames": n_frames, "frame_time": float(frame_time), "scheme": scheme,
            "select": header["select"], "projection": projection, "seed": seed,
            "optimized": header["optimized"]}


def read_bytes(path: str | os.PathLike) -> bytes:
    """The bytes of a ``.mck`` file (a missing or unreadable file: MotionFileError)."""
    try:
        return Path(path).read_bytes()
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None


def write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write :func:`encode`'s bytes atomically."""
    try:
        return atomic_write(path, data)
    except OSError as exc:
        raise MotionFileError(f"cannot write file ({exc.strerror or exc})", path) from None

