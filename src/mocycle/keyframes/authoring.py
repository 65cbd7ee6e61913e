"""Spatial-keyframe authoring (thesis 002, chapter 6): a trajectory drawn on the plane becomes an animation.

The animator's stroke is a list of 2-D points with timestamps (the mouse's own timing).  It is resampled at
the take's frame rate, each sample is back-projected to a pose by Igarashi's RBF (:class:`BackProjection`)
fitted to the keyframes' markers, and the root is placed afterwards (:func:`mocycle.contacts.plant_lowest_foot`).
:func:`relayout` re-projects the in-between frames after markers were moved: RBFP (Algorithm 10) from the
new markers as the seed, then Algorithm 12.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import MocycleError
from ..limits import check_frames
from ..motion import Motion
from .projection import PoseSpace, rbfp_map
from .spatial import BackProjection, OptimizeResult, optimize_projection

#: longest stroke, seconds (a stroke is resampled at the take's frame rate)
MAX_STROKE_S = 600.0


def resample_stroke(points, times_s, frame_time: float) -> np.ndarray:
    """The stroke's 2-D point at every frame time ``(T, 2)``: linear in time between the mouse samples.

    ``points``: ``(N, 2)``; ``times_s``: ``(N,)`` non-decreasing seconds (mouse event timestamps);
    ``T = floor(duration / frame_time) + 1``.
    """
    P = np.asarray(points, dtype=np.float64)
    t = np.asarray(times_s, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 2 or t.shape != (len(P),) or len(P) < 1:
        raise MocycleError(f"a stroke needs (N, 2) points and (N,) times; got {P.shape} and {t.shape}")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(t))):
        raise MocycleError("the stroke contains NaN or infinite values")
    if np.any(np.diff(t) < 0):
        raise MocycleError("the stroke's times must not decrease")
    duration = float(t[-1] - t[0])
    if duration > MAX_STROKE_S:
        raise MocycleError(f"the stroke lasts {duration:.0f} s; at most {MAX_STROKE_S:.0f} s")
    n = check_frames(np.floor(duration / frame_time + 1e-9) + 1, 1, "the stroke")
    ft = t[0] + np.arange(n) * frame_time
    return np.column_stack([np.interp(ft, t, P[:, 0]), np.interp(ft, t, P[:, 1])])


def author_motion(take: Motion, key_idx, markers, trajectory) -> Motion:
    """The poses along ``trajectory`` ``(T, 2)``, back-projected from the keyframes ``key_idx`` of ``take``
    placed at ``markers`` ``(K, 2)``; translations are the take's first frame's (place the root afterwards).
    """
    idx = np.asarray(key_idx, dtype=np.int64)
    if idx.ndim != 1 or len(idx) < 3 or idx.min() < 0 or idx.max() >= take.n_frames:
        raise MocycleError(f"need at least 3 keyframes within the take's {take.n_frames} frames; got {idx.tolist()}")
    L = np.asarray(markers, dtype=np.float64)
    if L.shape != (len(idx), 2):
        raise MocycleError(f"need one 2-D marker per keyframe ({len(idx)}, 2); got {L.shape}")
    traj = np.asarray(trajectory, dtype=np.float64).reshape(-1, 2)
    q, _ = BackProjection(L, take.rotations[idx])(traj)
    return Motion(take.skeleton, q, take.translations_at(0), take.frame_time)  # no joint moves: (J, 3)


def relayout(space: PoseSpace, key_idx, markers, optimize: bool = True,
             stop: Callable[[], bool] | None = None,
             progress: Callable[[float], None] | None = None) -> tuple[np.ndarray, OptimizeResult | None]:
    """Every frame's 2-D point after the keyframes' markers moved: RBFP from the markers (the seed), then
    Algorithm 12 when ``optimize``.  ``stop()`` ends Algorithm 12 early (its points so far are returned);
    ``progress(fraction)`` is told after each pass.  Returns ``(points (T, 2), OptimizeResult or None)``.
    """
    idx = np.asarray(key_idx, dtype=np.int64)
    L = np.asarray(markers, dtype=np.float64)
    if L.shape != (len(idx), 2) or not np.all(np.isfinite(L)):
        raise MocycleError(f"need one finite 2-D marker per keyframe ({len(idx)}, 2); got {L.shape}")
    D = space.distances[:, idx]
    points = rbfp_map(D, D[idx], L)
    points[idx] = L
    if not optimize:
        return points, None
    result = optimize_projection(points, idx, space.quats, space.weights, stop=stop, progress=progress)
    return result.points, result
