"""Keyframe compression (thesis chapter 3): :func:`compress` and the :class:`Compressed` take it makes.

:func:`compress` selects keyframes and, for the spatial scheme, projects every pose to 2-D (optionally
optimising the projection with Algorithm 12); :class:`Compressed` holds what is needed to rebuild the take,
:meth:`Compressed.decompress` rebuilds it.  Its file, ``.mck``, is :mod:`mocycle.io.mck`'s: that codec
encodes and decodes the fields and knows nothing of how the frames are rebuilt.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _validate
from ..defaults import KEY_SCHEMES as SCHEMES
from ..io import mck
from ..io.bvh import bvh_size
from ..motion import Motion, Skeleton
from ..threads import limit_threads
from .density import SPATIAL_MIN_KEYS, keyframe_density
from .distance import joint_weights
from .projection import ONE_STEP, PROJECTIONS, PoseSpace, select_keyframes, spatial_layout
from .select import METHODS, keyframe_count
from .spatial import optimize_projection, reconstruct_spatial
from .temporal import check_keys, interpolate_rotations

__all__ = ["SCHEMES", "Compressed", "compress", "read_compressed"]


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
            assert self.points is not None  # compress and read_compressed give the spatial scheme its points
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
        """The ``.mck`` file's bytes (:func:`mocycle.io.mck.encode`)."""
        return mck.encode(self)

    @classmethod
    def from_bytes(cls, data: bytes, path: str | os.PathLike | None = None) -> Compressed:
        """Read :meth:`to_bytes`'s bytes; every count, shape, index and value is checked (MotionFileError naming
        ``path``; :func:`mocycle.io.mck.decode`)."""
        return cls(**mck.decode(data, path))

    def save(self, path: str | os.PathLike) -> Path:
        """Write the ``.mck`` file atomically."""
        return mck.write_bytes(path, self.to_bytes())

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


def read_compressed(path: str | os.PathLike) -> Compressed:
    """Read a ``.mck`` file."""
    return Compressed.from_bytes(mck.read_bytes(path), path)


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
    if count is not None:
        k = keyframe_count(n, count=count)
    elif isinstance(ratio, str):
        k = keyframe_density(motion, ratio, scheme).count
    else:
        k = keyframe_count(n, ratio=ratio)
        if scheme == "spatial":
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
