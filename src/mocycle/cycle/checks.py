"""Is a cycle a loop?  The checks a cycle must pass before it is written (issue 11).

A cycle is refused (:class:`~mocycle.errors.LoopRefused`, CLI exit 3) when

* **length** — it is longer than the frames it was fitted on: the take does not
  hold one whole cycle, so the "cycle" is an extrapolation (a 573-frame take gave
  an 872-frame cycle);
* **fit** — its template error (thesis eq. 4.4-4.5, the repeated cycle slid along
  the take's longest excited region) is more than :data:`MAX_FIT_RATIO` times (widened for few periods,
  :func:`fit_limit`) that
  of the best *plain cut*: frames ``a .. a+lag`` of the take itself, with ``lag``
  near the found period or near the take's own autocorrelation period
  (:func:`best_cut_error`).  A cut copies the take, so a fitted cycle that fits
  much worse than a copy of one period is not the take's cycle (usually the
  period found is wrong).  An error under :data:`FIT_FLOOR` of the take's own
  spread (RMS distance of its poses from their mean, in the metrics' rotation-matrix
  space: a joint turning full circles adds its circle's radius, not its growing angle) passes whatever the cut
  does: on a noise-free take the cut is exact and any fit is "infinitely" worse;
* **seam** — its wrap jumps: the local seam ratio (the step across the wrap over
  the steps next to it, for pose or velocity, rotations or root path;
  :func:`~mocycle.cycle.seam.seam_ratios`) is above :data:`MAX_SEAM`.

Thresholds, from ``benchmarks/cycles.py`` on the 59 shared walks, runs and dashes
that have a cycle (docs/cycles.md): the template error of the harmonic M1 cycle
over the best cut's is 0.44-1.25 (2.03 on run_chimpira while its period was found
6.6 % short of the legs' own); the local seam ratios stay under 2.2.  A cycle of the
wrong period fits 4-6 times worse than the cut, with an error about the take's
spread (tests/cycle/test_checks.py); on the shared takes the harmonic cycle's error
is 25-50 % of the spread.  A pop that a viewer sees is a step several times its
neighbours.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import LoopRefused, MocycleWarning
from ..motion import Motion
from ..phase.period import autocorrelation_period, autocorrelation_period_of_blocks
from .metric_rows import MetricRows, loop_blocks
from .metrics import template_error
from .result import Cycle
from .seam import seam_ratios

MAX_FIT_RATIO = 2.0   # template error over the best plain cut's
FIT_FLOOR = 0.25      # template errors under this fraction of the take's spread always pass
MAX_SEAM = 3.0        # local seam ratio (step across the wrap over the nearby steps)
CUT_SPAN = 0.15       # the plain cut's lag within 15 % of a period estimate
PERIOD_AGREES = 0.03  # a cut this close to the cycle's period: the period is not what is wrong
MIN_PERIOD_S = 0.25   # the autocorrelation period is searched from a quarter of a second


@dataclass(frozen=True)
class FailedCheck:
    """One check a cycle failed: ``name`` (length, fit, seam), the measured ``value``, its ``limit``."""

    name: str
    value: float
    limit: float
    reason: str

    def to_dict(self) -> dict:
        return {"check": self.name, "value": self.value, "limit": self.limit, "reason": self.reason}


def _plain_cut_error(Y: np.ndarray | MetricRows, period: float, differences: dict | None = None,
                     errors: dict | None = None) -> tuple[float, int]:
    """Template error of the best plain cut of ``Y (M, D)`` with a lag within :data:`CUT_SPAN` of ``period``.

    The cut is frames ``a .. a+lag-1`` between the two windows (a fifth of a period wide) that are most
    alike ``lag`` frames apart, as :func:`~mocycle.cycle.cut.cut_cycle` picks them, without its
    cross-fade.  Returns ``(error, lag)``; NaN error when the frames hold no such pair.  ``differences``:
    lag -> :func:`_lag_differences`, filled and reused across calls on the same ``Y`` (two period estimates
    close together search the same lags); ``errors``: ``(a, lag)`` -> the template error of that cut, likewise
    (they often choose the same cut).
    """
    M = Y.shape[0]
    if not np.isfinite(period) or period < 2:
        return float("nan"), 0
    differences = {} if differences is None else differences
    lags = np.arange(max(2, int(np.floor((1 - CUT_SPAN) * period))), int(np.ceil((1 + CUT_SPAN) * period)) + 1)
    lags = lags[lags < M - 1]
    h = max(1, int(round(0.1 * period)))
    best = (np.inf, 0, 0)
    if isinstance(Y, MetricRows):  # the lags not searched yet, made together
        differences.update(Y.lag_differences_of([lag for lag in lags.tolist() if lag not in differences]))
    for lag in lags:
        lag = int(lag)
        if lag not in differences:
            assert isinstance(Y, np.ndarray)  # a MetricRows' lags were all made above
            differences[lag] = _lag_differences(Y, lag)
        d = differences[lag]
        if d.size < 2 * h + 1:
            continue
        c = np.concatenate([[0.0], np.cumsum(d)])
        cost = (c[2 * h + 1:] - c[:-2 * h - 1]) / (2 * h + 1)
        j = int(np.argmin(cost))
        if cost[j] < best[0]:
            best = (float(cost[j]), j + h, int(lag))
    if not np.isfinite(best[0]):
        return float("nan"), 0
    _, a, lag = best
    a = min(a, M - lag)
    errors = {} if errors is None else errors
    if (a, lag) not in errors:
        errors[a, lag] = template_error(Y, Y[a:a + lag])[0]
    return errors[a, lag], lag


def _lag_differences(Y: np.ndarray, lag: int) -> np.ndarray:
    """``(M - lag,)`` squared distances between the rows of ``Y (M, D)`` ``lag`` rows apart, in blocks of rows
    (no temporaries as large as ``Y``)."""
    M = Y.shape[0]
    d = np.empty(M - lag)
    for r in range(0, M - lag, 8192):
        r1 = min(r + 8192, M - lag)
        d[r:r1] = ((Y[r:r1] - Y[r + lag:r1 + lag]) ** 2).sum(axis=1)
    return d


def moving_columns(Y: np.ndarray) -> np.ndarray:
    """``Y (M, D)`` without its columns that hold one value on every row (joints that never move, the fixed
    entries of a joint turning about one axis): they add exactly nothing to a distance between two of its
    rows, and only rounding to a distance from a cycle fitted to it.  ``Y`` itself when every column moves."""
    moving = np.ptp(Y, axis=0) > 0 if Y.shape[0] else np.ones(Y.shape[1], dtype=bool)
    return Y if moving.all() else Y[:, moving]


def best_cut_error(motion: Motion, cycle: Cycle, reference: np.ndarray | None = None,
                   features: np.ndarray | MetricRows | None = None) -> tuple[float, float]:
    """``(template error of the best plain cut, its length in frames)`` on the cycle's longest excited
    region: the better of cuts near the cycle's period and near the region's own autocorrelation period
    (paper 004 eq. 1 on the pose features; independent of the phase).  ``reference`` changes nothing
    (:func:`~mocycle.cycle.metric_rows.metric_features`); ``features``: the region's metric features when the
    caller has them, an array or a :class:`~mocycle.cycle.metric_rows.MetricRows` (its still columns may be left
    out: :func:`moving_columns`); by default they are made block by block as they are read."""
    s, e = max(cycle.axis.regions, key=lambda r: r[1] - r[0])
    Y = MetricRows(motion, slice(s, e)) if features is None else features
    Y = Y.moving() if isinstance(Y, MetricRows) else moving_columns(Y)
    candidates = [cycle.period_frames]
    if Y.shape[0] >= 8:
        min_lag = max(2, int(round(MIN_PERIOD_S / motion.frame_time)))
        if min_lag <= Y.shape[0] // 2:
            candidates.append(autocorrelation_period_of_blocks(Y.column_blocks(), Y.shape[0], min_lag=min_lag)
                              if isinstance(Y, MetricRows) else autocorrelation_period(Y, min_lag=min_lag))
    best = (float("nan"), float("nan"))
    differences: dict = {}
    errors: dict = {}
    for p in candidates:
        err, lag = _plain_cut_error(Y, p, differences, errors)
        if np.isfinite(err) and not err >= best[0]:
            best = (err, float(lag))
    return best


def fit_limit(frames: int, period: float) -> float:
    """The largest template error of a cycle over the best plain cut's on ``frames`` frames of a ``period``:
    :data:`MAX_FIT_RATIO`, widened by ``sqrt(n / (n - 1))`` for ``n`` periods (at least 2): the cut copies one
    period of the take exactly, its error comes from the other ``n - 1`` only, while a typical cycle errs on all
    ``n`` (on a part of 2 periods the cut copies half of it: limit 2.83; 10 periods: 2.11)."""
    n = max(2.0, frames / period) if np.isfinite(period) and period > 0 else 2.0
    return MAX_FIT_RATIO * float(np.sqrt(n / (n - 1.0)))


def loop_checks(motion: Motion, cycle: Cycle, metrics: dict | None = None) -> list[FailedCheck]:
    """The checks of the module docstring that ``cycle`` (extracted from ``motion``) fails; empty when it is
    a loop.  ``metrics``: :func:`~mocycle.cycle.loop_metrics` of the pair if already computed (saves time)."""
    failed = []
    fitted = int(cycle.axis.frames().size)
    if cycle.n_frames > fitted:
        failed.append(FailedCheck(
            "length", float(cycle.n_frames), float(fitted),
            f"the cycle ({cycle.n_frames} frames) is longer than the {fitted} frames it was fitted on: the take "
            f"holds {cycle.n_periods:.2f} periods, not one whole cycle"))
    s, e = max(cycle.axis.regions, key=lambda r: r[1] - r[0])
    if metrics is not None:
        tmpl = metrics["template_error"]
        seam = max(metrics["seam_pose_local"], metrics["seam_velocity_local"])
    else:
        C, root = loop_blocks(cycle)
        tmpl = template_error(MetricRows(motion, slice(s, e)), C)[0]
        ratios = [seam_ratios(C), seam_ratios(root)]
        seam = max(max(r["pose_local"], r["velocity_local"]) for r in ratios)
    Y = MetricRows(motion, slice(s, e)).moving()  # the longest excited region without its still columns
    cut, cut_period = best_cut_error(motion, cycle, features=Y)
    spread = Y.spread()
    del Y
    limit = fit_limit(e - s, cycle.period_frames)
    if np.isfinite(cut) and not tmpl <= max(limit * cut, FIT_FLOOR * spread):
        why = (f"the period found ({cycle.period_frames:.1f} frames) is probably wrong"
               if abs(cut_period / cycle.period_frames - 1) > PERIOD_AGREES else
               "the take's cycles differ too much for one typical cycle (a cut copies one of them)")
        failed.append(FailedCheck(
            "fit", float(tmpl / cut), limit,
            f"the cycle fits the take {tmpl / cut:.2f} times worse than a plain cut of {cut_period:.0f} frames "
            f"(template error {tmpl:.3g} against {cut:.3g} rad; limit {limit:.3g}×): {why}"))
    if not seam <= MAX_SEAM:
        failed.append(FailedCheck(
            "seam", float(seam), MAX_SEAM,
            f"the seam jumps: the step across the wrap is {seam:.1f} times the steps next to it "
            f"(limit {MAX_SEAM:g})"))
    return failed


def check_loop(motion: Motion, cycle: Cycle, metrics: dict | None = None, force: bool = False,
               label: str | None = None, extra: list[FailedCheck] | None = None,
               skip: tuple[str, ...] = ()) -> list[FailedCheck]:
    """Raise :class:`~mocycle.errors.LoopRefused` when ``cycle`` fails a check of :func:`loop_checks` (or is
    one of ``extra``, checks the caller made); with ``force`` warn instead (naming each failed check) and
    return the failures.  ``label`` names the take; ``skip``: checks that do not apply (a one-cycle clip looped
    as it is has its author's own seam and no second cycle to cut)."""
    failed = [f for f in loop_checks(motion, cycle, metrics) if f.name not in skip] + list(extra or [])
    if not failed:
        return failed
    where = f"{label}: " if label else ""
    text = "; ".join(f"{f.name}: {f.reason}" for f in failed)
    if not force:
        raise LoopRefused(f"{where}not a loop ({text}); option 'force' writes it anyway", failed)
    warnings.warn(f"{where}kept although it fails the loop check(s) {', '.join(f.name for f in failed)} "
                  f"(option 'force'): {text}", MocycleWarning, stacklevel=2)
    return failed
