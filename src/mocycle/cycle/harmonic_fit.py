"""The ``"harmonic"`` cycle: weighted harmonic regression (KTH thesis ch. 3, models M1/M2/M3) of the
cycle-space curves ``P (T, n_periodic)`` and ``L (T, 4)`` along the time axis, sampled at ``N`` frames per
period and started at its calmest point (to a tenth of a frame).
"""

from __future__ import annotations

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError
from ..phase.analysis import PeriodicMotion
from .differences import HALF, central_acceleration, central_velocity
from .harmonic import MODELS, ROWS, HarmonicRegression, max_harmonics
from .metric_rows import loop_blocks_at
from .representation import CycleSpace, EncodedRows
from .result import Cycle, _check_choice
from .seam import calmest_sample
from .timeaxis import TimeAxis

DEFAULT_HARMONICS = defaults.HARMONICS  # the thesis' K
SUBFRAMES = 10           # the harmonic cycle's start is chosen to a tenth of a frame
#: Fewer periods than this: the path's drift is fitted with few harmonics (:func:`short_drift`).
SHORT_PERIODS = 3.0
#: ... this many: the sway of a stride (a hip's swing, a step's sideways shift) and its first overtone.
DRIFT_HARMONICS = 2


def _derivative_part(Y: np.ndarray | EncodedRows, axis: TimeAxis, s: int, e: int, r0: int, r1: int):
    """Velocities and accelerations per period (eq. 3.23-3.25) of region ``[s, e)``'s interior rows ``r0 .. r1-1``
    (frames ``s + HALF + r0 ..``): ``(x, dY, ddY)``, each row read from the stencil's ``2 * HALF + 1`` frames."""
    a, b = s + r0, s + r1 + 2 * HALF  # the frames the rows' stencils read
    if axis.method in ("smooth", "line"):  # the local tempo, frames per period, follows the axis
        rate = central_velocity(axis.x[a:b], 1.0)[:, 0]
    else:                                  # the thesis: t = 1/N everywhere (eq. 3.25)
        rate = np.full(r1 - r0, 1.0 / axis.period_frames)
    dY = central_velocity(Y[a:b], 1.0)
    dY /= rate[:, None]
    ddY = central_acceleration(Y[a:b], 1.0)
    ddY /= rate[:, None] ** 2
    return axis.x[a + HALF:b - HALF], dY, ddY


def _derivative_regions(axis: TimeAxis) -> list[tuple[int, int]]:
    """The regions long enough for the central stencils."""
    return [(s, e) for s, e in axis.regions if e - s >= 2 * HALF + 1]


def _derivative_rows(Y: np.ndarray, axis: TimeAxis):
    """Velocities and accelerations per period (eq. 3.23-3.25) on the interior frames of every region (written
    region by region into one array each: no per-region parts joined afterwards)."""
    regions = _derivative_regions(axis)
    if not regions:
        return None, None, None
    n = sum(e - s - 2 * HALF for s, e in regions)
    xs = np.empty(n)
    dY = np.empty((n,) + Y.shape[1:])
    ddY = np.empty_like(dY)
    r = 0
    for s, e in regions:
        m = e - s - 2 * HALF
        xs[r:r + m], dY[r:r + m], ddY[r:r + m] = _derivative_part(Y, axis, s, e, 0, m)
        r += m
    return xs, dY, ddY


def _derivative_blocks(Y: np.ndarray | EncodedRows, axis: TimeAxis, rows: int = ROWS):
    """:func:`_derivative_rows` as :meth:`HarmonicRegression.fit_blocks` reads them: a function returning a new
    iterator of ``(x, dY, ddY)`` blocks of at most ``rows`` rows, each made from its frames of ``Y`` when it
    is read (a long take's ``(T, D)`` velocities and accelerations are never held whole).  Rows that fit in
    one block are made once and kept for the fit's later passes."""
    parts = [(s, e, r0, min(r0 + rows, e - s - 2 * HALF)) for s, e in _derivative_regions(axis)
             for r0 in range(0, e - s - 2 * HALF, rows)]
    if sum(r1 - r0 for _, _, r0, r1 in parts) <= rows:
        kept = [_derivative_part(Y, axis, *part) for part in parts]
        return lambda: iter(kept)
    return lambda: (_derivative_part(Y, axis, *part) for part in parts)


def _position_blocks(Y: np.ndarray | EncodedRows, axis: TimeAxis, rows: int = ROWS):
    """A function returning a new iterator of ``(x, Y)`` blocks over the axis' frames (views of ``Y``: the
    frames are never copied)."""
    return lambda: ((axis.x[r:min(r + rows, e)], Y[r:min(r + rows, e)]) for s, e in axis.regions
                    for r in range(s, e, rows))


def _rows(Y: np.ndarray, axis: TimeAxis, frames: np.ndarray) -> np.ndarray:
    """``Y[frames]`` for the axis' frames: a view when they are one region (no copy of ``Y``)."""
    if len(axis.regions) == 1:
        s, e = axis.regions[0]
        return Y[s:e]
    return Y[frames]


def _harmonics(harmonics, n_rows: int, cycle_frames: int) -> int:
    limit = max_harmonics(n_rows, cycle_frames)
    if harmonics in (None, "auto"):
        if limit < 1:
            raise MocycleError(f"too few frames for a harmonic fit: {n_rows} frames, {cycle_frames} per cycle")
        return min(DEFAULT_HARMONICS, limit)
    harmonics = _validate.integer("harmonics", harmonics, 1)
    if harmonics > limit:
        raise MocycleError(f"K = {harmonics} harmonics is too many for {n_rows} frames with {cycle_frames} "
                           f"frames per cycle: K must be <= {limit} (2K+1 <= frames and K < frames per cycle / 2)")
    return int(harmonics)


def harmonic_cycle(space: CycleSpace, P: np.ndarray | EncodedRows, L: np.ndarray, axis: TimeAxis,
                   periodic: PeriodicMotion, model: str = "M1", harmonics: int | str = "auto", *,
                   calmest: bool = False, n_harmonics: int | str | None = None) -> Cycle:
    """Fit ``P`` periodically and ``L`` with a linear term on ``axis``, sample one period at ``N`` frames.

    With ``calmest`` the cycle starts at its calmest point, chosen to a tenth of a frame; without, at phase 0
    of the axis.  ``harmonics``: K, the number of harmonics, or ``"auto"`` (``n_harmonics`` is its old name,
    accepted with a DeprecationWarning until the next release).
    """
    harmonics = _validate.renamed("n_harmonics", "harmonics", n_harmonics, harmonics, "auto")
    _check_choice(model, MODELS, "model")
    frames = axis.frames()
    N = int(round(axis.period_frames))
    K = _harmonics(harmonics, frames.size, N)
    x = axis.x[frames]
    if model != "M2" and sum(e - s - 2 * HALF for s, e in _derivative_regions(axis)) < max(2 * K, 1):
        raise MocycleError(f"model {model} needs velocities on at least {2 * K} frames (K = {K}); the excited "
                           f"regions are too short: use option 'model' = M2 or fewer harmonics")
    # On a part of under SHORT_PERIODS periods a linear term fitted beside all the harmonics trades off against
    # them (a turn that speeds up and slows down came out 40 % too fast): there the drift per period is fitted
    # with few harmonics (short_drift), and the harmonics fit what is left.
    drift = short_drift(L, axis) if axis.n_periods < SHORT_PERIODS else None
    if drift is not None:
        L = L - np.outer(np.nan_to_num(axis.x), drift)
    linear = drift is None
    if model == "M1":  # the rows block by block: P's frames, velocities and accelerations are never held whole
        shared: dict = {}  # without the linear term the path's designs are the poses': factored once
        fit_p = HarmonicRegression(K, model).fit_blocks(_position_blocks(P, axis), _derivative_blocks(P, axis),
                                                        shared=shared)
        fit_l = HarmonicRegression(K, model, linear=linear).fit_blocks(_position_blocks(L, axis),
                                                                       _derivative_blocks(L, axis), shared=shared)
        del shared
    else:
        assert isinstance(P, np.ndarray)  # rows made as read are for M1 only (cycle.extract)
        xd, dP, ddP = _derivative_rows(P, axis) if model != "M2" else (None, None, None)
        _, dL, ddL = _derivative_rows(L, axis) if model != "M2" else (None, None, None)
        fit_p = HarmonicRegression(K, model).fit(x, _rows(P, axis, frames), xd, dP, ddP)
        del dP, ddP  # (T, D) each: not held while L is fitted
        fit_l = HarmonicRegression(K, model, linear=linear).fit(x, _rows(L, axis, frames), xd, dL, ddL)
    if drift is None:
        drift = fit_l.drift_

    def path(at):
        return fit_l.predict(at) if linear else fit_l.predict(at) + np.outer(at, drift)

    x0 = float(np.floor(x[0]))
    if calmest:  # start at the calmest step, between frames too
        fine = x0 + np.arange(SUBFRAMES * N) / (SUBFRAMES * N)
        trial = Cycle(space=space, P=fit_p.predict(fine), L=path(fine), drift=drift,
                      method="harmonic", model=model, harmonics=K, axis=axis, positions=np.zeros(0),
                      periodic=periodic)
        # the trial's rotations projected only where the start is looked for (the projection is most of it)
        start = calmest_sample(lambda rows: loop_blocks_at(trial, rows), SUBFRAMES * N, SUBFRAMES)
        x0 += start / (SUBFRAMES * N)
        # the cycle's frames are trial samples start, start + 10, ... (one period on, where they pass its end:
        # the periodic block is the same there): taken, not fitted again
        rows = (start + SUBFRAMES * np.arange(N)) % (SUBFRAMES * N)
        P = trial.P[rows]
        projected = space.project(P)
    else:
        P, projected = fit_p.predict(x0 + np.arange(N) / N), None
    xs = x0 + np.arange(N) / N
    return Cycle(space=space, P=P, L=path(xs), drift=drift, method="harmonic", model=model, harmonics=K,
                 axis=axis, positions=np.mod(x - x0, 1.0) * N, periodic=periodic, regression=fit_p,
                 projected=projected)


def short_drift(L: np.ndarray, axis: TimeAxis, harmonics: int = DRIFT_HARMONICS, *,
                n_harmonics: int | None = None) -> np.ndarray:
    """``(D,)`` change per period of the curves ``L (T, D)`` along ``axis`` on a part of few periods: their
    change between the ends of the longest region over the periods between, once the stride's sway (a line
    and ``harmonics`` harmonics fitted by least squares; only the harmonics are taken out) is removed
    (``n_harmonics``: the old name of ``harmonics``, accepted with a DeprecationWarning until the next release).

    With the cycle's full set of harmonics beside it, a linear term on 1-3 periods trades off against them
    (a turn that speeds up and slows down came out 40 % too fast); a line through a turn that starts and
    ends gently is steeper than the turn made over the part; the bare ends carry the sway of the stride.
    So: the ends (a tenth of a period each), less the sway."""
    harmonics = _validate.renamed("n_harmonics", "harmonics", n_harmonics, harmonics, DRIFT_HARMONICS)
    s, e = max(axis.regions, key=lambda r: r[1] - r[0])
    x = axis.x[s:e]
    Y = np.asarray(L[s:e], dtype=np.float64)
    waves = [f(2 * np.pi * k * x) for k in range(1, harmonics + 1) for f in (np.cos, np.sin)]
    B = np.column_stack([np.ones_like(x), x, *waves])
    if B.shape[0] > B.shape[1]:
        coef, *_ = np.linalg.lstsq(B, Y, rcond=None)
        Y = Y - B[:, 2:] @ coef[2:]
    h = min(max(1, int(round(0.1 * axis.period_frames))), max(1, x.size // 4))
    dx = float(x[-h:].mean() - x[:h].mean())
    return (Y[-h:].mean(axis=0) - Y[:h].mean(axis=0)) / dx if dx > 0 else np.zeros(Y.shape[1])
