"""The ``"cut"`` cycle, the baseline animators know: the frames between the two most similar poses about one
period apart, the seam cross-faded.
"""

from __future__ import annotations

import numpy as np

from ..errors import MocycleError
from ..phase.analysis import PeriodicMotion
from .representation import CycleSpace
from .result import Cycle
from .timeaxis import TimeAxis


def _smoothstep(t: np.ndarray) -> np.ndarray:
    return t * t * (3 - 2 * t)


def cut_cycle(space: CycleSpace, P: np.ndarray, L: np.ndarray, axis: TimeAxis, periodic: PeriodicMotion,
              features: np.ndarray, blend: float = 0.2) -> Cycle:
    """The baseline: frames ``a .. b-1`` between the most similar poses about one period apart (mean
    squared distance in ``features`` over a window of about a fifth of a period around ``a`` and ``b``, so
    noise averages out and velocities match too), the last ``blend`` of the cycle cross-faded into the
    frames before ``a`` so the wrap is seamless."""
    s, e = max(axis.regions, key=lambda r: r[1] - r[0])
    N = axis.period_frames
    lags = np.arange(max(2, int(np.floor(0.85 * N))), int(np.ceil(1.15 * N)) + 1)
    lags = lags[lags < e - s - 1]
    if lags.size == 0:
        raise MocycleError(f"the longest excited region ({e - s} frames) is shorter than one period ({N:.1f} "
                           f"frames): nothing to cut")
    F = features[s:e]
    h = max(1, int(round(0.1 * N)))  # compare windows of 2h+1 frames: averages noise, matches velocities too
    best = (np.inf, 0, 0)
    for lag in lags:
        d = ((F[:-lag] - F[lag:]) ** 2).sum(axis=1)              # d[i]: frame s+i against s+i+lag
        if d.size < 2 * h + 1:
            continue
        c = np.concatenate([[0.0], np.cumsum(d)])
        cost = (c[2 * h + 1:] - c[:-2 * h - 1]) / (2 * h + 1)      # cost[j]: window centred on d[j + h]
        first = max(0, min(round(blend * lag) - h, cost.size - 1))  # starts with room for the cross-fade
        j = first + int(np.argmin(cost[first:]))
        if cost[j] < best[0]:
            best = (float(cost[j]), j + h + s, int(lag))
    if not np.isfinite(best[0]):
        raise MocycleError(f"the longest excited region ({e - s} frames) is too short to cut a cycle of "
                           f"{N:.1f} frames")
    _, a, period = best
    b = a + period
    w = int(min(round(blend * period), a - s))
    Pc, Lc = P[a:b].copy(), L[a:b].copy()
    drift = L[b] - L[a]
    if w >= 1:
        k = np.arange(period - w, period)
        t = _smoothstep((k - (period - w) + 1) / (w + 1))[:, None]
        src = a + k - period
        Pc[k] = (1 - t) * P[a + k] + t * P[src]
        Lc[k] = (1 - t) * L[a + k] + t * (L[src] + drift)
    x = axis.x[axis.frames()]
    positions = np.mod(x - axis.x[a], 1.0) * period
    return Cycle(space=space, P=Pc, L=Lc, drift=drift, method="cut", model=None, harmonics=None, axis=axis,
                 positions=positions, periodic=periodic)


def clip_cycle(space: CycleSpace, P: np.ndarray, L: np.ndarray, axis: TimeAxis, periodic: PeriodicMotion) -> Cycle:
    """A take that is one cycle (a game clip) as its own loop: its first ``N`` frames (``N`` the period, the
    clip's length or one less when its last frame repeats the first) as they are, no fit and no cross-fade;
    the drift per cycle from the closing frame when there is one, else the frames' travel carried on by one
    more step (the mean of the clip's first and last steps)."""
    N = int(round(axis.period_frames))
    if not 2 <= N <= P.shape[0]:
        raise MocycleError(f"a clip of {P.shape[0]} frames cannot hold one cycle of {N} frames")
    # the step across the wrap: to the closing frame, else the mean of the clip's first and last steps
    drift = L[N] - L[0] if P.shape[0] > N else L[N - 1] - L[0] + 0.5 * ((L[1] - L[0]) + (L[N - 1] - L[N - 2]))
    x = axis.x[axis.frames()]
    positions = np.mod(x - axis.x[0], 1.0) * N
    return Cycle(space=space, P=P[:N].copy(), L=L[:N].copy(), drift=drift, method="clip", model=None,
                 harmonics=None, axis=axis, positions=positions, periodic=periodic)
