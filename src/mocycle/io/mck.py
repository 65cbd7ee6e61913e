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
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import MocycleError, MotionFileError
from ..io.atomic import atomic_write
from ..io.bvh import format_bvh, parse_bvh
from ..keyframes.density import SPATIAL_MIN_KEYS, keyframe_density
from ..keyframes.distance import joint_weights
from ..keyframes.projection import ONE_STEP, PROJECTIONS, PoseSpace, select_keyframes, spatial_layout
from ..keyframes.select import METHODS, keyframe_count
from ..keyframes.spatial import optimize_projection, reconstruct_spatial
from ..keyframes.temporal import SCHEMES as TEMPORAL_SCHEMES
from ..keyframes.temporal import check_keys, interpolate_rotations
from ..motion import Motion, Skeleton

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
        trans = np.broadcast_to(self.static, (self.n_frames,) + self.static.shape).copy()
        trans[:, self.track_joints] = self.track
        return Motion(self.skeleton, self.rotations(), trans, self.frame_time)

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
        if not data.startswith(MAGIC):
            raise MotionFileError(f"not a mocycle keyframe file (expected it to start with {MAGIC!r})", path)
        try:
            raw = zlib.decompress(data[len(MAGIC):])
            (n,) = struct.unpack("<I", raw[:4])
            header = json.loads(raw[4: 4 + n].decode("utf-8"))
            pos = 4 + n
            arrays = {}
            for name, dtype, shape in header["arrays"]:
                dt = np.dtype(dtype)
                size = int(np.prod(shape)) * dt.itemsize
                if pos + size > len(raw):
                    raise ValueError("truncated")
                arrays[name] = np.frombuffer(raw[pos: pos + size], dtype=dt).reshape(shape)
                pos += size
            skeleton = parse_bvh(header["skeleton"]).skeleton
        except (zlib.error, ValueError, KeyError, TypeError, struct.error, UnicodeDecodeError) as exc:
            raise MotionFileError(f"keyframe file is damaged or truncated ({exc})", path) from None
        K = len(arrays["key_idx"])
        key_quats = Rotation.from_rotvec(arrays["key_rotvec"].reshape(-1, 3).astype(np.float64)).as_quat()
        key_idx = arrays["key_idx"].astype(np.int64)
        track = arrays["track"].astype(np.float64)
        track[key_idx] = arrays["key_track"]
        points = arrays.get("points")
        return cls(skeleton=skeleton, frame_time=float(header["frame_time"]), n_frames=int(header["n_frames"]),
                   key_idx=key_idx, key_quats=key_quats.reshape(K, skeleton.n_joints, 4), scheme=header["scheme"],
                   select=header["select"], projection=header["projection"], seed=header["seed"],
                   optimized=bool(header["optimized"]), points=None if points is None else points.astype(np.float64),
                   track_joints=arrays["track_joints"].astype(np.int64), track=track,
                   static=arrays["static"].astype(np.float64))

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
            bvh_bytes = len(format_bvh(self.decompress()).encode("utf-8"))
        return {"frames": f, "joints": dof, "keyframes": self.n_keyframes, "keyframe_ratio": r,
                "formula_uncompressed_numbers": m, "formula_compressed_numbers": c, "formula_ratio": c / m,
                "compressed_bytes": real, "bvh_bytes": int(bvh_bytes), "real_ratio": real / bvh_bytes}


def read_compressed(path: str | os.PathLike) -> Compressed:
    """Read a ``.mck`` file."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None
    return Compressed.from_bytes(data, path)


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
    if scheme not in SCHEMES:
        raise MocycleError(f"scheme must be one of {', '.join(SCHEMES)}; got {scheme!r}")
    if select not in METHODS:
        raise MocycleError(f"keyframe selection must be one of {', '.join(METHODS)}; got {select!r}")
    if scheme == "spatial" and projection not in PROJECTIONS:
        raise MocycleError(f"projection must be one of {', '.join(PROJECTIONS)}; got {projection!r}")
    if seed not in ONE_STEP:
        raise MocycleError(f"the seed projection must be one of {', '.join(ONE_STEP)}; got {seed!r}")
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
    moving = np.flatnonzero(np.ptp(motion.translations, axis=0).max(axis=1) > 0)
    track = motion.translations[:, moving].astype(np.float32).astype(np.float64)
    track[key] = motion.translations[key][:, moving]
    return Compressed(skeleton=motion.skeleton, frame_time=motion.frame_time, n_frames=n, key_idx=key,
                      key_quats=motion.rotations[key].copy(), scheme=scheme, select=select,
                      projection=projection if scheme == "spatial" else None,
                      seed=seed if scheme == "spatial" and projection in ("rbfp", "lamp") else None,
                      optimized=bool(optimize and scheme == "spatial"), points=points, track_joints=moving,
                      track=track, static=motion.translations[0].copy())
