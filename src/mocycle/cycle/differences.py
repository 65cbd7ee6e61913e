"""Finite differences used by the cycle extraction and its metrics.

* 8th-order central differences for velocity and acceleration (KTH thesis
  eq. 3.23-3.24), with the time step ``t = 1 / N`` in periods (eq. 3.25);
* the 4th-order forward difference for the third derivative (jerk) that
  paper 001 §6.3 uses to judge smoothness.

All functions work along axis 0 of a ``(T, D)`` array and return only the
rows where the stencil fits (no padding, no wrap-around unless asked).
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from ..errors import MocycleError

# Fornberg's 8th-order central stencils for offsets -4..4 (thesis eq. 3.23, 3.24).
CENTRAL_1 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])
CENTRAL_2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
# 4th-order forward stencil of the third derivative, offsets 0..6 (paper 001 §6.3, Fornberg 1988).
FORWARD_3 = np.array([-49 / 8, 29.0, -461 / 8, 62.0, -307 / 8, 13.0, -15 / 8])
HALF = 4  # frames lost at each end by the central stencils


def _stencil(Y: np.ndarray, weights: np.ndarray, step: float, power: int) -> np.ndarray:
    """Apply a stencil along axis 0 where it fits: ``(T, D)`` -> ``(T - len(weights) + 1, D)``."""
    Y = np.asarray(Y, dtype=np.float64)
    if Y.ndim == 1:
        Y = Y[:, None]
    step = _validate.positive("step", step)
    rows = Y.shape[0] - (weights.size - 1)
    if rows < 1:
        raise MocycleError(f"differences need at least {weights.size} frames; got {Y.shape[0]}")
    out = np.zeros((rows,) + Y.shape[1:])
    term = np.empty_like(out)  # one buffer for every weighted row block (they are as large as Y)
    for k, w in enumerate(weights):
        if w:
            out += np.multiply(w, Y[k:k + rows], out=term)
    out /= step ** power
    return out


def central_velocity(Y: np.ndarray, step: float) -> np.ndarray:
    """8th-order central first derivative, ``(T, D)`` -> ``(T - 8, D)`` for frames ``4 .. T-5``.

    ``step``: time between rows in the unit the derivative is wanted in (``1/N`` for "per period").
    """
    return _stencil(Y, CENTRAL_1, step, 1)


def central_acceleration(Y: np.ndarray, step: float) -> np.ndarray:
    """8th-order central second derivative, ``(T, D)`` -> ``(T - 8, D)`` for frames ``4 .. T-5``."""
    return _stencil(Y, CENTRAL_2, step, 2)


def forward_jerk(Y: np.ndarray, step: float, periodic: bool = False) -> np.ndarray:
    """4th-order forward third derivative: ``(T, D)`` -> ``(T - 6, D)``, or ``(T, D)`` when ``periodic``.

    With ``periodic=True`` the rows are one cycle (row ``T`` would equal row 0), so every row gets a value.
    """
    if periodic:
        Y = np.asarray(Y, dtype=np.float64)
        T = Y.shape[0]
        idx = (np.arange(T)[:, None] + np.arange(FORWARD_3.size)) % T
        return np.tensordot(FORWARD_3, Y[idx.T], axes=1) / step ** 3
    return _stencil(Y, FORWARD_3, step, 3)


def periodic_central(Y: np.ndarray, step: float, order: int) -> np.ndarray:
    """8th-order central derivative (``order`` 1 or 2) of one cycle ``(N, D)`` with wrap-around: ``(N, D)``."""
    Y = np.asarray(Y, dtype=np.float64)
    N = Y.shape[0]
    weights = CENTRAL_1 if order == 1 else CENTRAL_2
    idx = (np.arange(N)[:, None] + np.arange(-HALF, HALF + 1)) % N
    return np.tensordot(weights, Y[idx.T], axes=1) / step ** order
