"""A compact file of swings (paper 003, section 5.1: compression by storing the segmentation).

Layout of a ``.mosw`` file: the 5 bytes ``b"MOSW\\x01"`` then one zlib stream of

* the skeleton as BVH hierarchy text (length-prefixed UTF-8),
* frames, frame time, threshold and window,
* the segmented joints, the swings column by column (joint, start, length, axis as
  two int16 angles, start angle and angle range as int16, end speeds as float16,
  the base rotation vector as three int16, the axis error as uint8),
* the holds (joint, start, end, mean rotation vector as three int16),
* per joint its translation keys (frames, float32 values).

Angles are quantised to about 1e-4 rad (0.006°), far below the segmentation's
own error.  :func:`size_report` gives the size against the BVH text and
against the raw float32 channels.
"""

from __future__ import annotations

import io
import os
import struct
import warnings
import zlib
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..errors import MocycleError, MocycleWarning, MotionFileError
from ..limits import check_frames, frame_time_problem
from ..motion import Motion
from ..segmentation import MAX_SKELETON_BYTES, Segmentation, checked_segmentation
from .atomic import atomic_write
from .bvh import bvh_size, parse_bvh, skeleton_text
from .inflate import Inflater

MAGIC = b"MOSW\x01"
_PI_Q = 32767.0 / np.pi  # int16 steps per radian for angles within [-π, π]
_RANGE_Q = 32767.0 / (4 * np.pi)  # for a swing's angle range within ±4π


# ---------------------------------------------------------------- packing helpers
def _put(buf: io.BytesIO, arr: ArrayLike, dtype: str) -> None:
    a = np.ascontiguousarray(np.asarray(arr).astype(dtype))
    buf.write(struct.pack("<I", a.size))
    buf.write(a.astype(np.dtype(dtype).newbyteorder("<")).tobytes())


class _Reader:
    """Arrays from a bounded zlib stream: each count is checked against ``limit`` before its bytes are taken."""

    def __init__(self, data: bytes, path):
        self.z = Inflater(data, path, "swings file")
        self.path = path

    def error(self, reason: str) -> MotionFileError:
        return self.z.error(reason)

    def take(self, n: int, purpose: str = "data") -> bytes:
        return self.z.take(n, purpose)

    def unpack(self, fmt: str, purpose: str = "header"):
        return self.z.unpack(fmt, purpose)

    def array(self, dtype: str, limit: int, purpose: str) -> np.ndarray:
        (n,) = self.unpack("<I", purpose)
        if n > limit:
            raise self.error(f"{purpose}: {n:,} values where at most {limit:,} fit the take")
        dt = np.dtype(dtype).newbyteorder("<")
        return np.frombuffer(self.take(n * dt.itemsize, purpose), dtype=dt).astype(dtype)


def _q(x, scale: float, lim: float | None = None) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64) * scale
    return np.clip(np.round(x), -32767, 32767).astype(np.int16)


# ---------------------------------------------------------------- encode / decode
def encode(seg: Segmentation) -> bytes:
    """The compact bytes of ``seg`` (read back with :func:`decode`)."""
    buf = io.BytesIO()
    text = skeleton_text(seg.skeleton).encode("utf-8")
    buf.write(struct.pack("<I", len(text)))
    buf.write(text)
    buf.write(struct.pack("<Idff", seg.n_frames, seg.frame_time, seg.threshold, seg.window_s))
    _put(buf, seg.joints, "u2")
    sw = sorted(seg.swings, key=lambda s: (s.joint, s.start))
    axis = np.array([s.axis for s in sw], dtype=np.float64).reshape(-1, 3)
    start_angle = np.array([s.start_angle for s in sw], dtype=np.float64)
    start_angle = start_angle - 2 * np.pi * np.round(start_angle / (2 * np.pi))
    _put(buf, [s.joint for s in sw], "u2")
    _put(buf, [s.start for s in sw], "u4")
    _put(buf, [s.end - s.start for s in sw], "u4")
    _put(buf, _q(np.arctan2(axis[:, 1], axis[:, 0]), _PI_Q), "i2")
    _put(buf, _q(np.arcsin(np.clip(axis[:, 2], -1, 1)), _PI_Q), "i2")
    _put(buf, _q(start_angle, _PI_Q), "i2")
    _put(buf, _q([s.end_angle - s.start_angle for s in sw], _RANGE_Q), "i2")
    _put(buf, np.clip([s.start_speed for s in sw], -6e4, 6e4), "f2")
    _put(buf, np.clip([s.end_speed for s in sw], -6e4, 6e4), "f2")
    _put(buf, _q(np.array([s.base for s in sw]).reshape(-1, 3), _PI_Q).ravel(), "i2")
    _put(buf, np.clip(np.round(np.array([s.error for s in sw]) * 127), 0, 255), "u1")
    hd = sorted(seg.holds, key=lambda h: (h.joint, h.start))
    _put(buf, [h.joint for h in hd], "u2")
    _put(buf, [h.start for h in hd], "u4")
    _put(buf, [h.end - h.start for h in hd], "u4")
    _put(buf, _q(np.array([h.mean for h in hd]).reshape(-1, 3), _PI_Q).ravel(), "i2")
    tracks = sorted(seg.translation_keys.items())
    _put(buf, [j for j, _ in tracks], "u2")
    for _, (frames, values) in tracks:
        _put(buf, frames, "u4")
        _put(buf, np.asarray(values).ravel(), "f4")
    return MAGIC + zlib.compress(buf.getvalue(), 9)


def decode(data: bytes, path: str | os.PathLike | None = None) -> Segmentation:
    """A :class:`Segmentation` from :func:`encode`'s bytes (quantised values).

    Every count is checked against the take's frames and joints before its bytes are decompressed, and
    every index, length and value after: damage gives one :class:`MotionFileError` naming the file.
    """
    if not data.startswith(MAGIC[:4]):
        raise MotionFileError("not a mocycle swings file (expected it to start with 'MOSW')", path)
    if data[4:5] != MAGIC[4:5]:
        raise MotionFileError(f"swings file version {data[4] if len(data) > 4 else '?'} is not supported "
                              f"(this mocycle reads version {MAGIC[4]})", path)
    r = _Reader(data[5:], path)
    (n_text,) = r.unpack("<I", "the skeleton length")
    if n_text > MAX_SKELETON_BYTES:
        raise r.error(f"its skeleton claims {n_text:,} bytes (at most {MAX_SKELETON_BYTES:,} expected)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MocycleWarning)
            skel = parse_bvh(r.take(n_text, "the skeleton").decode("utf-8"), path="(skeleton)").skeleton
    except (MotionFileError, UnicodeDecodeError) as exc:
        raise r.error(f"its skeleton does not read as BVH ({exc})") from None
    J = skel.n_joints
    n_frames, frame_time, threshold, window_s = r.unpack("<Idff", "the frame count and time")
    if n_frames < 1 or frame_time_problem(frame_time):
        raise r.error(f"{n_frames} frames of {frame_time!r} s (expected >= 1 frame and a positive frame time)")
    if not (np.isfinite(threshold) and np.isfinite(window_s)):
        raise r.error("its threshold or window is not a finite number")
    T = check_frames(n_frames, J, f"a swings file of {n_frames} frames", path)
    events = T * J  # at most one swing (and one hold) per frame and joint
    joints = r.array("u2", J, "segmented joints").astype(int).tolist()
    sj = r.array("u2", events, "swing joints")
    n = sj.size
    ss, sl = r.array("u4", n, "swing starts"), r.array("u4", n, "swing lengths")
    az, el = r.array("i2", n, "swing axes") / _PI_Q, r.array("i2", n, "swing axes") / _PI_Q
    a0, rng = r.array("i2", n, "swing angles") / _PI_Q, r.array("i2", n, "swing angles") / _RANGE_Q
    v0, v1 = r.array("f2", n, "swing speeds").astype(float), r.array("f2", n, "swing speeds").astype(float)
    base = r.array("i2", 3 * n, "swing bases") / _PI_Q
    errs = r.array("u1", n, "swing errors") / 127.0
    hj = r.array("u2", events, "hold joints")
    m = hj.size
    hs, hl = r.array("u4", m, "hold starts"), r.array("u4", m, "hold lengths")
    hm = r.array("i2", 3 * m, "hold rotations") / _PI_Q
    tj = r.array("u2", J, "translated joints")
    keys = {}
    for j in tj.tolist():
        f = r.array("u4", T, "translation key frames").astype(np.int64)
        with np.errstate(invalid="ignore"):  # a signalling NaN in the file: refused below
            v = r.array("f4", 3 * f.size, "translation key values").astype(np.float64)
        keys[int(j)] = (f, v)
    r.z.finish()
    sizes = {"swing": (sj, ss, sl, az, el, a0, rng, v0, v1, errs), "hold": (hj, hs, hl)}
    for what, arrays in sizes.items():
        if any(a.size != arrays[0].size for a in arrays):
            raise r.error(f"its {what} columns differ in length")
    if base.size != 3 * n or hm.size != 3 * m:
        raise r.error("its swing bases or hold rotations differ in length from the swings or holds")
    if np.any(np.diff(tj.astype(np.int64)) <= 0):
        raise r.error(f"its translated joints must be increasing joint numbers below {J}")
    for j, (f, v) in keys.items():
        if v.size != 3 * f.size:
            raise r.error(f"joint {j}'s translation keys: {f.size} frames but {v.size} values")
        keys[j] = (f, v.reshape(-1, 3))
    ss64, hs64 = ss.astype(np.int64), hs.astype(np.int64)
    axis = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    swings = dict(joint=sj.astype(np.int64), start=ss64, end=ss64 + sl, axis=axis, start_angle=a0,
                  end_angle=a0 + rng, start_speed=v0, end_speed=v1, base=base.reshape(-1, 3), error=errs)
    holds = dict(joint=hj.astype(np.int64), start=hs64, end=hs64 + hl, mean=hm.reshape(-1, 3))
    return checked_segmentation(r.error, skel, T, float(frame_time), float(threshold), float(window_s), joints,
                                swings, holds, keys)


def write_swings(seg: Segmentation, path: str | os.PathLike) -> Path:
    """Write the compact swings file (atomically).  Returns the path."""
    try:
        return atomic_write(path, encode(seg))
    except OSError as exc:
        raise MocycleError(f"{path}: cannot write the swings file ({exc.strerror or exc})") from None


def read_swings(path: str | os.PathLike) -> Segmentation:
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None
    return decode(data, path)


def size_report(seg: Segmentation, motion: Motion | None = None) -> dict:
    """Bytes of the compact file against the BVH text and the raw float32 channels.

    ``payload_bytes`` is the compact file without its skeleton (what compares
    with the raw channels, which hold no skeleton either).
    """
    data = encode(seg)
    skel_bytes = len(MAGIC) + len(zlib.compress(skeleton_text(seg.skeleton).encode("utf-8"), 9))
    raw = seg.n_frames * seg.skeleton.n_channels * 4
    bvh = bvh_size(motion) if motion is not None else None
    return dict(
        compressed_bytes=len(data),
        payload_bytes=max(len(data) - skel_bytes, 0),
        raw_float32_bytes=raw,
        bvh_bytes=bvh,
        ratio_raw=len(data) / raw if raw else None,
        payload_ratio_raw=max(len(data) - skel_bytes, 0) / raw if raw else None,
        ratio_bvh=len(data) / bvh if bvh else None,
    )
