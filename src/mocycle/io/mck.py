"""Keyframe compression (thesis chapter 3) and the ``.mck`` file.

:func:`compress` selects keyframes and, for the spatial scheme, projects every pose
to 2-D (optionally optimising the projection with Algorithm 12); :class:`Compressed`
holds what is needed to rebuild the take and :meth:`Compressed.decompress` rebuilds it.

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

The keyframes come back exactly (same rotations, same translations).
"""

from __future__ import annotations

import io
import json
import os
import struct
import warnings
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleWarning, MotionFileError
from ..io.atomic import atomic_write
from ..io.bvh import bvh_size, format_bvh, parse_bvh
from ..io.inflate import Inflater
from ..keyframes.density import SPATIAL_MIN_KEYS, keyframe_density
from ..keyframes.distance import joint_weights
from ..keyframes.projection import ONE_STEP, PROJECTIONS, PoseSpace, select_keyframes, spatial_layout
from ..keyframes.select import METHODS, keyframe_count
from ..keyframes.spatial import optimize_projection, reconstruct_spatial
from ..keyframes.temporal import SCHEMES as TEMPORAL_SCHEMES
from ..keyframes.temporal import check_keys, interpolate_rotations
from ..limits import check_frames, frame_time_problem
from ..motion import Motion, Skeleton
from ..threads import limit_threads

MAGIC = b"MOCK\x01"
SCHEMES = TEMPORAL_SCHEMES + ("spatial",)


@dataclass(frozen=True, eq=False, kw_only=True)
class Compressed:
    """A take reduced to keyframes (and, for the spatial scheme, a 2-D trajectory).

    Attributes
    ----------
    skeleton, frame_time, n_frames : the take's.
    key_idx : ``(K,)`` keyframe indices; ``key_quats``: ``(K, J, 4)`` their local rotations.
    scheme : ``linear``, ``hermite``, ``slerp``, ``rbf`` or ``spatial``; ``select``: the selector used.
    projection, seed, optimized : the spatial scheme's projection (``seed`` for rbfp/lamp), Algorithm 12 or not.
    points : ``(T, 2)`` 2-D trajectory (spatial scheme) or ``None``.
    track_joints : ``(M,)`` joints whose translation moves; ``track``: ``(T, M, 3)`` their translations
        (float32 precision except at the keyframes); ``static``: ``(J, 3)`` every joint's first-frame translation.
    """

    skeleton: Skeleton
    frame_time: float
    n_frames: int
    key_idx: np.ndarray
    key_quats: np.ndarray
    scheme: str
    select: str
    projection: str | None
    seed: str | None
    optimized: bool
    points: np.ndarray | None
    track_joints: np.ndarray
    track: np.ndarray
    static: np.ndarray

    @property
    def n_keyframes(self) -> int:
        return len(self.key_idx)

    def rotations(self) -> np.ndarray:
        """``(T, J, 4)`` rebuilt local rotations."""
        if self.scheme == "spatial":
            q, _ = reconstruct_spatial(self.key_idx, self.key_quats, self.points)
            return q
        return interpolate_rotations(self.skeleton, self.key_idx, self.key_quats, self.n_frames, self.scheme)

    def decompress(self) -> Motion:
        """The rebuilt take; the keyframes are the original poses.

        Examples
        --------
        >>> import numpy as np
        >>> from mocycle.datasets import synthetic_walk
        >>> walk = synthetic_walk(n_frames=300, fps=60).motion
        >>> packed = compress(walk, ratio=0.03)
        >>> again = packed.decompress()
        >>> again.n_frames, bool(np.allclose(again.rotations[packed.key_idx], walk.rotations[packed.key_idx]))
        (300, True)
        """
        tracks = {int(j): self.track[:, k] for k, j in enumerate(self.track_joints)}  # views: held here anyway
        return Motion(self.skeleton, self.rotations(), self.static, self.frame_time, tracks=tracks,
                      copy=False)  # the rotations were made here

    # ------------------------------------------------------------ bytes
    def to_bytes(self) -> bytes:
        K, J = self.key_quats.shape[:2]
        arrays = {
            "key_idx": self.key_idx.astype("<u4"),
            "key_rotvec": Rotation.from_quat(self.key_quats.reshape(-1, 4)).as_rotvec().reshape(K, J, 3)
            .astype("<f8"),
            "track_joints": self.track_joints.astype("<u2"),
            "key_track": self.track[self.key_idx].astype("<f8"),
            "track": self.track.astype("<f4"),
            "static": self.static.astype("<f8"),
        }
        if self.points is not None:
            arrays["points"] = self.points.astype("<f4")
        header = {
            "skeleton": format_bvh(Motion.rest(self.skeleton, 1)),
            "frame_time": self.frame_time, "n_frames": self.n_frames, "scheme": self.scheme,
            "select": self.select, "projection": self.projection, "seed": self.seed, "optimized": self.optimized,
            "arrays": [[name, a.dtype.str, list(a.shape)] for name, a in arrays.items()],
        }
        buf = io.BytesIO()
        text = json.dumps(header, separators=(",", ":")).encode("utf-8")
        buf.write(struct.pack("<I", len(text)))
        buf.write(text)
        for a in arrays.values():
            buf.write(np.ascontiguousarray(a).tobytes())
        return MAGIC + zlib.compress(buf.getvalue(), 9)

    @classmethod
    def from_bytes(cls, data: bytes, path: str | os.PathLike | None = None) -> Compressed:
        """Read :meth:`to_bytes`'s bytes; every count, shape, index and value is checked (MotionFileError)."""
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
        return cls(skeleton=skeleton, frame_time=h["frame_time"], n_frames=T,
                   key_idx=key_idx, key_quats=key_quats.reshape(K, J, 4), scheme=h["scheme"],
                   select=h["select"], projection=h["projection"], seed=h["seed"],
                   optimized=h["optimized"], points=None if points is None else points.astype(np.float64),
                   track_joints=tj, track=track, static=arrays["static"].astype(np.float64))

    def save(self, path: str | os.PathLike) -> Path:
        """Write the ``.mck`` file atomically."""
        try:
            return atomic_write(path, self.to_bytes())
        except OSError as exc:
            raise MotionFileError(f"cannot write file ({exc.strerror or exc})", path) from None

    # ------------------------------------------------------------ sizes
    def size_report(self, bvh_bytes: int | None = None) -> dict:
        """Real size next to formulas 5.1-5.3 (numbers, header ``h = 0``: the thesis' asymptotic ratios).

        ``m(f) = f(3·dof + 3)``, ``c_t(f) = f(r(3·dof + 1) + 3)``, ``c_skf(f) = f(r(3·dof + 1) + 5)`` with
        ``dof`` the number of joints and ``r`` the keyframe ratio.  ``bvh_bytes`` defaults to the size of
        the rebuilt take written as BVH.
        """
        f, dof = self.n_frames, self.skeleton.n_joints
        r = self.n_keyframes / f
        m = f * (3 * dof + 3)
        c = f * (r * (3 * dof + 1) + (5 if self.scheme == "spatial" else 3))
        real = len(self.to_bytes())
        if bvh_bytes is None:
            bvh_bytes = bvh_size(self.decompress())
        return {"frames": f, "joints": dof, "keyframes": self.n_keyframes, "keyframe_ratio": r,
                "formula_uncompressed_numbers": m, "formula_compressed_numbers": c, "formula_ratio": c / m,
                "compressed_bytes": real, "bvh_bytes": int(bvh_bytes), "real_ratio": real / bvh_bytes}


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
    if frame_time_problem(frame_time):
        raise z.error(frame_time_problem(frame_time))
    scheme = header["scheme"]
    if scheme not in SCHEMES:
        raise z.error(f"unknown scheme {str(scheme)[:40]!r}; expected one of {', '.join(SCHEMES)}")
    if header["select"] not in METHODS:
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



def read_compressed(path: str | os.PathLike) -> Compressed:
    """Read a ``.mck`` file."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None
    return Compressed.from_bytes(data, path)


@limit_threads
def compress(motion: Motion, ratio: float | str | None = "auto", count: int | None = None, select: str = "uniform",
             scheme: str = "slerp", projection: str = "mds", optimize: bool = False, seed: str = "mds",
             random_state: int = 0, space: PoseSpace | None = None) -> Compressed:
    """Keyframe-compress a take.

    Parameters
    ----------
    ratio, count : keyframes as a fraction of the frames (thesis: 3%) or a number (``count`` wins); at least 2.
        ``ratio="auto"`` (default): enough keys for the take's own rhythm (:mod:`.density`: 4 per period, at
        least 3% and 6 keys).  The spatial scheme gets at least 6 keys from any ratio.
    select : ``uniform``, ``scs``, ``pb`` or ``rols``.
    scheme : ``linear``, ``hermite``, ``slerp``, ``rbf`` (temporal) or ``spatial``.
    projection : the spatial scheme's projector (:data:`~mocycle.keyframes.projection.PROJECTIONS`);
        ``seed`` is the first-step projector of ``rbfp`` and ``lamp``.
    optimize : run Algorithm 12 on the 2-D trajectory (spatial scheme).
    space : a :class:`PoseSpace` of ``motion`` whose distances are already computed (saves time).

    Returns
    -------
    Compressed
        ``decompress()`` rebuilds the take, ``save(path)`` writes the ``.mck`` file (also
        ``mocycle.write(packed, "take.mck")``), ``size_report()`` compares sizes.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60).motion
    >>> packed = compress(walk, ratio=0.03, select="uniform", scheme="slerp")
    >>> packed.n_keyframes, packed.key_idx.tolist()
    (9, [0, 37, 75, 112, 150, 187, 224, 262, 299])
    """
    _validate.choice("scheme", scheme, SCHEMES)
    _validate.choice("select", select, METHODS)
    if scheme == "spatial":
        _validate.choice("projection", projection, PROJECTIONS)
    _validate.choice("seed", seed, ONE_STEP)
    n = motion.n_frames
    if count is None and isinstance(ratio, str):
        k = keyframe_density(motion, ratio, scheme).count
    else:
        k = keyframe_count(n, ratio=None if count is not None else ratio, count=count)
        if count is None and scheme == "spatial":
            k = max(k, min(n, SPATIAL_MIN_KEYS))
    space = PoseSpace(motion.rotations, joint_weights(motion.skeleton)) if space is None else space
    points = None
    if scheme == "spatial":
        key, points = spatial_layout(space, projection, select, k, seed=seed, random_state=random_state)
        points = points.astype(np.float32).astype(np.float64)  # what the file stores
        if optimize:
            points = optimize_projection(points, key, motion.rotations, space.weights).points
            points = points.astype(np.float32).astype(np.float64)
    else:
        key = select_keyframes(select, space, k, random_state=random_state)
    key = check_keys(key, n)
    moving = np.array(motion.moving_joints(), dtype=np.int64)
    track = np.empty((n, len(moving), 3))
    for k, j in enumerate(moving):
        track[:, k] = motion.joint_translations(j).astype(np.float32)
        track[key, k] = motion.joint_translations(j)[key]
    return Compressed(skeleton=motion.skeleton, frame_time=motion.frame_time, n_frames=n, key_idx=key,
                      key_quats=motion.rotations[key].copy(), scheme=scheme, select=select,
                      projection=projection if scheme == "spatial" else None,
                      seed=seed if scheme == "spatial" and projection in ("rbfp", "lamp") else None,
                      optimized=bool(optimize and scheme == "spatial"), points=points, track_joints=moving,
                      track=track, static=motion.translations_at(0))
