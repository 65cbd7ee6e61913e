"""Extract one seamless, typical cycle from a take: find its phase, choose the periodic motion, and make the
cycle by one of three methods (:mod:`.harmonic_fit`, :mod:`.centroid`, :mod:`.cut`), each returning a
:class:`~mocycle.cycle.result.Cycle` of ``N`` frames in the :class:`~mocycle.cycle.representation.CycleSpace`.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable

import numpy as np

from .. import defaults
from ..errors import MocycleError, MocycleWarning, NoPeriodicMotion
from ..motion import Motion
from ..phase.analysis import MIN_PERIODS, PeriodicMotion, PhaseResult, find_phase_every
from ..threads import limit_threads
from .centroid import centroid_cycle
from .cut import clip_cycle, cut_cycle
from .harmonic import MODELS
from .harmonic_fit import harmonic_cycle
from .metric_rows import loop_blocks, metric_features
from .representation import CycleSpace, EncodedRows
from .result import Cycle, _check_choice
from .seam import calmest_start
from .timeaxis import TIME_AXES
from .timeaxis import time_axis as make_time_axis

#: Above this size (bytes) the M1 harmonic fit reads the pose rows ``P`` of :meth:`CycleSpace.encode` as it
#: goes (:meth:`CycleSpace.encode_rows`: each of its three passes makes them again) instead of holding them.
LAZY_P_BYTES = 1 << 26

METHODS = defaults.CYCLE_METHODS
FEW_PERIODS = 1.5        # fewer periods than this: warn


def choose_periodic(result: PhaseResult, which: int | None = None) -> PeriodicMotion:
    """The periodic motion to loop: ``which`` (0-based), or the one whose excitation covers most frames."""
    if not result.classes:
        raise NoPeriodicMotion(f"no periodic motion found: {result.reason}")
    if which is None:
        return max(result.classes, key=lambda c: len(c.frames()))
    if not 0 <= which < len(result.classes):
        raise MocycleError(f"class {which} does not exist: {len(result.classes)} periodic motion(s) found")
    return result.classes[which]


def cycle_phase(motion: Motion, *, joints: str | Iterable[str] | None = None, classes: int | str = "auto",
                pca: int | str | None = "auto", delay: int = 2, min_periods: float = MIN_PERIODS,
                step: int = 1) -> PhaseResult:
    """:func:`~mocycle.phase.find_phase` as the cycle extraction calls it, optionally on every
    ``step``-th frame only (the thesis plugin's subsampling), brought back to every frame."""
    return find_phase_every(motion, step, classes=classes, joints=joints, pca=pca, delay=delay,
                            min_periods=min_periods)


@limit_threads
def extract_cycle(motion: Motion, method: str = "harmonic", model: str = "M1", harmonics: int | str = "auto",
                  time_axis: str = "smooth", *, joints: str | Iterable[str] | None = None,
                  classes: int | str = "auto", which: int | None = None, pca: int | str | None = "auto",
                  delay: int = 2, min_periods: float = MIN_PERIODS, phase: PhaseResult | None = None,
                  step: int = 1) -> Cycle:
    """One seamless cycle of ``motion``.

    ``method``: ``harmonic`` | ``centroid`` | ``cut``; ``model``: M1 | M2 | M3 (harmonic only);
    ``harmonics``: K or ``"auto"`` (20, capped by the frames); ``time_axis``: see
    :mod:`~mocycle.cycle.timeaxis`.  The phase options go to :func:`~mocycle.phase.find_phase`:
    ``joints`` (the joints the *phase* is found on; every joint is looped; default the whole body, then
    legs, then arms), ``classes`` (how many periodic motions to look for), ``pca``, ``delay`` and
    ``min_periods``; ``which``: the periodic motion to loop (0-based; default the one covering most frames);
    ``phase``: a :class:`PhaseResult` already computed for this motion (skips :func:`find_phase`);
    ``step``: find the phase on every ``step``-th frame only (the cycle is still built from
    every frame at the capture's rate).
    Raises :class:`NoPeriodicMotion` when the take has none; warns below 1.5 periods.

    Returns
    -------
    Cycle
        ``motion("inplace")`` / ``motion("motion")``: the loop as a Motion; ``repeat(k, root)``: ``k``
        seamless repetitions; ``to_dict()``: period, frames, method, travel and turn per cycle.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion
    >>> cycle = extract_cycle(walk, method="harmonic", model="M1")
    >>> cycle.n_frames, cycle.harmonics
    (60, 20)
    >>> cycle.motion("inplace").n_frames, cycle.repeat(3, root="motion").n_frames
    (60, 180)
    """
    t0 = time.perf_counter()
    if not isinstance(motion, Motion):
        raise MocycleError(f"extract_cycle needs a Motion; got {type(motion).__name__}")
    _check_choice(method, (*METHODS, "clip"), "method")  # "clip": a one-cycle take as it is (cycle.parts)
    _check_choice(time_axis, TIME_AXES, "time_axis")
    if method == "harmonic":
        _check_choice(model, MODELS, "model")
    if phase is None:
        phase = cycle_phase(motion, joints=joints, classes=classes, pca=pca, delay=delay, min_periods=min_periods,
                            step=step)
    periodic = choose_periodic(phase, which)
    axis = make_time_axis(periodic, time_axis)
    if axis.n_periods < FEW_PERIODS:
        warnings.warn(f"only {axis.n_periods:.2f} periods found (fewer than {FEW_PERIODS}); the cycle rests on "
                      f"little evidence", MocycleWarning, stacklevel=2)
    space = CycleSpace.fit(motion)
    P: np.ndarray | EncodedRows
    if method == "harmonic" and model == "M1" and motion.n_frames * space.n_periodic * 8 > LAZY_P_BYTES:
        P, L = space.encode_rows(motion)  # the fit reads P's rows block by block: made as read, never held
    else:
        P, L = space.encode(motion)
    # The path is fitted straightened (periodic plus a line) and turned back along the cycle's heading.
    trend = space.heading_trend(L[:, 3], axis.period_frames)  # the heading without its sway: made once
    Q = space.straighten(L, axis.period_frames, trend)
    # The cut's wrap is its seam; the others have none, so they start at the calmest point.
    if method == "harmonic":
        cycle = harmonic_cycle(space, P, Q, axis, periodic, model, harmonics, calmest=True)
    elif method == "centroid":
        assert isinstance(P, np.ndarray)  # rows made as read are for the harmonic fit only
        cycle = centroid_cycle(space, P, Q, axis, periodic)
        cycle = cycle.rolled(calmest_start(*loop_blocks(cycle)))
    elif method == "clip":
        assert isinstance(P, np.ndarray)
        cycle = clip_cycle(space, P, Q, axis, periodic)
    else:
        assert isinstance(P, np.ndarray)
        cycle = cut_cycle(space, P, Q, axis, periodic, metric_features(motion))
    path, drift = space.bend(cycle.L, cycle.drift, trend[0])
    cycle = cycle.on_path(path, drift)  # the same P: the same rotation matrices
    cycle.seconds = time.perf_counter() - t0
    return cycle
