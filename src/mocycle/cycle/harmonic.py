"""Harmonic regression of a periodic motion (KTH thesis ch. 3).

Per degree of freedom ``j`` the model is

    h_j(x) = c_j + sum_{k=1..K} a_jk sin(2 pi k x) + b_jk cos(2 pi k x)  [+ l_j x]     (eq. 3.6, 3.27)

with ``x`` the time axis in periods.  Three ways to fit it (Tables A-B):

* **M1** — positions, velocities and accelerations, weighted by feasible
  generalised least squares: separate OLS fits give the group variances
  ``s2_p, s2_v, s2_a`` (eq. 3.11-3.13), then ``alpha_j = s2_p / s2_v`` and
  ``gamma_j = s2_p / s2_a`` weight the velocity and acceleration rows (eq. 3.19);
* **M2** — positions only (eq. 3.8);
* **M3** — positions, velocities and accelerations, unweighted (eq. 3.9).

Every DOF shares one design matrix, so M2 and M3 are one least-squares call
with ``D`` right-hand sides and M1 is one batched solve of ``D`` normal
equations of size ``2K+1`` (+1 with the linear term).  M1 reads its rows block
by block (:meth:`HarmonicRegression.fit_blocks`): the cross products, the
designs' QR factors and the residual sums are added up over blocks, so a long
take's velocities and accelerations need never be held whole.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError

MODELS = defaults.HARMONIC_MODELS
#: DOFs per batch of M1's normal equations: a 100-joint rig's (D, 41, 41) at once is 10 MB of temporaries
_SOLVE_BLOCK = 64
WEIGHT_LIMIT = 1e8  # alpha, gamma are clipped here: a DOF whose derivatives fit perfectly stays solvable


def harmonic_basis(x: np.ndarray, harmonics: int | None = None, derivative: int = 0, linear: bool = False, *,
                   n_harmonics: int | None = None) -> np.ndarray:
    """Design matrix ``(M, 2K+1[+1])`` of the model or of its 1st/2nd derivative in ``x`` (periods).

    Columns: ``1, sin(2 pi x), cos(2 pi x), ..., sin(2 pi K x), cos(2 pi K x)[, x]``; K, the number of
    harmonics, is ``harmonics`` (``n_harmonics`` is its old name, accepted with a DeprecationWarning).
    """
    harmonics = _validate.renamed("n_harmonics", "harmonics", n_harmonics, harmonics)
    if harmonics is None:
        raise TypeError("harmonic_basis() needs harmonics")
    x = np.asarray(x, dtype=np.float64).reshape(-1)
    return _assemble(x, *_waves(x, harmonics), harmonics, derivative, linear)


def _waves(x: np.ndarray, harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """``sin(2 pi k x)`` and ``cos(2 pi k x)`` ``(M, K)`` for ``k = 1 .. K``: what every design of ``x`` is made of."""
    arg = np.outer(x, 2.0 * np.pi * np.arange(1, harmonics + 1))
    return np.sin(arg), np.cos(arg)


def _assemble(x: np.ndarray, s: np.ndarray, c: np.ndarray, harmonics: int, derivative: int,
              linear: bool) -> np.ndarray:
    """:func:`harmonic_basis` of ``x`` from its :func:`_waves` ``s``, ``c``."""
    w = 2.0 * np.pi * np.arange(1, harmonics + 1)
    cols = np.empty((x.size, 2 * harmonics + 1 + int(linear)))
    if derivative == 0:
        cols[:, 0] = 1.0
        cols[:, 1:2 * harmonics + 1:2], cols[:, 2:2 * harmonics + 1:2] = s, c
        if linear:
            cols[:, -1] = x
    elif derivative == 1:
        cols[:, 0] = 0.0
        cols[:, 1:2 * harmonics + 1:2], cols[:, 2:2 * harmonics + 1:2] = w * c, -w * s
        if linear:
            cols[:, -1] = 1.0
    elif derivative == 2:
        cols[:, 0] = 0.0
        cols[:, 1:2 * harmonics + 1:2], cols[:, 2:2 * harmonics + 1:2] = -w ** 2 * s, -w ** 2 * c
        if linear:
            cols[:, -1] = 0.0
    else:
        raise MocycleError(f"derivative must be 0, 1 or 2; got {derivative!r}")
    return cols


#: Bytes of design matrices :func:`_design` keeps (per process): a fit reads its designs three times over
#: (cross products, the ordinary fits' residuals, the weighted fit's), the two curves of a cycle share
#: their time axis, and the sines and cosines are most of a fit's arithmetic.  64 MB holds every design of
#: a part of about 30,000 frames; a longer one's are made again as they are read, as without the cache.
DESIGN_CACHE_BYTES = 64 * 2**20


class _Designs:
    """Design matrices made recently, least recently used first out, at most ``budget`` bytes: each kept
    read-only under the bytes of its ``x`` and ``(K, derivative, linear)``, so a hit is the very matrix
    :func:`harmonic_basis` makes for those; beside them the :func:`_waves` of each ``x`` and ``K``, which the
    designs of every derivative, with and without the linear term, are made from."""

    def __init__(self, budget: int):
        import threading
        from collections import OrderedDict

        self.budget, self.held = budget, 0
        self.kept: OrderedDict[tuple, tuple[Any, int]] = OrderedDict()  # key -> (value, bytes)
        self.lock = threading.Lock()  # a dask worker runs its tasks in threads

    def get(self, x: np.ndarray, harmonics: int, derivative: int, linear: bool) -> np.ndarray:
        key = (x.tobytes(), int(harmonics), int(derivative), bool(linear))
        B: np.ndarray | None = self._get(key)
        if B is not None:
            return B
        if derivative not in (0, 1, 2):
            raise MocycleError(f"derivative must be 0, 1 or 2; got {derivative!r}")
        waves_key = (key[0], key[1])
        waves: tuple[np.ndarray, np.ndarray] | None = self._get(waves_key)
        if waves is None:
            waves = _waves(x, harmonics)
            self._keep(waves_key, waves, waves[0].nbytes + waves[1].nbytes)
        B = _assemble(x, waves[0], waves[1], harmonics, derivative, linear)
        B.setflags(write=False)
        self._keep(key, B, B.nbytes)
        return B

    def _get(self, key: tuple) -> Any:
        with self.lock:
            hit = self.kept.get(key)
            if hit is None:
                return None
            self.kept.move_to_end(key)
            return hit[0]

    def _keep(self, key: tuple, value: Any, nbytes: int) -> None:
        size = nbytes + len(key[0])
        if size > self.budget:
            return
        with self.lock:
            if key not in self.kept:
                self.kept[key] = (value, size)
                self.held += size
            while self.held > self.budget:
                _, (_, old) = self.kept.popitem(last=False)
                self.held -= old


_DESIGNS = _Designs(DESIGN_CACHE_BYTES)


def _design(x, harmonics: int, derivative: int = 0, linear: bool = False) -> np.ndarray:
    """:func:`harmonic_basis`, read-only, kept for the next call with the same arguments (:data:`_DESIGNS`)."""
    return _DESIGNS.get(np.asarray(x, dtype=np.float64).reshape(-1), harmonics, derivative, linear)


def max_harmonics(n_rows: int, cycle_frames: int | None = None) -> int:
    """The largest K a fit supports: ``2K+1 <= rows``, and ``K < N/2`` (no harmonic above the cycle's Nyquist)."""
    k = (n_rows - 1) // 2
    if cycle_frames is not None:
        k = min(k, (int(cycle_frames) - 1) // 2)
    return max(k, 0)


def least_squares(B: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """``numpy.linalg.lstsq(B, Y, rcond=None)[0]`` for a small design ``B (M, p)`` and many columns ``Y (M, D)``:
    the minimum-norm solution ``(p, D)`` through the pseudo-inverse from ``B``'s SVD (singular values up to
    ``eps · max(M, p)`` of the largest dropped, as lstsq drops them), applied in two matrix products.  The
    same coefficients within rounding; 3-4× faster than LAPACK's ``gelsd`` on hundreds of columns, which
    applies its reflections to the columns one at a time."""
    U, S, Vt = np.linalg.svd(B, full_matrices=False)
    kept = S > np.finfo(np.float64).eps * max(B.shape) * (S[0] if S.size else 0.0)
    inv = np.where(kept, 1.0 / np.where(kept, S, 1.0), 0.0)
    return Vt.T @ (inv[:, None] * (U.T @ Y))


def _column_sq_sums(B: np.ndarray, coef: np.ndarray, Y: np.ndarray, rows: int = 8192) -> np.ndarray:
    """``((B @ coef - Y) ** 2).sum(axis=0)`` ``(D,)``, block by block of rows (no residual array as large as Y)."""
    out = np.zeros(Y.shape[1])
    for r in range(0, Y.shape[0], rows):
        e = B[r:r + rows] @ coef - Y[r:r + rows]
        out += np.einsum("ij,ij->j", e, e)
    return out


#: rows of a block when :meth:`HarmonicRegression.fit` hands whole arrays to :meth:`~HarmonicRegression.fit_blocks`
ROWS = 8192


class _DesignSums:
    """What M1 needs of one design ``B`` and its targets ``Y``, added up block by block of rows: ``BᵀB``
    ``(p, p)``, ``BᵀY`` ``(p, D)``, the ``R`` of ``B``'s QR factorisation (``B = QR``: ``B``'s singular values
    and right singular vectors are ``R``'s), which columns of ``B`` are not all zero, and the row count.

    ``shared``: a dict that fits on the same designs share (the two curves of a cycle, when the path has no
    linear term): the factors of a design read in one block (``BᵀB``, ``R``, the columns used and ``R``'s
    SVD), which depend on the design alone, are made by the first fit and read by the next, the same numbers.
    It holds the designs it was given (the fits' own, while they run)."""

    def __init__(self, shared: dict | None = None):
        self.BtB: Any = None
        self.BtY: Any = None
        self.R: Any = None
        self.nonzero: Any = None
        self.rows = 0
        self.shared = shared
        self.first: list | None = None  # the design's shared factors, while the fit is one block

    def add(self, B: np.ndarray, Y: np.ndarray) -> None:
        BtY = B.T @ Y
        if self.R is None and self.shared is not None:  # one design's own factors: made once per design
            kept = self.shared.get(id(B))
            if kept is None or kept[0] is not B:
                kept = self.shared[id(B)] = [B, *self._factors(B, None), None]
            _, BtB, self.R, nonzero, _ = kept
            BtB, nonzero = BtB.copy(), nonzero.copy()  # added to in place by the blocks that follow
            self.first = kept
        else:
            BtB, self.R, nonzero = self._factors(B, self.R)
            self.first = None
        if self.BtB is None:
            self.BtB, self.BtY, self.nonzero = BtB, BtY, nonzero
        else:
            self.BtB += BtB
            self.BtY += BtY
            self.nonzero |= nonzero
        self.rows += B.shape[0]

    @staticmethod
    def _factors(B: np.ndarray, R: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``BᵀB``, the ``R`` of ``B`` below the ``R`` of the blocks before (``None``: the first block) and the
        columns of ``B`` that are not all zero."""
        factor: Any = np.linalg.qr(B if R is None else np.vstack([R, B]), mode="r")
        nonzero = np.abs(B).max(axis=0) > 0 if B.shape[0] else np.zeros(B.shape[1], dtype=bool)
        return B.T @ B, factor, nonzero

    def least_squares(self) -> tuple[np.ndarray, np.ndarray]:
        """The columns used and :func:`least_squares` ``(B[:, cols], Y)`` from the sums: ``cols`` are ``B``'s
        columns that are not all zero (derivative designs lose the constant column); ``R[:, cols]``'s SVD
        is ``B[:, cols]``'s (``U`` aside), with the same cut of small singular values, and
        ``Uᵀ Y = S⁻¹ Vᵀ (BᵀY)``."""
        solved = self.first[4] if self.first is not None else None
        if solved is None:
            cols = np.flatnonzero(self.nonzero)
            _, S, Vt = np.linalg.svd(self.R[:, cols], full_matrices=False)
            kept = S > np.finfo(np.float64).eps * max(self.rows, cols.size) * (S[0] if S.size else 0.0)
            inv = np.where(kept, 1.0 / np.where(kept, S, 1.0), 0.0)
            solved = (cols, Vt, inv ** 2)
            if self.first is not None:  # one block: the design's alone, for the next fit on it
                self.first[4] = solved
        cols, Vt, inv2 = solved
        return cols, Vt.T @ (inv2[:, None] * (Vt @ self.BtY[cols]))


def _array_blocks(*arrays: np.ndarray, rows: int = ROWS):
    """A function returning a new iterator of row blocks (views) of ``arrays``, which share their row count."""
    n = arrays[0].shape[0]
    return lambda: (tuple(a[r:r + rows] for a in arrays) for r in range(0, n, rows))


class HarmonicRegression:
    """Harmonic regression of ``D`` curves on a shared time axis (scikit-learn style).

    Parameters
    ----------
    harmonics : K, the number of harmonics (the thesis used 20: :data:`mocycle.defaults.HARMONICS`);
        ``n_harmonics`` is its old name, accepted with a DeprecationWarning until the next release.
    model : ``"M1"`` (FGLS-weighted, default), ``"M2"`` (positions only) or ``"M3"`` (unweighted).
    linear : add the linear term ``l_j x`` (eq. 3.27) for curves that drift (root translation, heading).

    Fitted attributes
    -----------------
    coef_ : ``(p, D)``; ``alpha_``, ``gamma_`` : ``(D,)`` velocity and acceleration weights (1 for M3, 0 for M2);
    sigma2_ : ``(3, D)`` the FGLS group variances of position, velocity, acceleration (M1 only, else NaN);
    rmse_ : ``(3,)`` thesis eq. 4.1-4.3 on the training rows (velocity/acceleration errors weighted by
    ``sqrt(alpha)``, ``sqrt(gamma)``).
    """

    def __init__(self, harmonics: int = defaults.HARMONICS, model: str = "M1", linear: bool = False, *,
                 n_harmonics: int | None = None):
        self.harmonics = _validate.renamed("n_harmonics", "harmonics", n_harmonics, harmonics, defaults.HARMONICS)
        self.model = model
        self.linear = linear

    @property
    def n_harmonics(self) -> int:
        """The old name of :attr:`harmonics` (K, the number of harmonics): a DeprecationWarning, for one release."""
        import warnings

        warnings.warn("n_harmonics is now called harmonics; n_harmonics is accepted until the next release",
                      DeprecationWarning, stacklevel=2)
        return self.harmonics

    def _check(self, x, Y, xd, dY, ddY):
        _validate.choice("model", self.model, MODELS)
        K = _validate.integer("harmonics", self.harmonics, 1)
        x = np.asarray(x, dtype=np.float64).reshape(-1)
        Y = np.asarray(Y, dtype=np.float64)
        Y = Y[:, None] if Y.ndim == 1 else Y
        if Y.shape[0] != x.size:
            raise MocycleError(f"x has {x.size} rows but Y has {Y.shape[0]}")
        p = 2 * K + 1 + int(self.linear)
        if x.size < p:
            raise MocycleError(f"K = {K} harmonics need at least {p} frames; got {x.size} "
                               f"(K <= {max_harmonics(x.size)})")
        if not (np.isfinite(x).all() and np.isfinite(Y).all()):
            raise MocycleError("the time axis and the curves must be finite numbers")
        if self.model != "M2":
            if xd is None or dY is None or ddY is None:
                raise MocycleError(f"model {self.model} needs velocities and accelerations (xd, dY, ddY)")
            xd = np.asarray(xd, dtype=np.float64).reshape(-1)
            dY = np.asarray(dY, dtype=np.float64).reshape(xd.size, -1)
            ddY = np.asarray(ddY, dtype=np.float64).reshape(xd.size, -1)
            if dY.shape[1] != Y.shape[1] or ddY.shape[1] != Y.shape[1]:
                raise MocycleError("velocities and accelerations must have the columns of Y")
            if xd.size < 2 * K:
                raise MocycleError(f"K = {K} harmonics need velocities on at least {2 * K} frames; got {xd.size}")
        return x, Y, xd, dY, ddY

    def fit(self, x, Y, xd=None, dY=None, ddY=None) -> HarmonicRegression:
        """Fit positions ``Y (M, D)`` at times ``x (M,)`` (periods); velocities ``dY`` and accelerations
        ``ddY`` ``(M', D)`` per period (and per period²) at times ``xd (M',)`` for M1 and M3."""
        x, Y, xd, dY, ddY = self._check(x, Y, xd, dY, ddY)
        if self.model == "M1":
            return self.fit_blocks(_array_blocks(x, Y), _array_blocks(xd, dY, ddY))
        P = _design(x, self.harmonics, 0, self.linear)
        still = np.all(Y == Y[:1], axis=0)
        if still.any():
            self._fit_moving(~still, P, xd, Y, dY, ddY)
        else:
            self._fit_all(P, xd, Y, dY, ddY)
        self.rmse_ = self._rmse(P, Y, xd, dY, ddY)
        return self

    def fit_blocks(self, positions, derivatives=None, *, shared: dict | None = None) -> HarmonicRegression:
        """:meth:`fit` on rows handed over block by block, so that no array of every row need be held (a long
        take's velocities and accelerations are made a block at a time from its positions).

        ``positions()``: a new iterator of ``(x, Y)`` blocks (``(B,)``, ``(B, D)``) each time it is called;
        ``derivatives()`` (M1, M3): likewise of ``(xd, dY, ddY)`` blocks.  M1 reads them in three passes:
        the designs' cross products and QR factors; the residuals of the separate ordinary fits (the group
        variances, eq. 3.11-3.13); the residuals of the weighted fit (``rmse_``).  M2 and M3 join the blocks
        and fit them as :meth:`fit` does.  ``shared``: a dict (empty at first) that M1 fits on the same time
        axis pass along: the factors of a design that both read in one block are made once (the same numbers)."""
        _validate.choice("model", self.model, MODELS)
        if self.model != "M1":
            x, Y = (np.concatenate(part) for part in zip(*positions(), strict=True))
            if derivatives is None:
                return self.fit(x, Y)
            return self.fit(x, Y, *(np.concatenate(part) for part in zip(*derivatives(), strict=True)))
        K = _validate.integer("harmonics", self.harmonics, 1)
        if derivatives is None:
            raise MocycleError(f"model {self.model} needs velocities and accelerations (xd, dY, ddY)")
        lin, p = self.linear, 2 * K + 1 + int(self.linear)
        pos, vel, acc = _DesignSums(shared), _DesignSums(shared), _DesignSums(shared)
        first, moving = None, None
        for x, Y in positions():  # pass 1: cross products, QR factors, the columns that move
            x, Y = np.asarray(x, dtype=np.float64).reshape(-1), np.asarray(Y, dtype=np.float64)
            Y = Y[:, None] if Y.ndim == 1 else Y
            if not x.size:
                continue
            if not (np.isfinite(x).all() and np.isfinite(Y).all()):
                raise MocycleError("the time axis and the curves must be finite numbers")
            if first is None:
                first, moving = Y[0].copy(), np.zeros(Y.shape[1], dtype=bool)
            moving |= (Y != first).any(axis=0)
            pos.add(_design(x, K, 0, lin), Y)
        if pos.rows < p:
            raise MocycleError(f"K = {K} harmonics need at least {p} frames; got {pos.rows} "
                               f"(K <= {max_harmonics(pos.rows)})")
        assert first is not None and moving is not None  # pos.rows >= p > 0: pass 1 read a frame
        D = first.size
        for xd, dY, ddY in derivatives():
            if not xd.size:
                continue
            if dY.shape[1] != D or ddY.shape[1] != D:
                raise MocycleError("velocities and accelerations must have the columns of Y")
            vel.add(_design(xd, K, 1, lin), dY)
            acc.add(_design(xd, K, 2, lin), ddY)
        if vel.rows < 2 * K:
            raise MocycleError(f"K = {K} harmonics need velocities on at least {2 * K} frames; got {vel.rows}")
        self._fit_fgls(positions, derivatives, pos, vel, acc)
        still = ~moving
        if still.any():  # a joint that never moves: its constant exactly, the weights of a still curve, no error
            self.coef_[:, still] = 0.0
            self.coef_[0, still] = first[still]
            self.alpha_[still], self.gamma_[still], self.sigma2_[:, still] = 0.0, 0.0, 0.0
        # pass 3: the errors of the weighted fit (thesis eq. 4.1-4.3)
        sp = self._sq_sums(positions, self.coef_)
        sv, sa = self._sq_sums(derivatives, self.coef_, self.coef_)
        self.rmse_ = np.sqrt([sp.sum() / pos.rows, (self.alpha_ * sv).sum() / vel.rows,
                              (self.gamma_ * sa).sum() / acc.rows])
        return self

    def _sq_sums(self, blocks, coef, coef2=None, cols=None, cols2=None):
        """Column sums of squared residuals ``(D,)`` over ``blocks()``: of the positions' design (``(x, Y)``
        blocks, ``coef``) or, with ``coef2``, of the velocities' and the accelerations' (``(xd, dY, ddY)``
        blocks; two sums).  ``cols``/``cols2``: only these columns of the design (and rows of ``coef``)."""
        K, lin = self.harmonics, self.linear
        first, second = 0.0, 0.0
        for block in blocks():
            x = block[0]
            if not x.size:
                continue
            if coef2 is None:
                B = _design(x, K, 0, lin)
                first = first + _column_sq_sums(B if cols is None else B[:, cols], coef, block[1])
            else:
                V, A = _design(x, K, 1, lin), _design(x, K, 2, lin)
                first = first + _column_sq_sums(V if cols is None else V[:, cols], coef, block[1])
                second = second + _column_sq_sums(A if cols2 is None else A[:, cols2], coef2, block[2])
        return first if coef2 is None else (first, second)

    def _fit_all(self, P, xd, Y, dY, ddY) -> None:
        """``coef_``, ``alpha_``, ``gamma_``, ``sigma2_`` of every column of ``Y`` (design ``P`` of the positions)."""
        K, lin, D = self.harmonics, self.linear, Y.shape[1]
        if self.model == "M2":
            self.coef_ = np.linalg.lstsq(P, Y, rcond=None)[0]
            self.alpha_, self.gamma_ = np.zeros(D), np.zeros(D)
            self.sigma2_ = np.full((3, D), np.nan)
            return
        V, A = _design(xd, K, 1, lin), _design(xd, K, 2, lin)
        self.alpha_, self.gamma_ = np.ones(D), np.ones(D)  # M3 (M1 is fitted by fit_blocks)
        self.sigma2_ = np.full((3, D), np.nan)
        self.coef_ = np.linalg.lstsq(np.vstack([P, V, A]), np.vstack([Y, dY, ddY]), rcond=None)[0]

    def _fit_moving(self, moving: np.ndarray, P, xd, Y, dY, ddY) -> None:
        """Fit the columns where ``moving`` ``(D,)`` is set; every other column of ``Y`` is one value on every
        row (a joint that never moves): its curve is that constant (``coef_`` ``[c, 0, ..., 0]``, so
        :meth:`predict` gives ``c`` exactly), with the weights a still curve gets (``alpha_``, ``gamma_``
        0, or 1 for M3) and no error."""
        D = Y.shape[1]
        sub = HarmonicRegression(self.harmonics, self.model, self.linear)
        if moving.any():
            sub._fit_all(P, xd, Y[:, moving], None if dY is None else dY[:, moving],
                         None if ddY is None else ddY[:, moving])
        p = 2 * self.harmonics + 1 + int(self.linear)
        self.coef_ = np.zeros((p, D))
        self.coef_[0] = Y[0]
        still_weight = 1.0 if self.model == "M3" else 0.0
        self.alpha_, self.gamma_ = np.full(D, still_weight), np.full(D, still_weight)
        self.sigma2_ = np.zeros((3, D)) if self.model == "M1" else np.full((3, D), np.nan)
        if moving.any():
            self.coef_[:, moving] = sub.coef_
            self.alpha_[moving], self.gamma_[moving] = sub.alpha_, sub.gamma_
            self.sigma2_[:, moving] = sub.sigma2_

    def _fit_fgls(self, positions, derivatives, pos: _DesignSums, vel: _DesignSums, acc: _DesignSums) -> None:
        """M1: group variances from separate OLS fits (eq. 3.11-3.13), then WLS (eq. 3.19), all DOFs at once,
        from the designs' sums of pass 1 and the OLS residuals of pass 2."""
        K = self.harmonics
        (cp, bp), (cv, bv), (ca, ba) = pos.least_squares(), vel.least_squares(), acc.least_squares()
        sp = self._sq_sums(positions, bp, cols=cp)
        sv, sa = self._sq_sums(derivatives, bv, ba, cols=cv, cols2=ca)
        s2p = sp / max(pos.rows - 2 * K - 1 - int(self.linear), 1)
        s2v = sv / max(vel.rows - 2 * K, 1)
        s2a = sa / max(acc.rows - 2 * K, 1)
        tiny = np.finfo(np.float64).tiny
        self.alpha_ = np.clip(s2p / np.maximum(s2v, tiny), 0.0, WEIGHT_LIMIT)
        self.gamma_ = np.clip(s2p / np.maximum(s2a, tiny), 0.0, WEIGHT_LIMIT)
        self.sigma2_ = np.vstack([s2p, s2v, s2a])
        PtP, VtV, AtA = pos.BtB, vel.BtB, acc.BtB
        b = pos.BtY.T + self.alpha_[:, None] * vel.BtY.T + self.gamma_[:, None] * acc.BtY.T  # (D, p)
        # A tiny ridge keeps DOFs that never move (all-zero rows and columns but the constant) solvable.
        ridge = 1e-12 * np.trace(PtP) / PtP.shape[0] * np.eye(PtP.shape[0])
        # every DOF's normal matrix PtP + ridge + alpha VtV + gamma AtA as one product (D, 3) @ (3, p²)
        grams = np.stack([PtP + ridge, VtV, AtA]).reshape(3, -1)
        coef = np.empty(b.shape)
        for d in range(0, b.shape[0], _SOLVE_BLOCK):  # (block, p, p) normal matrices that stay in the cache
            block = slice(d, d + _SOLVE_BLOCK)
            weights = np.column_stack([np.ones(b[block].shape[0]), self.alpha_[block], self.gamma_[block]])
            G = (weights @ grams).reshape(-1, *PtP.shape)
            coef[block] = np.linalg.solve(G, b[block, :, None])[..., 0]
        self.coef_ = coef.T

    def _rmse(self, P, Y, xd, dY, ddY) -> np.ndarray:
        rp = np.sqrt(_column_sq_sums(P, self.coef_, Y).sum() / Y.shape[0])
        if xd is None or dY is None:
            return np.array([rp, np.nan, np.nan])
        K, lin = self.harmonics, self.linear
        a = np.sqrt(self.alpha_ if self.model != "M2" else np.ones_like(self.alpha_))
        g = np.sqrt(self.gamma_ if self.model != "M2" else np.ones_like(self.gamma_))
        rv = np.sqrt((a**2 * _column_sq_sums(_design(xd, K, 1, lin), self.coef_, dY)).sum() / dY.shape[0])
        ra = np.sqrt((g**2 * _column_sq_sums(_design(xd, K, 2, lin), self.coef_, ddY)).sum() / ddY.shape[0])
        return np.array([rp, rv, ra])

    def predict(self, x, derivative: int = 0, drift: bool = True) -> np.ndarray:
        """``h(x)`` (or ``h'``, ``h''``) at times ``x (N,)`` in periods: ``(N, D)``.

        ``drift=False`` leaves out the linear term (a cycle that stays in place).
        """
        if not hasattr(self, "coef_"):
            raise MocycleError("fit the regression before predicting")
        B = _design(x, self.harmonics, derivative, self.linear)
        coef = self.coef_
        if self.linear and not drift:
            coef = coef.copy()
            coef[-1] = 0.0
        return B @ coef

    @property
    def drift_(self) -> np.ndarray:
        """``(D,)`` change per period of the linear term (zeros without it)."""
        return self.coef_[-1].copy() if self.linear else np.zeros(self.coef_.shape[1])
