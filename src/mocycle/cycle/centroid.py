"""The ``"centroid"`` cycle (paper 001 §4.4): Gaussian-mixture density of the circular coordinate, ``S``
quantile samples, centroid of the ``k`` nearest frames in phase, resampled to ``N`` frames.
"""

from __future__ import annotations

import numpy as np

from ..phase.analysis import PeriodicMotion
from ..phase.period import circle_gmm_cdf
from .representation import CycleSpace
from .result import Cycle
from .timeaxis import TimeAxis

CENTROID_SAMPLES = 500   # paper 001 §6: 500 sampled coordinate values
CENTROID_NEIGHBOURS = 10  # paper 001 §6: 10 nearest neighbours


def _detrend(L: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drift per period ``(4,)`` of ``L`` along ``x`` (least squares) and ``L`` without it."""
    B = np.column_stack([np.ones_like(x), x])
    coef = np.linalg.lstsq(B, L, rcond=None)[0]
    return coef[1], L - np.outer(x, coef[1])


def _circular_resample(Y: np.ndarray, n: int, shift: float = 0.0) -> np.ndarray:
    """Linear resampling of one cycle ``(S, D)`` (row ``S`` = row 0) to ``n`` rows; new row ``k`` is read at
    old row position ``k * S / n + shift``."""
    S = Y.shape[0]
    t = np.arange(n) * S / n + shift
    i0 = np.floor(t).astype(int)
    f = (t - i0)[:, None]
    return (1 - f) * Y[i0 % S] + f * Y[(i0 + 1) % S]


def centroid_cycle(space: CycleSpace, P: np.ndarray, L: np.ndarray, axis: TimeAxis, periodic: PeriodicMotion,
                   n_samples: int = CENTROID_SAMPLES, n_neighbours: int | None = None) -> Cycle:
    """Paper 001 §4.4: GMM density of the phase, quantile samples, centroids of the k nearest frames."""
    frames = axis.frames()
    phi = periodic.coords[frames]
    k = n_neighbours or max(CENTROID_NEIGHBOURS, int(np.ceil(axis.n_periods)) + 1)
    k = min(k, frames.size)
    cdf = circle_gmm_cdf(phi)
    grid = np.linspace(0.0, 1.0, 4097)
    cgrid = np.maximum.accumulate(cdf(grid))
    # Deterministic samples from the density: its quantiles at evenly spaced probabilities (time runs evenly).
    theta = np.interp((np.arange(n_samples) + 0.5) / n_samples, cgrid, grid)
    d = np.abs(np.mod(theta[:, None] - phi[None, :] + 0.5, 1.0) - 0.5)  # (S, M) circular distance
    nearest = np.argpartition(d, k - 1, axis=1)[:, :k]
    drift, flat = _detrend(L[frames], axis.x[frames])
    N = int(round(axis.period_frames))
    # Sample s sits at time (s + 0.5) / S of the cycle; output frame k at time k / N.
    Pn = _circular_resample(P[frames][nearest].mean(axis=1), N, shift=-0.5)
    Ln = _circular_resample(flat[nearest].mean(axis=1), N, shift=-0.5) + np.outer(np.arange(N) / N, drift)
    positions = np.mod((cdf(phi) * n_samples - 0.5) * N / n_samples, N)
    return Cycle(space=space, P=Pn, L=Ln, drift=drift, method="centroid", model=None, harmonics=None, axis=axis,
                 positions=positions, periodic=periodic)
