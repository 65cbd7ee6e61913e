"""From the circular coordinate of a periodic motion to a time axis in periods.

The circular coordinate follows the geometry of the poses, not the clock: it
runs fast through poses that change a lot and slowly where the motion lingers
(KTH thesis §3.5).  The regression needs time, so each excited frame gets an
*unwrapped time* ``x`` in periods (``frac(x)`` is its phase).  Four choices:

* ``"smooth"`` (default) — the unwrapped coordinate averaged over a sliding
  window of one period.  The average of ``t/N + f(t)`` over exactly one period
  of a periodic ``f`` is ``t/N + const``, so the within-cycle unevenness of the
  coordinate cancels while slow changes of tempo between cycles are followed.
* ``"rank"`` — the thesis' rank-uniform remap (eq. 3.20), unwrapped.
* ``"gmm"`` — the Gaussian-mixture CDF remap (eq. 3.21, paper 001 §5.2), unwrapped.
* ``"line"`` — the least-squares line through the unwrapped coordinate (a constant tempo).

Each excitation region is handled on its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError
from ..phase.analysis import PeriodicMotion
from ..phase.period import gmm_cdf_remap, rank_uniform, unwrap_phase

TIME_AXES = defaults.TIME_AXES


@dataclass(frozen=True, kw_only=True)
class TimeAxis:
    """``x``: ``(T,)`` unwrapped time in periods (NaN on frames outside the regions);
    ``regions``: the frame ranges ``[start, end)`` used; ``period_frames``: frames per period."""

    x: np.ndarray
    regions: tuple[tuple[int, int], ...]
    period_frames: float
    method: str

    def frames(self) -> np.ndarray:
        """Indices of the frames on the axis, in order."""
        return np.concatenate([np.arange(s, e) for s, e in self.regions])

    @property
    def n_periods(self) -> float:
        return float(sum(self.x[e - 1] - self.x[s] + 1.0 / self.period_frames for s, e in self.regions))


def _line(u: np.ndarray) -> np.ndarray:
    i = np.arange(u.size, dtype=np.float64)
    slope, icept = np.polyfit(i, u, 1)
    return icept + slope * i


def _period_average(u: np.ndarray, period: float) -> np.ndarray:
    """Sliding mean of ``u`` over one period, continued at the local slope where the window does not fit."""
    w = int(round(period))
    n = u.size
    if w < 2 or n < w + 2:
        return _line(u)
    c = np.concatenate([[0.0], np.cumsum(u)])
    mean = (c[w:] - c[:-w]) / w                # windows [i, i + w), i = 0 .. n - w
    centres = np.arange(mean.size) + (w - 1) / 2.0
    i = np.arange(n, dtype=np.float64)
    x = np.interp(i, centres, mean)
    # Beyond the first and last window centre, continue at the local tempo of the nearest period.
    m = min(w, mean.size)
    rate0 = np.polyfit(centres[:m], mean[:m], 1)[0] if m >= 2 else 1.0 / period
    rate1 = np.polyfit(centres[-m:], mean[-m:], 1)[0] if m >= 2 else 1.0 / period
    before, after = i < centres[0], i > centres[-1]
    x[before] = mean[0] + (i[before] - centres[0]) * rate0
    x[after] = mean[-1] + (i[after] - centres[-1]) * rate1
    return x


def time_axis(periodic: PeriodicMotion, method: str = "smooth") -> TimeAxis:
    """The time axis of one periodic motion found by :func:`mocycle.phase.find_phase`."""
    _validate.choice("time_axis", method, TIME_AXES)
    period = float(periodic.period_frames)
    if not (np.isfinite(period) and period > 1):
        raise MocycleError(f"the periodic motion has no usable period ({period:.4g} frames)")
    T = periodic.coords.size
    regions = tuple((int(s), int(e)) for s, e in periodic.excitation if e - s >= 2) or ((0, T),)
    x = np.full(T, np.nan)
    for s, e in regions:
        coords = periodic.coords[s:e]
        if method == "smooth":
            x[s:e] = _period_average(unwrap_phase(coords), period)
        elif method == "line":
            x[s:e] = _line(unwrap_phase(coords))
        elif method == "rank":
            x[s:e] = unwrap_phase(rank_uniform(coords))
        else:
            x[s:e] = unwrap_phase(gmm_cdf_remap(coords))
    return TimeAxis(x=x, regions=regions, period_frames=period, method=method)
