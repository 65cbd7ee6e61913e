"""Periods and phase remaps of a circular coordinate (pure functions on numpy arrays).

A circular coordinate is one value per frame in *cycles* (the circle is
``[0, 1)``).  This module turns it into:

* an unwrapped phase (KTH thesis, Fig. 3.8) and a least-squares period
  (thesis §3.6): :func:`unwrap_phase`, :func:`fit_period`;
* a time-uniform phase, by rank (thesis eq. 3.20, :func:`rank_uniform`) or by
  the CDF of a Gaussian mixture fitted to three shifted copies of the values
  (thesis eq. 3.21, paper 001 §5.2, :func:`gmm_cdf_remap`);
* the frame ranges where the coordinate winds, the "excitation regions" of
  paper 001 §4.6 (:func:`excitation_regions`).

:func:`autocorrelation_period` is independent of any coordinate: the
fundamental cycle of a pose matrix from its windowed circular autocorrelation
(paper 004), used as a cross-check; :func:`self_similarity` decides between
period estimates that disagree.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..errors import MocycleError

__all__ = [
    "PeriodFit",
    "autocorrelation_period",
    "excitation_regions",
    "fit_period",
    "gmm_cdf_remap",
    "rank_uniform",
    "self_similarity",
    "unwrap_phase",
]

#: A fitted slope below this many cycles over the whole fitted span counts as no winding (period ``inf``).
_FLAT_CYCLES = 1e-9


def _series(values, name: str, min_len: int = 1) -> np.ndarray:
    """``values`` as a finite 1-D float array of at least ``min_len`` frames, or a MocycleError."""
    try:
        x = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MocycleError(f"{name} must be a 1-D array of numbers; got {type(values).__name__} ({exc})") from None
    if x.ndim != 1:
        raise MocycleError(f"{name} must be a 1-D array (one value per frame); got shape {x.shape}")
    if x.size < min_len:
        raise MocycleError(f"{name} needs at least {min_len} frame{'s' if min_len > 1 else ''}; got {x.size}")
    bad = ~np.isfinite(x)
    if bad.any():
        raise MocycleError(f"{name} must be finite; {int(bad.sum())} of {x.size} values are NaN or infinite "
                           f"(first at frame {int(np.argmax(bad))})")
    return x


def _circle(values, name: str, min_len: int = 1) -> np.ndarray:
    """Finite 1-D circle values reduced to ``[0, 1)`` (``np.mod`` can round tiny negatives up to 1.0)."""
    x = np.mod(_series(values, name, min_len), 1.0)
    x[x >= 1.0] = 0.0
    return x


def _wrapped_diff(x: np.ndarray) -> np.ndarray:
    """Differences of consecutive circle values, wrapped to ``[-0.5, 0.5)`` cycles."""
    return np.mod(np.diff(x) + 0.5, 1.0) - 0.5


def _positive_int(value, name: str, minimum: int = 1) -> int:
    return _validate.integer(name, value, minimum)


# -- unwrapping and the least-squares period ---------------------------------------------------------------------


def unwrap_phase(coords) -> np.ndarray:
    """Unwrap circle values (cycles) into a continuous phase: ``(T,)`` -> ``(T,)`` cycles.

    KTH thesis Fig. 3.8: ``x̂_1 = x_1``; ``x̂_i = x_i + floor(x̂_{i-1} - x_i + 0.5)``, i.e. every step is
    taken as the shorter way round the circle (a step of exactly half a cycle counts as forward).
    Vectorised: ``x̂ = x + cumsum(floor(0.5 - diff(x)))``.  The first value is kept as given.
    """
    x = _series(coords, "coords")
    offsets = np.zeros_like(x)
    offsets[1:] = np.cumsum(np.floor(0.5 - np.diff(x)))
    return x + offsets


@dataclass(frozen=True)
class PeriodFit:
    """A least-squares line through an unwrapped phase.

    slope_cycles_per_frame : signed slope (cycles per frame; negative when the phase runs backwards).
    intercept : the line's value at frame 0 (cycles).
    period_frames : ``1 / |slope|`` in frames (``inf`` when the phase does not wind).
    period_s : ``period_frames * frame_time`` in seconds, ``None`` without a frame time.
    n_periods : cycles covered over the frames used: ``|slope| * (last frame - first frame)``.
    residual_rms : root mean square distance of the phase from the line (cycles).
    """

    slope_cycles_per_frame: float
    intercept: float
    period_frames: float
    period_s: float | None
    n_periods: float
    residual_rms: float


def fit_period(unwrapped, frame_time: float | None = None, frames=None) -> PeriodFit:
    """Fit a line to an unwrapped phase (cycles, ``(T,)``) against the frame index (KTH thesis §3.6).

    ``frames``: the frames to use, as an index array, a boolean mask of length T or a slice (default all);
    at least two distinct frames.  ``frame_time``: seconds per frame, for :attr:`PeriodFit.period_s`.
    """
    y_all = _series(unwrapped, "unwrapped", min_len=2)
    T = y_all.size
    if frame_time is not None:
        frame_time = _validate.positive("frame_time", frame_time)
    index = np.arange(T)
    if frames is None:
        idx = index
    elif isinstance(frames, slice):
        idx = index[frames]
    else:
        sel = np.asarray(frames)
        if sel.ndim != 1:
            raise MocycleError(f"frames must be a 1-D index array, a boolean mask or a slice; got shape {sel.shape}")
        if sel.dtype == bool:
            if sel.size != T:
                raise MocycleError(f"a boolean frames mask must have one value per frame ({T}); got {sel.size}")
            idx = index[sel]
        elif sel.size == 0 or np.issubdtype(sel.dtype, np.integer):
            idx = sel.astype(np.intp)
            if idx.size and (idx.min() < -T or idx.max() >= T):
                raise MocycleError(f"frames must be frame indices in [0, {T}); got values from {idx.min()} "
                                   f"to {idx.max()}")
            idx = index[idx]
        else:
            raise MocycleError(f"frames must be integer frame indices, a boolean mask or a slice; got dtype "
                               f"{sel.dtype}")
    if idx.size < 2 or idx.min() == idx.max():  # fewer than two distinct frames (without np.unique's sort)
        raise MocycleError(f"fitting a period needs at least two distinct frames; got {np.unique(idx).size}")
    y = y_all[idx]
    x = idx.astype(np.float64)
    # the least-squares line (what np.polyfit(x, y, 1) gives, in closed form about the means: 10x faster)
    xm, ym = float(x.mean()), float(y.mean())
    dx = x - xm
    slope = float(dx @ (y - ym) / (dx @ dx))
    intercept = ym - slope * xm
    span = float(x.max() - x.min())
    if abs(slope) * span < _FLAT_CYCLES:
        period = float("inf")
    else:
        period = 1.0 / abs(slope)
    resid = y - (slope * x + intercept)
    return PeriodFit(
        slope_cycles_per_frame=slope,
        intercept=intercept,
        period_frames=period,
        period_s=None if frame_time is None else period * frame_time,
        n_periods=abs(slope) * span,
        residual_rms=float(np.sqrt(np.mean(resid**2))),
    )


# -- windowed circular autocorrelation (paper 004) ---------------------------------------------------------------


def periodic_hann(T: int) -> np.ndarray:
    """The periodic Hann window ``(T,)``: ``scipy.signal.windows.hann(T, sym=False)``, computed as scipy does
    (``0.5 + 0.5 cos`` on ``linspace(-pi, pi, T + 1)``, last sample dropped), for the same numbers without
    importing ``scipy.signal`` (0.2-0.4 s, a third of a ``mocycle loop``)."""
    if T <= 1:
        return np.ones(T)
    return (0.5 + 0.5 * np.cos(np.linspace(-np.pi, np.pi, T + 1)))[:-1]


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of ``x`` ``(n,)``: samples higher than both neighbours; a flat top counts
    once, at its middle (rounded down), and never at either end of ``x``.  The peaks
    ``scipy.signal.find_peaks(x)`` finds without conditions (see :func:`periodic_hann` for why not it)."""
    x = np.asarray(x)
    starts = np.r_[0, np.flatnonzero(x[1:] != x[:-1]) + 1] if x.size else np.zeros(0, dtype=np.intp)
    ends = np.r_[starts[1:], x.size] - 1  # each run of equal values is [start, end]
    v = x[starts]
    top = np.zeros(starts.size, dtype=bool)
    top[1:-1] = (v[1:-1] > v[:-2]) & (v[1:-1] > v[2:])
    return (starts[top] + ends[top]) // 2


def moving_average(x: np.ndarray, size: int) -> np.ndarray:
    """The mean of ``x`` ``(T,)`` over ``size`` samples about each one, the ends repeated beyond the edges:
    ``scipy.ndimage.uniform_filter1d(x, size, mode="nearest")`` (window ``[i - size // 2, i + (size - 1) // 2]``),
    by a cumulative sum; equal to it within rounding (the tests compare them), without importing
    ``scipy.ndimage`` (0.05 s of every ``mocycle loop``)."""
    x = np.asarray(x, dtype=np.float64)
    size = int(size)
    if x.size == 0 or size <= 1:
        return x.copy()
    padded = np.pad(x, (size // 2, size - 1 - size // 2), mode="edge")
    level = padded.mean()  # summed about the mean: the running sums stay small, so do their rounding errors
    sums = np.concatenate([[0.0], np.cumsum(padded - level)])
    return (sums[size:] - sums[:-size]) / size + level


def _smooth_length(n: int) -> int:
    """The smallest ``2^a 3^b 5^c >= n``: a length pocketfft transforms fast (a length with a large prime
    factor takes it 10-20 times as long: 99 998 = 2 x 49 999)."""
    best = 1 << max(0, int(n - 1).bit_length())
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            m = p35 << max(0, int(-(-n // p35) - 1).bit_length())  # p35 x the power of two reaching n
            best = min(best, m)
            p35 *= 3
        p5 *= 5
    return best


def circular_autocorrelation(Y: np.ndarray, per_column: bool = False) -> np.ndarray:
    """``r(k) = Σ_d Σ_n y_d(n) y_d((n + k) mod T)`` of ``Y`` ``(T,)`` or ``(T, D)``: ``(T,)``, by FFT;
    ``per_column=True`` keeps the columns apart: ``(T, D)``.

    When T is a fast FFT length (no prime factor above 5) directly; otherwise from the linear autocorrelation
    ``c`` zero-padded to the next fast length of at least ``2T - 1`` (``r(k) = c(k) + c(T - k)``): the same
    numbers within rounding, without pocketfft's slow path for lengths with large prime factors.
    """
    Y = np.asarray(Y, dtype=np.float64)
    if Y.ndim == 1:
        Y = Y[:, None]
    T = Y.shape[0]
    n = T if _smooth_length(T) == T else _smooth_length(2 * T - 1)
    power = np.abs(np.fft.rfft(Y, n=n, axis=0)) ** 2
    if not per_column:
        power = np.sum(power, axis=1)
    c = np.fft.irfft(power, n=n, axis=0)
    if n == T:
        return c
    c = c[:T]
    r = c.copy()
    r[1:] += c[:0:-1]
    return r


#: Autocorrelation maxima (fractions of ``r(0)``) this close to the highest count as level with it.
PEAK_TIE = 0.02


#: Values (frames x columns) per block of :func:`autocorrelation_period`: at least 16 columns at a time, as
#: many as fit in 2^18 values (2 MB; 1700 columns of a 150-frame region) so that a wide rig's features are
#: not transformed 16 columns at a time, and a long take's temporaries stay small.
_BLOCK_VALUES = 1 << 18
_COLUMNS = 16
#: From this many frames on, 4 columns at a time: a block's transforms (its padded spectrum is complex and
#: twice the take long) were the largest arrays of ``find_phase`` on a million frames (640 MB at 16 columns).
#: The sum over columns then rounds differently in its last bits; shorter takes are unchanged.
_LONG_TAKE, _LONG_COLUMNS = 1 << 16, 4


def autocorrelation_period(X, min_lag: int = 2, max_lag: int | None = None, min_strength: float = 0.1) -> float:
    """The fundamental cycle (frames) of ``X`` (``(T,)`` or ``(T, D)``) by windowed circular autocorrelation.

    Paper 004: every column is centred and multiplied by a Hann window ``w``, then
    ``r(k) = sum_n w(n)x(n) w((n+k) mod T) x((n+k) mod T)`` (circular, no zero padding, by FFT), summed over
    columns and divided by ``r(0)``.  The window favours the smallest period: ``r`` decays with the lag, so the
    first multiple of the cycle gives the highest maximum.  The period is the lag of the highest local maximum
    in ``[min_lag, max_lag]`` (default ``max_lag = T // 2``; a maximum within :data:`PEAK_TIE` of the
    highest at a whole fraction of its lag is taken instead, which matters on long takes), refined to
    sub-frame precision by a parabola through the peak and its two neighbours of ``r(k)`` divided by the
    window's own autocorrelation (which removes the window's pull towards shorter lags).

    Columns with a NaN or infinite value are dropped; constant columns contribute nothing.  Returns NaN when no
    column is usable, when the signal is constant, or when no maximum reaches ``min_strength * r(0)`` (white
    noise, say; on short noisy signals a chance maximum can pass ``0.1``).
    """
    try:
        A = np.asarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MocycleError(f"X must be a (T,) or (T, D) array of numbers; got {type(X).__name__} ({exc})") from None
    if A.ndim == 1:
        A = A[:, None]
    if A.ndim != 2:
        raise MocycleError(f"X must be a (T,) or (T, D) array; got shape {A.shape}")
    T = A.shape[0]
    min_lag = _positive_int(min_lag, "min_lag")
    if T < 4:
        raise MocycleError(f"the autocorrelation period needs at least 4 frames; got {T}")
    if max_lag is None:
        max_lag = T // 2
    max_lag = _positive_int(max_lag, "max_lag")
    if max_lag > T - 2:
        raise MocycleError(f"max_lag must be at most T - 2 = {T - 2} frames; got {max_lag}")
    if max_lag < min_lag:
        raise MocycleError(f"max_lag ({max_lag}) must not be smaller than min_lag ({min_lag})")
    min_strength = _validate.real("min_strength", min_strength, 0.0, 1.0, high_open=True)

    finite = np.flatnonzero(np.all(np.isfinite(A), axis=0))
    if finite.size == 0:
        return float("nan")
    width = column_block_width(T)
    blocks = (A[:, finite[c0:c0 + width]] for c0 in range(0, finite.size, width))
    return _period_of_column_blocks(blocks, T, min_lag, max_lag, min_strength)


def column_block_width(T: int) -> int:
    """Columns per block of :func:`autocorrelation_period` on ``T`` frames (:data:`_BLOCK_VALUES`)."""
    return max(_COLUMNS if T < _LONG_TAKE else _LONG_COLUMNS, _BLOCK_VALUES // T)


def autocorrelation_period_of_blocks(blocks, T: int, min_lag: int = 2, max_lag: int | None = None,
                                     min_strength: float = 0.1) -> float:
    """:func:`autocorrelation_period` of a ``(T, D)`` array given as its blocks of columns ``(T, d)`` (finite
    values), :func:`column_block_width` columns each: the same number (within the FFT's rounding, which
    follows the blocks' memory layout) for a caller that makes the columns block by block instead of holding
    them all (the loop checks' pose features of a long take)."""
    if T < 4:
        raise MocycleError(f"the autocorrelation period needs at least 4 frames; got {T}")
    max_lag = T // 2 if max_lag is None else max_lag
    if not 1 <= min_lag <= max_lag <= T - 2:
        raise MocycleError(f"need 1 <= min_lag <= max_lag <= T - 2; got {min_lag}, {max_lag} with T = {T}")
    return _period_of_column_blocks(blocks, T, min_lag, max_lag, min_strength)


def _period_of_column_blocks(blocks, T: int, min_lag: int, max_lag: int, min_strength: float) -> float:
    """The core of :func:`autocorrelation_period`: its windowed autocorrelation summed over blocks of columns."""
    window = periodic_hann(T)
    r = np.zeros(T)
    for B in blocks:  # a block of columns at a time: no temporaries as large as the whole array
        B = B - B.mean(axis=0)
        B[:, np.ptp(B, axis=0) == 0.0] = 0.0  # exactly constant columns: remove the rounding left by centring
        r += circular_autocorrelation(B * window[:, None])  # sums over columns: blocks add up
    if not r[0] > 0.0:
        return float("nan")
    return period_from_autocorrelation(r / r[0], circular_autocorrelation(window), min_lag, max_lag, min_strength)


def period_from_autocorrelation(r: np.ndarray, env: np.ndarray, min_lag: int, max_lag: int,
                                min_strength: float) -> float:
    """The cycle (frames) at the highest maximum of a normalised autocorrelation ``r`` ``(T,)`` in
    ``[min_lag, max_lag]``, as :func:`autocorrelation_period` chooses and refines it (``env`` ``(T,)``: the
    window's own circular autocorrelation); NaN when no maximum reaches ``min_strength``."""
    T = r.size
    seg = r[: max_lag + 2]  # the peak's right neighbour must be inside
    peaks = local_maxima(seg)
    peaks = peaks[(peaks >= min_lag) & (peaks <= max_lag)]
    peaks = peaks[seg[peaks] > min_strength]
    if peaks.size == 0:
        return float("nan")
    p = int(peaks[np.argmax(seg[peaks])])
    # On long takes the window hardly decays over a few cycles, so the maxima at the cycle and at its
    # multiples are level and noise picks among them: a maximum within PEAK_TIE of the highest, at a lag the
    # highest is a whole multiple (>= 2) of, is the cycle (on short takes the decay keeps it highest anyway)
    level = peaks[(seg[peaks] >= seg[p] - PEAK_TIE) & (peaks < p)]
    times = p / np.maximum(level, 1)
    whole = (np.round(times) >= 2) & (np.abs(times / np.maximum(np.round(times), 1) - 1) <= 0.1)
    if whole.any():
        p = int(level[whole][0])
    # Refine on r / (the window's own circular autocorrelation): the window's decay would pull the vertex
    # towards smaller lags by up to ~1 % of the period; the division undoes that bias for a stationary signal.
    q = np.arange(p - 2, p + 3) % T  # r is circular
    u = r[q] / env[q]
    c = 1 + int(np.argmax(u[1:4]))  # the largest of lags p-1, p, p+1
    p += c - 2
    left, mid, right = u[c - 1], u[c], u[c + 1]
    curvature = left - 2.0 * mid + right
    shift = 0.5 * (left - right) / curvature if curvature < 0 else 0.0
    return float(p + np.clip(shift, -0.5, 0.5))


# -- remaps of a coordinate to time-uniform phase ----------------------------------------------------------------


def rank_uniform(coords) -> np.ndarray:
    """Spread circle values (cycles) uniformly over ``[0, 1)`` by rank: ``(T,)`` -> ``(T,)`` (KTH eq. 3.20).

    ``x_new_i = rank(x_i) / T`` with 0-based ranks, ties broken by frame order; the output holds exactly the
    values ``0, 1/T, ..., (T-1)/T``.  Inputs are first reduced to ``[0, 1)``.
    """
    x = _circle(coords, "coords")
    ranks = np.empty(x.size, dtype=np.float64)
    ranks[np.argsort(x, kind="stable")] = np.arange(x.size)
    return ranks / x.size


def circle_gmm_cdf(coords, n_components: int = 30, random_state: int | None = 0):
    """The CDF on ``[0, 1)`` of a Gaussian mixture fitted to circle values (cycles) and their copies at -1, +1.

    Paper 001 §5.2: a 1-D mixture of ``n_components`` Gaussians (``reg_covar=1e-5``, 100 EM iterations) is
    fitted to the values and their copies shifted by -1 and +1, so its middle part is close to periodic.
    Returns ``cdf(v)`` with ``cdf(0) = 0``, ``cdf(1) = 1``, non-decreasing: ``(G(v) - G(0)) / (G(1) - G(0))``
    with ``G(v) = sum_k w_k Phi((v - mu_k) / sigma_k)``.  ``n_components`` is capped at the number of
    distinct values (at least 1).  EM that stops at 100 iterations without converging is accepted silently
    (as in paper 001).
    """
    from scipy.stats import norm  # scikit-learn and scipy.stats take a second to import: only here
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.mixture import GaussianMixture

    x = _circle(coords, "coords")
    n_components = _positive_int(n_components, "n_components")
    k = max(1, min(n_components, np.unique(x).size))
    data = np.concatenate([x - 1.0, x, x + 1.0])[:, None]
    gmm = GaussianMixture(n_components=k, covariance_type="full", reg_covar=1e-5, max_iter=100,
                          random_state=random_state)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        gmm.fit(data)
    mu = gmm.means_[:, 0]
    sigma = np.sqrt(gmm.covariances_.reshape(k))
    w = gmm.weights_

    def raw(v: np.ndarray) -> np.ndarray:
        return norm.cdf((np.asarray(v, dtype=np.float64).reshape(-1)[:, None] - mu) / sigma) @ w

    g0, g1 = raw(np.array([0.0, 1.0]))
    if not g1 > g0:
        raise MocycleError("the Gaussian mixture put no mass on [0, 1); cannot remap the coordinate")

    def cdf(v) -> np.ndarray:
        return np.clip((raw(v) - g0) / (g1 - g0), 0.0, 1.0)

    return cdf


def gmm_cdf_remap(coords, n_components: int = 30, random_state: int | None = 0) -> np.ndarray:
    """Remap circle values (cycles) through a Gaussian-mixture CDF: ``(T,)`` -> ``(T,)`` in ``[0, 1]``.

    KTH thesis eq. 3.21 with paper 001 §5.2 (see :func:`circle_gmm_cdf`).  The result is non-decreasing in
    the value, and near uniform over ``[0, 1)`` when the values are spread like time.  Inputs are first
    reduced to ``[0, 1)``.
    """
    x = _circle(coords, "coords")
    return circle_gmm_cdf(x, n_components=n_components, random_state=random_state)(x)


# -- excitation regions (paper 001 §4.6) -------------------------------------------------------------------------


def excitation_regions(coords, window: int, threshold: float = 0.3, min_length: int | None = None,
                       max_gap: int | None = None, min_rate: float | None = None,
                       min_cycles: float = 0.5) -> list[tuple[int, int]]:
    """Frame ranges ``[start, end)`` where a circular coordinate (cycles, ``(T,)``) winds.

    Paper 001 §4.6: "connected parts of the timeseries exhibiting most variation in circular coordinate".
    The winding rate (cycles/frame) is the wrapped difference of consecutive values (in ``[-0.5, 0.5)``,
    centred on the frames), averaged over ``window`` frames (a moving average, so the sign counts and jitter
    cancels).  A frame is excited when ``|rate| >= threshold * (90th percentile of |rate|)`` and ``|rate| >=
    min_rate`` (default ``1 / T``: a coordinate that never reaches one cycle per take has no region).  Runs of
    excited frames closer than ``max_gap`` frames (default ``window``) are merged, then runs shorter than
    ``min_length`` frames (default ``window``) or winding less than ``min_cycles`` cycles in total are dropped.
    Returns sorted, non-overlapping ranges; ``[]`` for a constant coordinate.  The moving average widens each
    region by about ``0.2 * window`` frames at both ends.
    """
    x = _series(coords, "coords")
    T = x.size
    window = _positive_int(window, "window")
    min_length = window if min_length is None else _positive_int(min_length, "min_length")
    max_gap = window if max_gap is None else _positive_int(max_gap, "max_gap", minimum=0)
    for name, value in (("threshold", threshold), ("min_cycles", min_cycles)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) or not np.isfinite(value) \
                or value < 0:
            raise MocycleError(f"{name} must be a finite number >= 0; got {value!r}")
    if min_rate is None:
        min_rate = 1.0 / T
    elif isinstance(min_rate, bool) or not isinstance(min_rate, (int, float, np.number)) \
            or not np.isfinite(min_rate) or min_rate < 0:
        raise MocycleError(f"min_rate must be a finite number >= 0 (cycles per frame); got {min_rate!r}")
    if T < 2:
        return []
    d = _wrapped_diff(x)
    rate = np.concatenate([d[:1], 0.5 * (d[:-1] + d[1:]), d[-1:]])
    smooth = np.abs(moving_average(rate, min(window, T)))
    ref = float(np.percentile(smooth, 90))
    if not ref > 0.0:
        return []
    excited = (smooth >= threshold * ref) & (smooth >= min_rate) & (smooth > 0.0)
    edges = np.diff(np.concatenate([[0], excited.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    if starts.size == 0:
        return []
    merged = [[int(starts[0]), int(ends[0])]]
    for s, e in zip(starts[1:], ends[1:], strict=True):
        if s - merged[-1][1] < max_gap:
            merged[-1][1] = int(e)
        else:
            merged.append([int(s), int(e)])
    cum = np.concatenate([[0.0], np.cumsum(d)])  # cum[i] = unwrapped x[i] - x[0]
    return [(s, e) for s, e in merged
            if e - s >= min_length and abs(cum[e - 1] - cum[s]) >= min_cycles]


# -- self-similarity one period apart ----------------------------------------------------------------------------


def self_similarity(X, lag: float) -> float:
    """How unlike itself ``X`` (``(T,)`` or ``(T, D)``) is ``lag`` frames later: 0 identical, about 1 unrelated.

    ``mean_t ||x(t + lag) - x(t)||² / (2 * total variance)``, with ``x(t + lag)`` linearly interpolated for a
    fractional lag; NaN when fewer than two frames overlap.  A periodic take scores lowest at its period
    (and its multiples), which decides between two nearby period estimates.
    """
    A = np.asarray(X, dtype=np.float64)
    if A.ndim == 1:
        A = A[:, None]
    if A.ndim != 2:
        raise MocycleError(f"X must be a (T,) or (T, D) array; got shape {A.shape}")
    lag = float(lag)
    if not np.isfinite(lag) or lag <= 0:
        return float("nan")
    k = int(np.floor(lag))
    f = lag - k
    n = A.shape[0] - k - 1
    if n < 2:
        return float("nan")
    var = float(A.var(axis=0).sum())
    if not var > 0:
        return float("nan")
    # x(t + lag) - x(t) = x(t + k) + f (x(t + k + 1) - x(t + k)) - x(t), in one buffer
    diff = np.subtract(A[k + 1: k + 1 + n], A[k: k + n])
    diff *= f
    diff += A[k: k + n]
    diff -= A[:n]
    return float(np.einsum("ij,ij->", diff, diff) / n / (2.0 * var))


def repetition_distance(X, period: float, smooth: int = 1) -> np.ndarray:
    """Per frame, how unlike ``X`` (``(T, D)``) is to itself one ``period`` earlier or later: ``(T,)``.

    ``min(||x(t + P) - x(t)||², ||x(t - P) - x(t)||²) / (2 * total variance)`` (linear interpolation for a
    fractional period; only the side inside the take where the other is not), averaged over ``smooth``
    frames.  About 0 where the motion repeats at that period, about 1 or more where it does not (a
    different motion, a transition).  NaN where neither side is inside the take.
    """
    A = np.asarray(X, dtype=np.float64)
    if A.ndim == 1:
        A = A[:, None]
    T = A.shape[0]
    out = np.full(T, np.nan)
    P = float(period)
    var = float(A.var(axis=0).sum())
    if not (np.isfinite(P) and P > 0 and var > 0) or T < 3:
        return out
    t = np.arange(T, dtype=np.float64)

    def at(times: np.ndarray) -> np.ndarray:
        i0 = np.clip(np.floor(times).astype(int), 0, T - 2)
        f = (times - i0)[:, None]
        return (1.0 - f) * A[i0] + f * A[i0 + 1]

    d = np.full((2, T), np.inf)
    for k, sign in enumerate((1.0, -1.0)):
        inside = (t + sign * P >= 0) & (t + sign * P <= T - 1)
        d[k, inside] = np.sum((at(t[inside] + sign * P) - A[inside]) ** 2, axis=1) / (2.0 * var)
    best = d.min(axis=0)
    ok = np.isfinite(best)
    out[ok] = best[ok]
    if smooth > 1 and ok.any():
        filled = np.where(ok, out, np.nanmax(out[ok]))
        out = np.where(ok, moving_average(filled, int(smooth)), np.nan)
    return out
