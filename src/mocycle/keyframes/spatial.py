"""Spatial keyframes (thesis section 2.4 and chapter 4): Igarashi back-projection and Algorithm 12.

Igarashi et al.'s back-projection maps a 2-D point to a pose with an RBF (eq. 2.1,
2.2) fitted to the keyframes' markers: the linear kernel ``φ(r) = r`` (eq. 2.3)
plus the linear polynomial ``p₀ + p₁x + p₂y``, one output per rotation-matrix
entry (9 per joint) and per root coordinate.  The interpolated matrices are
orthonormalised to the nearest pure rotation: the SVD's ``U·Vᵀ``, computed by
Newton polar iterations (:func:`fast_nearest_rotation`, the same matrix within
1e-12, three times faster) with the SVD itself for reflections and stragglers.

:func:`optimize_projection` is Algorithm 12: every non-key frame's 2-D point
moves downhill in back-projection error (eq. 3.2), the gradient estimated from four
probes at ``δ·r`` (``r`` = mean distance to the previous and next frame's point),
steps of ``α·r``.  The back-projection depends on the keyframes only, so all
frames move at once (vectorised); a step is kept only when it lowers the error,
otherwise that frame's radius halves, and a frame stops after ``max_shrinks``
halvings (the thesis stops it at its first local minimum).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.distance import cdist
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError
from ..rotations import (
    angle_to_nearest_rotation,
    fast_nearest_rotation,
    matrix_quats,
    nearest_rotation_angle_entries,
    nearest_rotations,
)
from .distance import moving_joints

# The rotation helpers live in mocycle.rotations; these names stay importable from here.
nearest_rotation = nearest_rotations  # the pure rotation closest (Frobenius) to each (..., 3, 3) matrix
__all__ = ["BackProjection", "OptimizeResult", "angle_to_nearest_rotation", "fast_nearest_rotation",
           "nearest_rotation", "optimize_projection", "rbf_solve", "reconstruct_spatial"]


# ---------------------------------------------------------------- RBF (eq. 2.1, 2.2; Algorithm 11)


def rbf_solve(phi: np.ndarray, values: np.ndarray, poly: np.ndarray | None = None) -> np.ndarray:
    """Weights ``(K [+ P], D)`` of the RBF system of eq. 2.2.

    ``phi``: kernel matrix ``(K, K)``; ``values``: ``(K, D)``; ``poly``: the polynomial
    columns ``(K, P)`` (e.g. ``[1, x, y]``) or ``None``.  Falls back to least squares
    (minimum norm) when the system is singular (repeated or collinear markers).
    """
    K = phi.shape[0]
    if poly is None:
        A, B = phi, values
    else:
        P = poly.shape[1]
        A = np.zeros((K + P, K + P))
        A[:K, :K] = phi
        A[:K, K:] = poly
        A[K:, :K] = poly.T
        B = np.vstack([values, np.zeros((P, values.shape[1]))])
    try:
        W = np.linalg.solve(A, B)
        if np.all(np.isfinite(W)) and np.allclose(A @ W, B, atol=1e-6 * (1 + np.abs(B).max())):
            return W
    except np.linalg.LinAlgError:
        pass
    return np.linalg.lstsq(A, B, rcond=None)[0]


class BackProjection:
    """Igarashi back-projection: 2-D markers of the keyframes → their rotation matrices and root position.

    Parameters
    ----------
    markers : ``(K, 2)`` 2-D points of the keyframes.
    key_quats : ``(K, J, 4)`` keyframe local rotations.
    key_root : ``(K, 3)`` keyframe root positions, or ``None`` (rotations only).
    joints : joints to back-project (default: every joint); the others are returned as keyframe 0's.
    """

    def __init__(self, markers: np.ndarray, key_quats: np.ndarray, key_root: np.ndarray | None = None,
                 joints: np.ndarray | None = None):
        L = np.asarray(markers, dtype=np.float64)
        kq = np.asarray(key_quats, dtype=np.float64)
        if L.ndim != 2 or L.shape[1] != 2 or kq.ndim != 3 or kq.shape[0] != L.shape[0] or kq.shape[2] != 4:
            raise MocycleError(f"back-projection needs (K, 2) markers and (K, J, 4) keyframes; got {L.shape}, "
                               f"{kq.shape}")
        if not np.all(np.isfinite(L)):
            raise MocycleError("keyframe markers contain NaN or infinite values")
        K, J = kq.shape[:2]
        self.markers = L
        self.n_joints = J
        self.joints = np.arange(J) if joints is None else np.asarray(joints, dtype=np.int64)
        self.rest = kq[0].copy()
        R = Rotation.from_quat(kq[:, self.joints].reshape(-1, 4)).as_matrix().reshape(K, -1)
        self.has_root = key_root is not None
        Y = np.hstack([R, np.asarray(key_root, dtype=np.float64).reshape(K, 3)]) if self.has_root else R
        self.W = rbf_solve(cdist(L, L), Y, self._poly(L))

    @staticmethod
    def _poly(p: np.ndarray) -> np.ndarray:
        return np.hstack([np.ones((len(p), 1)), p])

    def raw(self, points: np.ndarray) -> np.ndarray:
        """The RBF outputs ``(N, 9·len(joints) [+ 3])`` at ``points`` ``(N, 2)``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        return np.hstack([cdist(p, self.markers), self._poly(p)]) @ self.W

    def matrices(self, points: np.ndarray, fast: bool = False) -> np.ndarray:
        """Orthonormalised rotation matrices ``(N, len(joints), 3, 3)`` of the back-projected joints."""
        n = len(self.joints)
        M = self.raw(points)[:, : 9 * n].reshape(-1, n, 3, 3)
        return fast_nearest_rotation(M) if fast else nearest_rotation(M)

    def __call__(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """Rotations ``(N, J, 4)`` and root positions ``(N, 3)`` (``None`` without a root) at ``points``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        N, n = len(p), len(self.joints)
        out = self.raw(p)
        q = np.broadcast_to(self.rest, (N, self.n_joints, 4)).copy()
        R = fast_nearest_rotation(out[:, : 9 * n].reshape(N, n, 3, 3))
        q[:, self.joints] = matrix_quats(R)
        return q, (out[:, 9 * n: 9 * n + 3] if self.has_root else None)


def reconstruct_spatial(key_idx, key_quats: np.ndarray, points: np.ndarray,
                        key_root: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Every frame's rotations ``(T, J, 4)`` (and root ``(T, 3)``) from the keyframes and the 2-D trajectory.

    ``points``: ``(T, 2)``, the markers are ``points[key_idx]``; keyframes come back exactly.
    """
    idx = np.asarray(key_idx)
    pts = np.asarray(points, dtype=np.float64)
    kq = np.asarray(key_quats, dtype=np.float64)
    bp = BackProjection(pts[idx], kq, key_root)
    q, root = bp(pts)
    q[idx] = kq
    if root is not None:
        root[idx] = key_root
    return q, root


# ---------------------------------------------------------------- Algorithm 12


@dataclass
class OptimizeResult:
    """``points`` ``(T, 2)`` optimised; ``error_before``/``error_after``: mean eq. 3.2 error of the non-key
    frames; ``passes`` run; ``moved``: frames that moved at least once."""

    points: np.ndarray
    error_before: float
    error_after: float
    passes: int
    moved: int


def optimize_projection(points: np.ndarray, key_idx, quats: np.ndarray, weights: np.ndarray,
                        alpha: float = 0.5, delta: float = 0.5, max_passes: int = 60,
                        max_shrinks: int = 4, grow: float = 1.5, min_spread: float = 0.01,
                        stop=None, progress=None) -> OptimizeResult:
    """Algorithm 12: move each non-key frame's 2-D point downhill in back-projection error.

    Parameters
    ----------
    points : ``(T, 2)`` projection of every frame (the keyframes' points stay).
    key_idx : keyframe indices (increasing, first and last frame included).
    quats : ``(T, J, 4)`` the original rotations; ``weights``: ``(J,)`` eq. 3.2 weights.
    alpha, delta : step and probe sizes as fractions of the radius ``r`` (thesis: 0.5, 0.5).
    max_passes : passes over the frames (the thesis' ``maxtries``).
    max_shrinks : a frame stops after its radius halved this many times without a better point.
    grow : the radius of a frame grows by this factor after a step that helped (1 = the thesis' fixed radius).
    min_spread : joints whose keyframe rotations all lie within this angle (radians) of the first keyframe's
        are left out of the error while optimising (they back-project to nearly the same rotation anywhere;
        on the 100-joint CMU/iClone rig this halves the work).
    stop : ``stop()`` is asked before each pass; ``True`` ends the optimisation there (the points so far are
        returned, every one no worse than where it started).
    progress : ``progress(fraction)`` is told the fraction of ``max_passes`` done after each pass.
    """
    P = np.array(points, dtype=np.float64, copy=True)
    q = np.asarray(quats, dtype=np.float64)
    T = q.shape[0]
    idx = np.asarray(key_idx, dtype=np.int64)
    if P.shape != (T, 2) or not np.all(np.isfinite(P)):
        raise MocycleError(f"points must be a finite ({T}, 2) array; got {P.shape}")
    alpha = _validate.real("alpha", alpha, 0, 1, low_open=True)
    delta = _validate.real("delta", delta, 0, 1, low_open=True)
    free = np.setdiff1d(np.arange(T), idx)
    joints = moving_joints(q[idx], tol=min_spread)
    if free.size == 0 or joints.size == 0:
        return OptimizeResult(P, 0.0, 0.0, 0, 0)
    w = np.asarray(weights, dtype=np.float64)[joints]
    bp = BackProjection(P[idx], q[idx], None, joints)
    target = Rotation.from_quat(q[free][:, joints].reshape(-1, 4)).as_matrix().reshape(len(free), -1, 9)
    target = np.ascontiguousarray(np.moveaxis(target, -1, 0))  # (9, F, Jm) entries, row-major

    Jm = len(joints)

    def err(pts: np.ndarray, rows: np.ndarray) -> np.ndarray:
        M = bp.raw(pts)[:, : 9 * Jm].reshape(-1, Jm, 9)
        Tg = target[:, rows]
        # N = R_targetᵀ · M entry by entry: N_ac = Σ_b T_ba M_bc
        N = [Tg[a] * M[..., c] + Tg[3 + a] * M[..., 3 + c] + Tg[6 + a] * M[..., 6 + c]
             for a in range(3) for c in range(3)]
        return nearest_rotation_angle_entries(N) @ w

    extent = float(np.ptp(P, axis=0).max()) or 1.0
    r = 0.5 * (np.linalg.norm(P[free] - P[free - 1], axis=1) + np.linalg.norm(P[free] - P[free + 1], axis=1))
    r = np.maximum(r, 1e-4 * extent)
    rows_all = np.arange(len(free))
    e = err(P[free], rows_all)
    e_start = float(e.mean())
    shrinks = np.zeros(len(free), dtype=np.int64)
    moved = np.zeros(len(free), dtype=bool)
    probes = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    passes = 0
    for passes in range(1, max_passes + 1):  # noqa: B007
        rows = np.flatnonzero(shrinks < max_shrinks)
        if rows.size == 0 or (stop is not None and stop()):
            break
        cur = P[free[rows]]
        e0 = e[rows]
        s = (delta * r[rows])[None, :, None]
        cand = cur[None] + s * probes[:, None, :]  # (4, m, 2)
        ep = err(cand.reshape(-1, 2), np.tile(rows, 4)).reshape(4, -1)
        exp_, exn, eyp, eyn = ep
        hx = np.where((e0 > exp_) | (e0 > exn), exn - exp_, 0.0)
        hy = np.where((e0 > eyp) | (e0 > eyn), eyn - eyp, 0.0)
        h = np.stack([hx, hy], axis=1)
        hn = np.linalg.norm(h, axis=1)
        step = cur + alpha * r[rows, None] * h / np.where(hn > 0, hn, 1.0)[:, None]
        es = err(step, rows)
        es = np.where(hn > 0, es, np.inf)
        best_probe = np.argmin(ep, axis=0)
        ebp = ep[best_probe, np.arange(len(rows))]
        use_step = (es < e0) & (es <= ebp)
        use_probe = ~use_step & (ebp < e0)
        new = np.where(use_step[:, None], step, np.where(use_probe[:, None], cand[best_probe, np.arange(len(rows))],
                                                         cur))
        better = use_step | use_probe
        P[free[rows]] = new
        e[rows] = np.where(use_step, es, np.where(use_probe, ebp, e0))
        moved[rows] |= better
        shrinks[rows] += ~better
        r[rows] = np.where(better, grow * r[rows], 0.5 * r[rows])
        if progress is not None:
            progress(passes / max_passes)
    return OptimizeResult(P, e_start, float(e.mean()), passes, int(moved.sum()))
