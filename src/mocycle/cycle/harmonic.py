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
equations of size ``2K+1`` (+1 with the linear term).
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from ..errors import MocycleError

MODELS = ("M1", "M2", "M3")
WEIGHT_LIMIT = 1e8  # alpha, gamma are clipped here: a DOF whose derivatives fit perfectly stays solvable


def harmonic_basis(x: np.ndarray, n_harmonics: int, derivative: int = 0, linear: bool = False) -> np.ndarray:
    """Design matrix ``(M, 2K+1[+1])`` of the model or of its 1st/2nd derivative in ``x`` (periods).

    Columns: ``1, sin(2 pi x), cos(2 pi x), ..., sin(2 pi K x), cos(2 pi K x)[, x]``.
    """
    x = np.asarray(x, dtype=np.float64).reshape(-1)
    w = 2.0 * np.pi * np.arange(1, n_harmonics + 1)
    arg = np.outer(x, w)
    s, c = np.sin(arg), np.cos(arg)
    cols = np.empty((x.size, 2 * n_harmonics + 1 + int(linear)))
    if derivative == 0:
        cols[:, 0] = 1.0
        cols[:, 1:2 * n_harmonics + 1:2], cols[:, 2:2 * n_harmonics + 1:2] = s, c
        if linear:
            cols[:, -1] = x
    elif derivative == 1:
        cols[:, 0] = 0.0
        cols[:, 1:2 * n_harmonics + 1:2], cols[:, 2:2 * n_harmonics + 1:2] = w * c, -w * s
        if linear:
            cols[:, -1] = 1.0
    elif derivative == 2:
        cols[:, 0] = 0.0
        cols[:, 1:2 * n_harmonics + 1:2], cols[:, 2:2 * n_harmonics + 1:2] = -w ** 2 * s, -w ** 2 * c
        if linear:
            cols[:, -1] = 0.0
    else:
        raise MocycleError(f"derivative must be 0, 1 or 2; got {derivative!r}")
    return cols


def max_harmonics(n_rows: int, cycle_frames: int | None = None) -> int:
    """The largest K a fit supports: ``2K+1 <= rows``, and ``K < N/2`` (no harmonic above the cycle's Nyquist)."""
    k = (n_rows - 1) // 2
    if cycle_frames is not None:
        k = min(k, (int(cycle_frames) - 1) // 2)
    return max(k, 0)


def _column_sq_sums(B: np.ndarray, coef: np.ndarray, Y: np.ndarray, rows: int = 8192) -> np.ndarray:
    """``((B @ coef - Y) ** 2).sum(axis=0)`` ``(D,)``, block by block of rows (no residual array as large as Y)."""
    out = np.zeros(Y.shape[1])
    for r in range(0, Y.shape[0], rows):
        e = B[r:r + rows] @ coef - Y[r:r + rows]
        out += np.einsum("ij,ij->j", e, e)
    return out


#: rows of a block when :meth:`HarmonicRegression.fit` passes whole arrays to :meth:`~HarmonicRegression.fit_blocks`
ROWS = 8192


class _Gram:
    """``BᵀB (p, p)``, ``BᵀY (p, D)`` and the row count of a design ``B`` and its targets ``Y``, summed over blocks."""

    def __init__(self):
        self.BtB, self.BtY, self.rows = 0.0, 0.0, 0

    @staticmethod
    def of(blocks, designs, n: int) -> list[_Gram]:
        """``n`` sums over ``blocks()``; ``designs(block)`` -> ``n`` pairs ``(B, Y)`` of that block."""
        out = [_Gram() for _ in range(n)]
        for block in blocks():
            for g, (B, Y) in zip(out, designs(block), strict=True):
                Y = np.asarray(Y, dtype=np.float64)
                if not (np.isfinite(B).all() and np.isfinite(Y).all()):
                    raise MocycleError("the time axis and the curves must be finite numbers")
                g.BtB = g.BtB + B.T @ B
                g.BtY = g.BtY + B.T @ Y
                g.rows += B.shape[0]
        for g in out:
            if g.rows == 0:
                raise MocycleError("no rows to fit")
        return out


def _design(K: int, derivative: int, linear: bool):
    return lambda x: harmonic_basis(x, K, derivative, linear)


def _solve(G: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The least-squares coefficients from the normal equations ``G c = b`` (minimum norm if ``G`` is singular)."""
    return np.linalg.lstsq(G, b, rcond=None)[0]


def _sq_sums(blocks, design, coef, index: int = 1, design2=None, index2: int = 2, coef2=None):
    """Column sums of squared residuals ``(D,)`` of ``design(x) @ coef - block[index]`` over ``blocks()``;
    with ``design2`` also those of ``design2(x) @ coef2 - block[index2]`` (``coef2`` defaults to ``coef``)
    from the same pass."""
    first, second = 0.0, 0.0
    coef2 = coef if coef2 is None else coef2
    for block in blocks():
        first = first + _column_sq_sums(design(block[0]), coef, block[index])
        if design2 is not None:
            second = second + _column_sq_sums(design2(block[0]), coef2, block[index2])
    return first if design2 is None else (first, second)


class HarmonicRegression:
    """Harmonic regression of ``D`` curves on a shared time axis (scikit-learn style).

    Parameters
    ----------
    n_harmonics : K (the thesis used 20).
    model : ``"M1"`` (FGLS-weighted, default), ``"M2"`` (positions only) or ``"M3"`` (unweighted).
    linear : add the linear term ``l_j x`` (eq. 3.27) for curves that drift (root translation, heading).

    Fitted attributes
    -----------------
    coef_ : ``(p, D)``; ``alpha_``, ``gamma_`` : ``(D,)`` velocity and acceleration weights (1 for M3, 0 for M2);
    sigma2_ : ``(3, D)`` the FGLS group variances of position, velocity, acceleration (M1 only, else NaN);
    rmse_ : ``(3,)`` thesis eq. 4.1-4.3 on the training rows (velocity/acceleration errors weighted by
    ``sqrt(alpha)``, ``sqrt(gamma)``).
    """

    def __init__(self, n_harmonics: int = 20, model: str = "M1", linear: bool = False):
        self.n_harmonics = n_harmonics
        self.model = model
        self.linear = linear

    def _check(self, x, Y, xd, dY, ddY):
        _validate.choice("model", self.model, MODELS)
        K = _validate.integer("n_harmonics", self.n_harmonics, 1)
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
        derivatives = None
        if xd is not None and dY is not None and ddY is not None:
            xd = np.asarray(xd, dtype=np.float64).reshape(-1)
            dY = np.asarray(dY, dtype=np.float64).reshape(xd.size, -1)
            ddY = np.asarray(ddY, dtype=np.float64).reshape(xd.size, -1)

            def derivatives():
                return ((xd[r:r + ROWS], dY[r:r + ROWS], ddY[r:r + ROWS]) for r in range(0, xd.size, ROWS))
        return self.fit_blocks(lambda: ((x[r:r + ROWS], Y[r:r + ROWS]) for r in range(0, x.size, ROWS)),
                               derivatives)

    def fit_blocks(self, positions, derivatives=None) -> HarmonicRegression:
        """:meth:`fit` on rows given block by block, so that no array of all rows is ever held.

        ``positions()``: a new iterator of ``(x, Y)`` blocks (``(B,)``, ``(B, D)``) each time it is called;
        ``derivatives()`` (M1, M3): likewise of ``(xd, dY, ddY)`` blocks.  The data are read in up to three
        passes: the cross products ``BᵀB``, ``BᵀY`` of each design; the residual sums of the separate
        ordinary fits (M1's group variances, eq. 3.11-3.13); the residuals of the final fit (``rmse_``).
        The least-squares fits are solved from the normal equations of the ``(2K+1[+1])``-column designs.
        """
        _validate.choice("model", self.model, MODELS)
        K = _validate.integer("n_harmonics", self.n_harmonics, 1)
        lin = self.linear
        if self.model != "M2" and derivatives is None:
            raise MocycleError(f"model {self.model} needs velocities and accelerations (xd, dY, ddY)")
        pos = _Gram.of(positions, lambda b: [(harmonic_basis(b[0], K, 0, lin), b[1])], 1)[0]
        D = pos.BtY.shape[1]
        p = 2 * K + 1 + int(lin)
        if pos.rows < p:
            raise MocycleError(f"K = {K} harmonics need at least {p} frames; got {pos.rows} "
                               f"(K <= {max_harmonics(pos.rows)})")
        if self.model == "M2":
            self.coef_ = _solve(pos.BtB, pos.BtY)
            self.alpha_, self.gamma_ = np.zeros(D), np.zeros(D)
            self.sigma2_ = np.full((3, D), np.nan)
            self.rmse_ = np.array([np.sqrt(_sq_sums(positions, _design(K, 0, lin), self.coef_).sum() / pos.rows),
                                   np.nan, np.nan])
            if derivatives is not None:  # unweighted errors of the derivatives the fit did not use
                sv, sa = _sq_sums(derivatives, _design(K, 1, lin), self.coef_, 1, _design(K, 2, lin), 2)
                rows = sum(b[0].size for b in derivatives())
                self.rmse_[1:] = np.sqrt(sv.sum() / rows), np.sqrt(sa.sum() / rows)
            return self

        def both(b):
            return [(harmonic_basis(b[0], K, 1, lin), b[1]), (harmonic_basis(b[0], K, 2, lin), b[2])]
        vel, acc = _Gram.of(derivatives, both, 2)
        if vel.BtY.shape[1] != D:
            raise MocycleError("velocities and accelerations must have the columns of Y")
        if vel.rows < 2 * K:
            raise MocycleError(f"K = {K} harmonics need velocities on at least {2 * K} frames; got {vel.rows}")
        if self.model == "M3":
            self.alpha_, self.gamma_ = np.ones(D), np.ones(D)
            self.sigma2_ = np.full((3, D), np.nan)
            self.coef_ = _solve(pos.BtB + vel.BtB + acc.BtB, pos.BtY + vel.BtY + acc.BtY)
        else:
            self._fit_fgls(positions, derivatives, pos, vel, acc)
        rp = np.sqrt(_sq_sums(positions, _design(K, 0, lin), self.coef_).sum() / pos.rows)
        sv, sa = _sq_sums(derivatives, _design(K, 1, lin), self.coef_, 1, _design(K, 2, lin), 2)
        rv = np.sqrt((self.alpha_ * sv).sum() / vel.rows)
        ra = np.sqrt((self.gamma_ * sa).sum() / acc.rows)
        self.rmse_ = np.array([rp, rv, ra])
        return self

    def _fit_fgls(self, positions, derivatives, pos, vel, acc) -> None:
        """M1: group variances from separate OLS fits (eq. 3.11-3.13), then WLS (eq. 3.19), all DOFs at once."""
        K, lin = self.n_harmonics, self.linear

        def ols(g):
            cols = np.flatnonzero(np.abs(np.diag(g.BtB)) > 0)  # derivative designs lose the constant column
            beta = np.zeros_like(g.BtY)
            beta[cols] = _solve(g.BtB[np.ix_(cols, cols)], g.BtY[cols])
            return beta

        sp = _sq_sums(positions, _design(K, 0, lin), ols(pos))
        sv, sa = _sq_sums(derivatives, _design(K, 1, lin), ols(vel), 1, _design(K, 2, lin), 2, ols(acc))
        s2p = sp / max(pos.rows - 2 * K - 1 - int(lin), 1)
        s2v = sv / max(vel.rows - 2 * K, 1)
        s2a = sa / max(acc.rows - 2 * K, 1)
        tiny = np.finfo(np.float64).tiny
        self.alpha_ = np.clip(s2p / np.maximum(s2v, tiny), 0.0, WEIGHT_LIMIT)
        self.gamma_ = np.clip(s2p / np.maximum(s2a, tiny), 0.0, WEIGHT_LIMIT)
        self.sigma2_ = np.vstack([s2p, s2v, s2a])
        PtP, VtV, AtA = pos.BtB, vel.BtB, acc.BtB
        G = PtP + self.alpha_[:, None, None] * VtV + self.gamma_[:, None, None] * AtA  # (D, p, p)
        b = pos.BtY.T + self.alpha_[:, None] * vel.BtY.T + self.gamma_[:, None] * acc.BtY.T  # (D, p)
        # A tiny ridge keeps DOFs that never move (all-zero rows and columns but the constant) solvable.
        G = G + 1e-12 * np.trace(PtP) / PtP.shape[0] * np.eye(G.shape[-1])
        self.coef_ = np.linalg.solve(G, b[..., None])[..., 0].T

    def predict(self, x, derivative: int = 0, drift: bool = True) -> np.ndarray:
        """``h(x)`` (or ``h'``, ``h''``) at times ``x (N,)`` in periods: ``(N, D)``.

        ``drift=False`` leaves out the linear term (a cycle that stays in place).
        """
        if not hasattr(self, "coef_"):
            raise MocycleError("fit the regression before predicting")
        B = harmonic_basis(x, self.n_harmonics, derivative, self.linear)
        coef = self.coef_
        if self.linear and not drift:
            coef = coef.copy()
            coef[-1] = 0.0
        return B @ coef

    @property
    def drift_(self) -> np.ndarray:
        """``(D,)`` change per period of the linear term (zeros without it)."""
        return self.coef_[-1].copy() if self.linear else np.zeros(self.coef_.shape[1])
