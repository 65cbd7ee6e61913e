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
import zlib
from pathlib import Path

import numpy as np

from ..errors import MocycleError, MotionFileError
from ..io.atomic import atomic_write
from ..io.bvh import format_bvh, parse_bvh
from ..motion import Motion, Skeleton
from ..swings.segment import Hold, Segmentation, Swing

MAGIC = b"MOSW\x01"
_PI_Q = 32767.0 / np.pi  # int16 steps per radian for angles within [-π, π]
_RANGE_Q = 32767.0 / (4 * np.pi)  # for a swing's angle range within ±4π


# ---------------------------------------------------------------- skeleton as text
def skeleton_text(skeleton: Skeleton) -> str:
    """The BVH text of the skeleton's rest pose (one frame), from which :func:`skeleton_from_text` rebuilds it."""
    return format_bvh(Motion.rest(skeleton, 1))


def skeleton_from_text(text: str) -> Skeleton:
    return parse_bvh(text).skeleton


# ---------------------------------------------------------------- packing helpers
def _put(buf: io.BytesIO, arr: np.ndarray, dtype: str) -> None:
    a = np.ascontiguousarray(np.asarray(arr).astype(dtype))
    buf.write(struct.pack("<I", a.size))
    buf.write(a.astype(np.dtype(dtype).newbyteorder("<")).tobytes())


class _Reader:
    def __init__(self, data: bytes, path):
        self.data, self.pos, self.path = data, 0, path

    def take(self, n: int) -> bytes:
        if self.pos + n > len(self.data):
            raise MotionFileError("swings file is truncated", self.path)
        out = self.data[self.pos:self.pos + n]
        self.pos += n
        return out

    def unpack(self, fmt: str):
        return struct.unpack(fmt, self.take(struct.calcsize(fmt)))

    def array(self, dtype: str) -> np.ndarray:
        (n,) = self.unpack("<I")
        dt = np.dtype(dtype).newbyteorder("<")
        return np.frombuffer(self.take(n * dt.itemsize), dtype=dt).astype(dtype)


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
    """A :class:`Segmentation` from :func:`encode`'s bytes (quantised values)."""
    if not data.startswith(MAGIC[:4]):
        raise MotionFileError("not a mocycle swings file (expected it to start with 'MOSW')", path)
    if data[4:5] != MAGIC[4:5]:
        raise MotionFileError(f"swings file version {data[4] if len(data) > 4 else '?'} is not supported "
                              f"(this mocycle reads version {MAGIC[4]})", path)
    try:
        raw = zlib.decompress(data[5:])
    except zlib.error:
        raise MotionFileError("swings file is damaged (its compressed data does not decode)", path) from None
    r = _Reader(raw, path)
    (n_text,) = r.unpack("<I")
    skel = skeleton_from_text(r.take(n_text).decode("utf-8"))
    n_frames, frame_time, threshold, window_s = r.unpack("<Idff")
    joints = r.array("u2").astype(int).tolist()
    names = skel.names
    sj, ss, sl = r.array("u2"), r.array("u4"), r.array("u4")
    az, el = r.array("i2") / _PI_Q, r.array("i2") / _PI_Q
    a0, rng = r.array("i2") / _PI_Q, r.array("i2") / _RANGE_Q
    v0, v1 = r.array("f2").astype(float), r.array("f2").astype(float)
    base = (r.array("i2") / _PI_Q).reshape(-1, 3)
    errs = r.array("u1") / 127.0
    axis = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    hj, hs, hl = r.array("u2"), r.array("u4"), r.array("u4")
    hm = (r.array("i2") / _PI_Q).reshape(-1, 3)
    tj = r.array("u2")
    keys = {}
    for j in tj.tolist():
        f = r.array("u4").astype(np.int64)
        keys[int(j)] = (f, r.array("f4").astype(np.float64).reshape(-1, 3))
    if max([*sj.tolist(), *hj.tolist(), *joints, -1]) >= skel.n_joints:
        raise MotionFileError("swings file names a joint the skeleton does not have", path)
    swings = [Swing(joint=int(sj[i]), name=names[sj[i]], start=int(ss[i]), end=int(ss[i] + sl[i]),
                    axis=tuple(float(x) for x in axis[i]), start_angle=float(a0[i]),
                    end_angle=float(a0[i] + rng[i]), start_speed=float(v0[i]), end_speed=float(v1[i]),
                    base=tuple(float(x) for x in base[i]), error=float(errs[i])) for i in range(sj.size)]
    holds = [Hold(joint=int(hj[i]), name=names[hj[i]], start=int(hs[i]), end=int(hs[i] + hl[i]),
                  mean=tuple(float(x) for x in hm[i])) for i in range(hj.size)]
    return Segmentation(skeleton=skel, n_frames=int(n_frames), frame_time=float(frame_time), joints=joints,
                        swings=swings, holds=holds, translation_keys=keys, threshold=float(threshold),
                        window_s=float(window_s))


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
    bvh = len(format_bvh(motion).encode("utf-8")) if motion is not None else None
    return dict(
        compressed_bytes=len(data),
        payload_bytes=max(len(data) - skel_bytes, 0),
        raw_float32_bytes=raw,
        bvh_bytes=bvh,
        ratio_raw=len(data) / raw if raw else None,
        payload_ratio_raw=max(len(data) - skel_bytes, 0) / raw if raw else None,
        ratio_bvh=len(data) / bvh if bvh else None,
    )
