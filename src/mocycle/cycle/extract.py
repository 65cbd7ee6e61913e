"""Extract one seamless, typical cycle from a take: three methods, one result type.

* ``"harmonic"`` — weighted harmonic regression (KTH thesis ch. 3, models M1/M2/M3),
  sampled at ``N`` frames per period;
* ``"centroid"`` — paper 001 §4.4: Gaussian-mixture density of the circular
  coordinate, ``S`` quantile samples, centroid of the ``k`` nearest frames in phase,
  resampled to ``N`` frames;
* ``"cut"`` — the baseline animators know: the two most similar poses about one
  period apart, the frames between them, the seam cross-faded.

All three work in the :class:`~mocycle.cycle.representation.CycleSpace`
(rotation matrices, translations; travel-joint translation and heading with a
per-cycle drift) and return a :class:`Cycle`, which decodes to a Motion with
the root in place or moving on, and repeats seamlessly.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError, MocycleWarning, NoPeriodicMotion
from ..features import pose_matrix
from ..limits import check_frames
from ..motion import ROTATION_CHANNELS, Motion
from ..phase.analysis import MIN_PERIODS, PeriodicMotion, PhaseResult, find_phase
from ..phase.period import circle_gmm_cdf
from ..rotations import axis_rotations, continuous_quats, matrix_quats, vector_norms
from ..threads import limit_threads
from .differences import HALF, central_acceleration, central_velocity
from .harmonic import MODELS, ROWS, HarmonicRegression, max_harmonics
from .representation import CycleSpace
from .seam import calmest_start
from .timeaxis import TIME_AXES, TimeAxis, time_axis

#: Above this size (bytes) the M1 harmonic fit reads the pose rows ``P`` of :meth:`CycleSpace.encode` as it
#: goes (:meth:`CycleSpace.encode_rows`: each of its three passes makes them again) instead of holding them.
LAZY_P_BYTES = 1 << 26

METHODS = ("harmonic", "centroid", "cut")
ROOT_MODES = ("inplace", "motion")
DEFAULT_HARMONICS = 20   # the thesis' K
FEW_PERIODS = 1.5        # fewer periods than this: warn
CENTROID_SAMPLES = 500   # paper 001 §6: 500 sampled coordinate values
CENTROID_NEIGHBOURS = 10  # paper 001 §6: 10 nearest neighbours
SUBFRAMES = 10           # the harmonic cycle's start is chosen to a tenth of a frame


@dataclass(kw_only=True)
class Cycle:
    """One cycle of ``N`` frames (frame ``N`` would equal frame 0) and how it was made.

    ``P``: ``(N, n_periodic)`` and ``L``: ``(N, 4)`` in the cycle space, ``L`` with its drift;
    ``drift``: ``(4,)`` change of ``L`` over one cycle (horizontal travel per cycle, turn per cycle);
    ``positions``: ``(M,)`` where each frame of ``axis.frames()`` falls in the cycle, in cycle frames.

    The drift carries only what a loop may keep doing: travel across the floor and turn about the
    vertical.  A vertical component (a take whose root rises or sinks slowly: capture drift, a ramp)
    is taken out of ``drift`` and of ``L`` on construction, so the root's height is periodic and
    ``repeat(20, root="motion")`` neither floats nor sinks.
    """

    space: CycleSpace
    P: np.ndarray
    L: np.ndarray
    drift: np.ndarray
    method: str
    model: str | None
    n_harmonics: int | None
    axis: TimeAxis
    positions: np.ndarray
    periodic: PeriodicMotion
    regression: HarmonicRegression | None = field(default=None, repr=False)
    seconds: float = 0.0
    #: :func:`loop_blocks` of this cycle and ``space.project(P)``, once made (not copied by ``dataclasses.replace``)
    _blocks: tuple | None = field(default=None, init=False, repr=False, compare=False)
    _projected: np.ndarray | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        up = self.space.up
        rise = float(self.drift[:3] @ up)
        if rise != 0.0:  # level the drift: only horizontal travel and the turn about the vertical remain
            ramp = np.arange(self.P.shape[0])[:, None] / self.P.shape[0]
            self.L = self.L.copy()
            self.L[:, :3] -= ramp * (rise * up)
            self.drift = self.drift.copy()
            self.drift[:3] -= rise * up

    def __getstate__(self) -> dict:
        """Pickled without the caches ``_blocks`` and ``_projected`` (made again from ``P`` when asked for)."""
        return {**self.__dict__, "_blocks": None, "_projected": None}

    @property
    def n_frames(self) -> int:
        return self.P.shape[0]

    def _rotations(self, count: int = 1) -> np.ndarray:
        """``space.project(P)`` ``(N, J, 3, 3)``, made once, repeated ``count`` times: every motion of the
        cycle (in place, moving on, repeated, the seam's blocks) has these rotations, only the travel joint's
        heading differs."""
        if self._projected is None:
            self._projected = self.space.project(self.P)
        return self._projected if count == 1 else np.tile(self._projected, (count, 1, 1, 1))

    @property
    def period_frames(self) -> float:
        """The input's period in frames (the cycle has ``round`` of it, the cut its own length)."""
        return self.axis.period_frames

    @property
    def n_periods(self) -> float:
        return self.axis.n_periods

    def rolled(self, k: int) -> Cycle:
        """The same loop started at its frame ``k``: frames ``N..N+k-1`` are the first ones moved on by the
        drift.  Exact for a path in the straight form the cycles are fitted and blended in (periodic plus a
        line); :meth:`repeat` turns each repeat as a whole."""
        N, k = self.n_frames, int(k) % self.n_frames
        if k == 0:
            return self
        idx = (np.arange(N) + k) % N
        L = self.L[idx] + np.outer(np.arange(N) + k >= N, self.drift)
        return replace(self, P=self.P[idx], L=L, positions=np.mod(self.positions - k, N))

    def _next_repeat(self, L: np.ndarray, times: int = 1) -> np.ndarray:
        """Rows of ``L`` as they are ``times`` repeats later: the rigid motion of one cycle (the turn about the
        vertical through the first frame's position, then the travel) applied ``times`` times."""
        p0 = self.L[0, :3]
        out = L.copy()
        for _ in range(times):
            R = axis_rotations(self.space.up, np.array([self.drift[3]]))[0]
            out[:, :3] = (out[:, :3] - p0) @ R.T + p0 + self.drift[:3]
            out[:, 3] += self.drift[3]
        return out

    def _inplace_L(self) -> np.ndarray:
        """``L (N, 4)`` walking on the spot: the path straightened (each step turned back by the turn spread
        evenly over the cycle, so a turning walk's steps line up as a straight walk's) and its travel and turn
        taken out along a ramp.  Position and velocity both wrap seamlessly; a straight walk's path is only
        ramped.  :func:`drifting_L` is the inverse."""
        N = self.n_frames
        ramp = np.arange(N) / N
        full = np.vstack([self.L, self._next_repeat(self.L[:1])])  # the next repeat's first frame closes it
        steps = np.einsum("tij,tj->ti", _step_turns(self.space.up, self.drift[3], N).swapaxes(1, 2),
                          np.diff(full[:, :3], axis=0))
        path = full[0, :3] + np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])  # (N + 1, 3)
        out = self.L.copy()
        out[:, :3] = path[:-1] - ramp[:, None] * (path[-1] - path[0])
        out[:, 3] -= ramp * self.drift[3]
        return out

    def motion(self, root: str = "inplace") -> Motion:
        """The cycle as a Motion; ``root="inplace"`` walks on the spot, ``"motion"`` moves on by ``drift``."""
        _check_choice(root, ROOT_MODES, "root")
        return self.space.decode(self.P, self._inplace_L() if root == "inplace" else self.L, self._rotations())

    def repeat(self, count: int, root: str = "inplace") -> Motion:
        """The cycle ``count`` times, seamlessly; with ``root="motion"`` each repeat starts where the last ends."""
        _check_choice(root, ROOT_MODES, "root")
        count = _validate.integer("count", count, 1)
        check_frames(count * self.n_frames, self.space.skeleton.n_joints,
                     f"{count} cycles of {self.n_frames} frames")
        return self.space.decode(np.tile(self.P, (count, 1)), self._repeat_L(count, root), self._rotations(count))

    def _repeat_L(self, count: int, root: str) -> np.ndarray:
        """``L (count * N, 4)`` of :meth:`repeat`."""
        if root == "inplace":
            return np.tile(self._inplace_L(), (count, 1))
        Ls = [self.L]
        for _ in range(count - 1):  # each repeat is the last one moved rigidly: a turning walk walks a circle
            Ls.append(self._next_repeat(Ls[-1]))
        return np.concatenate(Ls)

    def repeat_path(self, count: int, root: str = "inplace") -> np.ndarray:
        """``space.path(repeat(count, root))`` ``(count * N, 4)``, the same numbers, from the travel joint alone:
        its rotation decoded as :meth:`repeat` and the Motion it makes do (quaternions, signs made continuous,
        normalised), no other joint's (a long view's ``(T, J, 3, 3)`` rotations and their quaternions are
        never made)."""
        _check_choice(root, ROOT_MODES, "root")
        count = _validate.integer("count", count, 1)
        space = self.space
        L = self._repeat_L(count, root)
        R = np.tile(self._rotations()[:, space.travel], (count, 1, 1))
        R = space.heading_rotations(L) @ R
        q = continuous_quats(matrix_quats(R[:, None]), inplace=True)  # decode
        q /= vector_norms(q, keepdims=True)  # Motion's own normalisation
        q = continuous_quats(q, inplace=True)[:, 0]
        psi = space.heading(Rotation.from_quat(q).as_matrix())
        return np.concatenate([L[:, :3], psi[:, None]], axis=1)

    def to_dict(self) -> dict:
        return {
            "period_frames": self.period_frames,
            "cycle_frames": self.n_frames,
            "n_periods": self.n_periods,
            "method": self.method,
            "model": self.model,
            "harmonics": self.n_harmonics,
            "time_axis": self.axis.method,
            "travel_per_cycle": self.drift[:3].tolist(),
            "turn_per_cycle_deg": float(np.degrees(self.drift[3])),
            **self.periodic.provenance(),
        }


def _step_turns(up: np.ndarray, turn: float, n: int) -> np.ndarray:
    """Rotations ``(n, 3, 3)`` about ``up`` by the turn ``turn`` (rad per cycle) spread over a cycle of ``n``
    frames, at the middle of each step ``k -> k + 1``."""
    return axis_rotations(up, turn * (np.arange(n) + 0.5) / n)


def drifting_L(up: np.ndarray, inplace: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """The cycle's ``L (N, 4)`` that moves on by ``drift (4,)`` (travel in the file's frame, turn in rad) and
    walks on the spot as ``inplace (N, 4)``: the inverse of ``Cycle._inplace_L``.  The straight travel ``s``
    that, bent by the turn, ends at ``drift[:3]`` solves ``mean_k(R_k) s = drift - sum_k R_k (step_k)``."""
    N = inplace.shape[0]
    R = _step_turns(up, drift[3], N)
    d_in = np.diff(np.vstack([inplace[:, :3], inplace[:1, :3]]), axis=0)  # (N, 3), closing step included
    rhs = drift[:3] - np.einsum("tij,tj->i", R, d_in)
    s = np.linalg.lstsq(R.mean(axis=0), rhs, rcond=None)[0]
    steps = np.einsum("tij,tj->ti", R, d_in + s / N)
    out = inplace.copy()
    out[1:, :3] = inplace[0, :3] + np.cumsum(steps[:-1], axis=0)
    out[:, 3] += np.arange(N) / N * drift[3]
    return out


def _check_choice(value, choices, name):
    _validate.choice(name, value, choices)


# ------------------------------------------------------------------ harmonic
def _derivative_part(Y: np.ndarray, axis: TimeAxis, s: int, e: int, r0: int, r1: int):
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


def _derivative_blocks(Y: np.ndarray, axis: TimeAxis, rows: int = ROWS):
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


def _position_blocks(Y: np.ndarray, axis: TimeAxis, rows: int = ROWS):
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


def _harmonics(n_harmonics, n_rows: int, cycle_frames: int) -> int:
    limit = max_harmonics(n_rows, cycle_frames)
    if n_harmonics in (None, "auto"):
        if limit < 1:
            raise MocycleError(f"too few frames for a harmonic fit: {n_rows} frames, {cycle_frames} per cycle")
        return min(DEFAULT_HARMONICS, limit)
    n_harmonics = _validate.integer("n_harmonics", n_harmonics, 1)
    if n_harmonics > limit:
        raise MocycleError(f"K = {n_harmonics} harmonics is too many for {n_rows} frames with {cycle_frames} "
                           f"frames per cycle: K must be <= {limit} (2K+1 <= frames and K < frames per cycle / 2)")
    return int(n_harmonics)


def harmonic_cycle(space: CycleSpace, P: np.ndarray, L: np.ndarray, axis: TimeAxis, periodic: PeriodicMotion,
                   model: str = "M1", n_harmonics: int | str = "auto", reference: np.ndarray | None = None,
                   *, calmest: bool | None = None) -> Cycle:
    """Fit ``P`` periodically and ``L`` with a linear term on ``axis``, sample one period at ``N`` frames.

    With ``calmest`` (default: when a ``reference`` is given, the input's mean rotation per joint ``(J, 4)``,
    whose value changes nothing) the cycle starts at its calmest point, chosen to a tenth of a frame;
    without, at phase 0 of the axis.
    """
    _check_choice(model, MODELS, "model")
    frames = axis.frames()
    N = int(round(axis.period_frames))
    K = _harmonics(n_harmonics, frames.size, N)
    x = axis.x[frames]
    if model != "M2" and sum(e - s - 2 * HALF for s, e in _derivative_regions(axis)) < max(2 * K, 1):
        raise MocycleError(f"model {model} needs velocities on at least {2 * K} frames (K = {K}); the excited "
                           f"regions are too short: use --model M2 or fewer harmonics")
    # On a part of under SHORT_PERIODS periods a linear term fitted beside all the harmonics trades off against
    # them (a turn that speeds up and slows down came out 40 % too fast): there the drift per period is fitted
    # with few harmonics (short_drift), and the harmonics fit what is left.
    drift = short_drift(L, axis) if axis.n_periods < SHORT_PERIODS else None
    if drift is not None:
        L = L - np.outer(np.nan_to_num(axis.x), drift)
    linear = drift is None
    if model == "M1":  # the rows block by block: P's frames, velocities and accelerations are never held whole
        fit_p = HarmonicRegression(K, model).fit_blocks(_position_blocks(P, axis), _derivative_blocks(P, axis))
        fit_l = HarmonicRegression(K, model, linear=linear).fit_blocks(_position_blocks(L, axis),
                                                                       _derivative_blocks(L, axis))
    else:
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
    if calmest or (calmest is None and reference is not None):  # start at the calmest step, between frames too
        fine = x0 + np.arange(SUBFRAMES * N) / (SUBFRAMES * N)
        trial = Cycle(space=space, P=fit_p.predict(fine), L=path(fine), drift=drift,
                      method="harmonic", model=model, n_harmonics=K, axis=axis, positions=np.zeros(0),
                      periodic=periodic)
        start = calmest_start(*loop_blocks(trial), stride=SUBFRAMES)
        x0 += start / (SUBFRAMES * N)
        # the cycle's frames are trial samples start, start + 10, ... (one period on, where they pass its end:
        # the periodic block and its projection are the same there): taken, not fitted and projected again
        rows = (start + SUBFRAMES * np.arange(N)) % (SUBFRAMES * N)
        P, projected = trial.P[rows], trial._rotations()[rows]
    else:
        P, projected = fit_p.predict(x0 + np.arange(N) / N), None
    xs = x0 + np.arange(N) / N
    cycle = Cycle(space=space, P=P, L=path(xs), drift=drift, method="harmonic", model=model,
                  n_harmonics=K, axis=axis, positions=np.mod(x - x0, 1.0) * N, periodic=periodic, regression=fit_p)
    cycle._projected = projected
    return cycle


#: Fewer periods than this: the path's drift is fitted with few harmonics (:func:`short_drift`).
SHORT_PERIODS = 3.0
#: ... this many: the sway of a stride (a hip's swing, a step's sideways shift) and its first overtone.
DRIFT_HARMONICS = 2


def short_drift(L: np.ndarray, axis: TimeAxis, n_harmonics: int = DRIFT_HARMONICS) -> np.ndarray:
    """``(D,)`` change per period of the curves ``L (T, D)`` along ``axis`` on a part of few periods: their
    change between the ends of the longest region over the periods between, once the stride's sway (a line
    and ``n_harmonics`` harmonics fitted by least squares; only the harmonics are taken out) is removed.

    With the cycle's full set of harmonics beside it, a linear term on 1-3 periods trades off against them
    (a turn that speeds up and slows down came out 40 % too fast); a line through a turn that starts and
    ends gently is steeper than the turn made over the part; the bare ends carry the sway of the stride.
    So: the ends (a tenth of a period each), less the sway."""
    s, e = max(axis.regions, key=lambda r: r[1] - r[0])
    x = axis.x[s:e]
    Y = np.asarray(L[s:e], dtype=np.float64)
    waves = [f(2 * np.pi * k * x) for k in range(1, n_harmonics + 1) for f in (np.cos, np.sin)]
    B = np.column_stack([np.ones_like(x), x, *waves])
    if B.shape[0] > B.shape[1]:
        coef, *_ = np.linalg.lstsq(B, Y, rcond=None)
        Y = Y - B[:, 2:] @ coef[2:]
    h = min(max(1, int(round(0.1 * axis.period_frames))), max(1, x.size // 4))
    dx = float(x[-h:].mean() - x[:h].mean())
    return (Y[-h:].mean(axis=0) - Y[:h].mean(axis=0)) / dx if dx > 0 else np.zeros(Y.shape[1])


# ------------------------------------------------------------------ centroid
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
    return Cycle(space=space, P=Pn, L=Ln, drift=drift, method="centroid", model=None, n_harmonics=None, axis=axis,
                 positions=positions, periodic=periodic)


# ----------------------------------------------------------------------- cut
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
    _, a, lag = best
    b = a + lag
    w = int(min(round(blend * lag), a - s))
    Pc, Lc = P[a:b].copy(), L[a:b].copy()
    drift = L[b] - L[a]
    if w >= 1:
        k = np.arange(lag - w, lag)
        t = _smoothstep((k - (lag - w) + 1) / (w + 1))[:, None]
        src = a + k - lag
        Pc[k] = (1 - t) * P[a + k] + t * P[src]
        Lc[k] = (1 - t) * L[a + k] + t * (L[src] + drift)
    x = axis.x[axis.frames()]
    positions = np.mod(x - axis.x[a], 1.0) * lag
    return Cycle(space=space, P=Pc, L=Lc, drift=drift, method="cut", model=None, n_harmonics=None, axis=axis,
                 positions=positions, periodic=periodic)


# ------------------------------------------------------------------ pipeline
def metric_features(motion: Motion, reference: np.ndarray | None = None, rows: slice = slice(None)) -> np.ndarray:
    """``(T, 9J)`` the space the loop metrics are measured in: every joint's rotation matrix (its 9 entries,
    :func:`~mocycle.features.pose_matrix` ``rotmat``) divided by √2.

    The distance between two poses is then, per joint, ``||R1 - R2||_F / √2 = 2 sin(θ/2)`` for a relative
    rotation of ``θ``: about ``θ`` in radians for small angles (0.5 % short at 20°, 4 % at 60°), and, unlike
    a rotation vector, continuous for a joint that turns a full circle every cycle (no wrap at ±π); it is
    the same wrap-free space the cycle is regressed in (:class:`~mocycle.cycle.representation.CycleSpace`).
    ``reference`` (``(J, 4)``, the input's mean rotation per joint, as the callers pass it) changes no
    distance in this space and is accepted for the callers' sake only; values are not relative to it.
    ``rows``: only these frames (a slice), without copying the motion.  Computed block by block of frames:
    the same numbers as ``pose_matrix(motion, rep="rotmat", root="drop")[0] / √2``.
    """
    joints = _rotation_joints(motion.skeleton)
    if not joints:
        return pose_matrix(motion, rep="rotmat", root="drop")[0]  # raises: no features
    quats = motion.rotations[rows]
    T = quats.shape[0]
    out = np.empty((T, 9 * len(joints)))
    for f0 in range(0, T, 8192):
        block = np.take(quats[f0:f0 + 8192], joints, axis=1)  # contiguous, unlike [:, joints]
        out[f0:f0 + 8192] = Rotation.from_quat(block.reshape(-1, 4)).as_matrix().reshape(block.shape[0], -1)
    out /= np.sqrt(2.0)
    return out


def _rotation_joints(skeleton) -> list[int]:
    """The joints :func:`metric_features` measures: those with rotation channels."""
    return [j for j, channels in enumerate(skeleton.channels) if any(c in ROTATION_CHANNELS for c in channels)]


class MetricRows:
    """``metric_features(motion, rows=region)[:, columns]`` made a block of rows (or of columns) at a time when
    read, never held whole: a long take's ``(T, 9J)`` array (158 MB for 100k frames of 22 joints) was the
    largest thing the loop metrics and checks held.

    ``rows[a:b]`` and ``rows[index array]`` are those rows of the array ``(n, len(columns))``, the same numbers
    (each block made as :func:`metric_features` makes its blocks, columns picked as ``array[:, columns]``
    picks them); :meth:`region` is a block of frames, :meth:`select` and :meth:`moving` pick columns;
    :meth:`column_blocks` feeds :func:`~mocycle.phase.period.autocorrelation_period_of_blocks`;
    :meth:`lag_differences` gives the squared row distances ``lag`` rows apart from the quaternions
    (``||R1 - R2||²/2 = 4 sin²(θ/2) = 4 (1 - (q1·q2)²)`` per moving joint, within 1e-15 of the largest of the
    rows' own); :meth:`spread` the RMS distance of the rows from their mean row."""

    BLOCK = 8192

    def __init__(self, motion: Motion, region: slice = slice(None), columns: np.ndarray | None = None):
        self.quats = motion.rotations[region]
        self.joints = np.asarray(_rotation_joints(motion.skeleton), dtype=np.intp)
        if self.joints.size == 0:
            metric_features(motion, rows=region)  # raises: no features
        self.every = columns is None
        self.columns = np.arange(9 * self.joints.size) if columns is None else np.asarray(columns, dtype=np.intp)
        self.shape = (self.quats.shape[0], int(self.columns.size))
        self.ndim = 2

    def _like(self, quats: np.ndarray, columns: np.ndarray | None) -> MetricRows:
        out = object.__new__(MetricRows)
        out.quats, out.joints, out.every = quats, self.joints, columns is None
        out.columns = self.columns if columns is None else columns
        out.shape, out.ndim = (quats.shape[0], int(out.columns.size)), 2
        return out

    def region(self, start: int, stop: int) -> MetricRows:
        """Rows ``start:stop`` as another :class:`MetricRows` (nothing is made)."""
        return self._like(self.quats[start:stop], None if self.every else self.columns)

    def select(self, keep: np.ndarray) -> MetricRows:
        """The columns where the boolean ``keep`` ``(n_columns,)`` is true."""
        return self._like(self.quats, self.columns[np.asarray(keep, dtype=bool)])

    def still(self) -> np.ndarray:
        """``(n_columns,)`` True where a column holds one value on every row (``np.ptp(rows, axis=0) == 0``)."""
        lo = hi = None
        for r0 in range(0, self.shape[0], self.BLOCK):
            raw = self._raw(self.quats[r0:r0 + self.BLOCK])
            lo = raw.min(axis=0) if lo is None else np.minimum(lo, raw.min(axis=0))
            hi = raw.max(axis=0) if hi is None else np.maximum(hi, raw.max(axis=0))
        if lo is None:
            return np.zeros(self.shape[1], dtype=bool)
        return (hi - lo == 0)[self.columns]

    def moving(self) -> MetricRows:
        """Without the still columns (:func:`~mocycle.cycle.checks.moving_columns`); itself when all move."""
        still = self.still()
        return self if not still.any() else self.select(~still)

    def _raw(self, quats: np.ndarray, joints: np.ndarray | None = None) -> np.ndarray:
        """All 9 entries per joint (of ``joints``, default every rotation joint) of the frames ``quats``."""
        block = np.take(quats, self.joints if joints is None else joints, axis=1)
        out = Rotation.from_quat(block.reshape(-1, 4)).as_matrix().reshape(block.shape[0], -1)
        out /= np.sqrt(2.0)
        return out

    def _pick(self, raw: np.ndarray) -> np.ndarray:
        return raw if self.every else raw[:, self.columns]  # laid out as array[:, columns]: the same rounding

    def __getitem__(self, key) -> np.ndarray:
        if isinstance(key, slice):
            if key.step not in (None, 1):
                raise TypeError("MetricRows reads a slice of rows with step 1")
            r0, r1, _ = key.indices(self.shape[0])
            if r1 <= r0:
                return np.empty((0, self.shape[1]))
            blocks = [self._raw(self.quats[a:min(r1, a + self.BLOCK)]) for a in range(r0, r1, self.BLOCK)]
            return self._pick(blocks[0] if len(blocks) == 1 else np.concatenate(blocks, axis=0))
        index = np.asarray(key)
        if index.ndim != 1 or index.dtype.kind not in "iu":
            raise TypeError("MetricRows reads a slice of rows or a 1-D array of row indices")
        blocks = [self._raw(np.take(self.quats, index[a:a + self.BLOCK], axis=0))
                  for a in range(0, index.size, self.BLOCK)] or [np.empty((0, 9 * self.joints.size))]
        return self._pick(blocks[0] if len(blocks) == 1 else np.concatenate(blocks, axis=0))

    def column_blocks(self):
        """The columns, :func:`~mocycle.phase.period.column_block_width` at a time, all rows each ``(n, d)``."""
        from ..phase.period import column_block_width

        M, width = self.shape[0], column_block_width(self.shape[0])
        for c0 in range(0, self.shape[1], width):
            cols = self.columns[c0:c0 + width]
            ks = np.unique(cols // 9)  # the joints (positions in self.joints) these columns belong to
            local = np.searchsorted(ks, cols // 9) * 9 + cols % 9
            out = np.empty((M, cols.size))
            for r0 in range(0, M, self.BLOCK):
                out[r0:r0 + self.BLOCK] = self._raw(self.quats[r0:r0 + self.BLOCK], self.joints[ks])[:, local]
            yield out

    def lag_differences(self, lag: int) -> np.ndarray:
        """``(n - lag,)`` squared distances between rows ``lag`` apart (see the class docstring)."""
        M = self.shape[0]
        d = np.empty(max(0, M - lag))
        joints = self.joints[np.unique(self.columns // 9)]  # those with a column here: the others add nothing
        every = np.array_equal(joints, np.arange(self.quats.shape[1]))
        for r in range(0, M - lag, self.BLOCK):
            r1 = min(r + self.BLOCK, M - lag)
            a, b = self.quats[r:r1], self.quats[r + lag:r1 + lag]
            if not every:
                a, b = np.take(a, joints, axis=1), np.take(b, joints, axis=1)
            cos = np.einsum("tjk,tjk->tj", a, b)  # cos(θ/2) per joint, up to sign
            d[r:r1] = 4.0 * (joints.size - np.einsum("tj,tj->t", cos, cos))
        return d

    def spread(self) -> float:
        """RMS distance of the rows from their mean row."""
        M = self.shape[0]
        mean = sum(self[r:r + self.BLOCK].sum(axis=0) for r in range(0, M, self.BLOCK)) / M
        return float(np.sqrt(sum(float(((self[r:r + self.BLOCK] - mean) ** 2).sum())
                                 for r in range(0, M, self.BLOCK)) / M))


def loop_blocks(cycle: Cycle, reference: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """What the seam of a cycle is judged on: its in-place rotations as :func:`metric_features` ``(N, 9J)``
    and the world path of its travel joint ``(N, 3)``.

    Made from the decoded rotation matrices directly (the numbers of ``metric_features`` and
    ``world_positions`` of ``cycle.motion("inplace")`` within rounding, without building the motion or
    running forward kinematics of every joint), and kept on the cycle: the metrics and the checks ask
    for the same blocks.  ``reference`` changes nothing (see :func:`metric_features`)."""
    if cycle._blocks is None:
        space = cycle.space
        joints = _rotation_joints(space.skeleton)
        if not joints:
            raise MocycleError("no features: the selected joints have no rotation channels and the root is dropped")
        L = cycle._inplace_L()
        R = cycle._rotations()  # local rotations; the travel joint's without its heading, which is put in below
        travel = space.heading_rotations(L) @ R[:, space.travel]
        every = len(joints) == space.n_joints
        C = (R if every else np.take(R, joints, axis=1)).reshape(R.shape[0], -1) / np.sqrt(2.0)
        if space.travel in joints:
            at = space.travel if every else joints.index(space.travel)
            C[:, 9 * at:9 * at + 9] = travel.reshape(-1, 9) / np.sqrt(2.0)
        cycle._blocks = (C, space.travel_path(R, space.translations(cycle.P, L), travel))
    return cycle._blocks


def choose_periodic(result: PhaseResult, which: int | None = None) -> PeriodicMotion:
    """The periodic motion to loop: ``which`` (0-based), or the one whose excitation covers most frames."""
    if not result.classes:
        raise NoPeriodicMotion(f"no periodic motion found: {result.reason}")
    if which is None:
        return max(result.classes, key=lambda c: len(c.frames()))
    if not 0 <= which < len(result.classes):
        raise MocycleError(f"class {which} does not exist: {len(result.classes)} periodic motion(s) found")
    return result.classes[which]


def _phase_at_full_rate(result: PhaseResult, step: int, n_frames: int) -> PhaseResult:
    """A phase found on every ``step``-th frame, brought back to all ``n_frames`` frames (the unwrapped
    coordinate interpolated linearly; excitation regions and periods scaled by ``step``)."""
    frames = np.arange(n_frames)
    classes = []
    for c in result.classes:
        unwrapped = np.interp(frames, np.arange(c.unwrapped.size) * step, c.unwrapped)
        excitation = [(s * step, min(n_frames, (e - 1) * step + 1)) for s, e in c.excitation]
        classes.append(replace(c, coords=np.mod(unwrapped, 1.0), unwrapped=unwrapped, excitation=excitation,
                               period_frames=c.period_frames * step, frame_time=c.frame_time / step))
    return replace(result, classes=classes, n_frames=n_frames, frame_time=result.frame_time / step,
                   autocorrelation_period_frames=result.autocorrelation_period_frames * step)


def cycle_phase(motion: Motion, *, joints: str | Iterable[str] | None = None, classes: int | str = "auto",
                pca: int | str | None = "auto", delay: int = 2, min_periods: float = MIN_PERIODS,
                phase_step: int = 1) -> PhaseResult:
    """:func:`~mocycle.phase.find_phase` as the cycle extraction calls it, optionally on every
    ``phase_step``-th frame only (the thesis plugin's subsampling), brought back to every frame."""
    phase_step = _validate.integer("phase_step", phase_step, 1)
    options = dict(classes=classes, joints=joints, pca=pca, delay=delay, min_periods=min_periods)
    if phase_step > 1:
        return _phase_at_full_rate(find_phase(motion[::phase_step], **options), phase_step, motion.n_frames)
    return find_phase(motion, **options)


@limit_threads
def extract_cycle(motion: Motion, method: str = "harmonic", model: str = "M1", n_harmonics: int | str = "auto",
                  time_axis_method: str = "smooth", *, joints: str | Iterable[str] | None = None,
                  classes: int | str = "auto", which: int | None = None, pca: int | str | None = "auto",
                  delay: int = 2, min_periods: float = MIN_PERIODS, phase: PhaseResult | None = None,
                  phase_step: int = 1) -> Cycle:
    """One seamless cycle of ``motion``.

    ``method``: ``harmonic`` | ``centroid`` | ``cut``; ``model``: M1 | M2 | M3 (harmonic only);
    ``n_harmonics``: K or ``"auto"`` (20, capped by the frames); ``time_axis_method``: see
    :mod:`~mocycle.cycle.timeaxis`.  The phase options go to :func:`~mocycle.phase.find_phase`:
    ``joints`` (the joints the *phase* is found on; every joint is looped; default the whole body, then
    legs, then arms), ``classes`` (how many periodic motions to look for), ``pca``, ``delay`` and
    ``min_periods``; ``which``: the periodic motion to loop (0-based; default the one covering most frames);
    ``phase``: a :class:`PhaseResult` already computed for this motion (skips :func:`find_phase`);
    ``phase_step``: find the phase on every ``phase_step``-th frame only (the cycle is still built from
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
    >>> cycle.n_frames, cycle.n_harmonics
    (60, 20)
    >>> cycle.motion("inplace").n_frames, cycle.repeat(3, root="motion").n_frames
    (60, 180)
    """
    t0 = time.perf_counter()
    if not isinstance(motion, Motion):
        raise MocycleError(f"extract_cycle needs a Motion; got {type(motion).__name__}")
    _check_choice(method, METHODS, "method")
    _check_choice(time_axis_method, TIME_AXES, "time_axis_method")
    if method == "harmonic":
        _check_choice(model, MODELS, "model")
    if phase is None:
        phase = cycle_phase(motion, joints=joints, classes=classes, pca=pca, delay=delay, min_periods=min_periods,
                            phase_step=phase_step)
    periodic = choose_periodic(phase, which)
    axis = time_axis(periodic, time_axis_method)
    if axis.n_periods < FEW_PERIODS:
        warnings.warn(f"only {axis.n_periods:.2f} periods found (fewer than {FEW_PERIODS}); the cycle rests on "
                      f"little evidence", MocycleWarning, stacklevel=2)
    space = CycleSpace.fit(motion)
    if method == "harmonic" and model == "M1" and motion.n_frames * space.n_periodic * 8 > LAZY_P_BYTES:
        P, L = space.encode_rows(motion)  # the fit reads P's rows block by block: made as read, never held
    else:
        P, L = space.encode(motion)
    # The path is fitted straightened (periodic plus a line) and turned back along the cycle's heading.
    Q = space.straighten(L, axis.period_frames)
    # The cut's wrap is its seam; the others have none, so they start at the calmest point.
    if method == "harmonic":
        cycle = harmonic_cycle(space, P, Q, axis, periodic, model, n_harmonics, calmest=True)
    elif method == "centroid":
        cycle = centroid_cycle(space, P, Q, axis, periodic)
        cycle = cycle.rolled(calmest_start(*loop_blocks(cycle)))
    else:
        cycle = cut_cycle(space, P, Q, axis, periodic, metric_features(motion))
    path, drift = space.bend(cycle.L, cycle.drift, space.heading_trend(L[:, 3], axis.period_frames)[0])
    bent = replace(cycle, L=path, drift=drift)
    bent._projected = cycle._projected  # the same P: the same projection
    cycle = bent
    cycle.seconds = time.perf_counter() - t0
    return cycle
