"""Lengthening takes by time-frequency warping (paper 004 §4-§6).

A curve is taken to the time-frequency domain with the lapped cosine transform (:mod:`.lct`), on blocks of
one *fundamental cycle* (the window size).  The coefficient image is dilated along its time axis by the
factor: each block of atoms is *replicated*, not stretched (output block ``k`` holds the coefficients of the
input block nearest to time ``(k + 1/2) / factor`` blocks), and the inverse transform gives a longer curve
that keeps every frequency of the original; a factor of 2 doubles the length with the same cycle.  Two
details make the seams between copies of a block smooth:

* a copy of the first block that does not stand at the start is folded, on its left, against the end of its
  own cycle (the cycle "before" it), not left unfolded as at the start of the take;
* the last block (one cycle plus the ``T mod N`` remainder) is never replicated, and stays last.

With a window equal to an integer period, a periodic curve comes back as its exact continuation.

For a motion (§6), joints are grouped (legs, arms, spine/head: :func:`joint_groups`), the fundamental cycle of
every rotation curve is found by windowed circular autocorrelation (eq. 1, :func:`fundamental_cycles`), and
each group uses its *largest* cycle as its window, so the shorter cycles of the group (whose periods divide
it) are replicated whole.  Rotations are warped as continuous curves (the quaternion logarithm about each
joint's mean rotation, ``features.pose_matrix(rep="quatlog")``) and decoded back; a rotation curve dominated
by a linear trend (a character turning) and the travelling joint's translation are split into a
least-squares line and a residual: the residual is warped, the line extended, so the character keeps
travelling at its mean velocity.
"""

from __future__ import annotations

import fnmatch
import math
import re
import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError, MocycleWarning, NoPeriodicMotion
from ..features import pose_matrix
from ..limits import check_frames
from ..motion import JOINT_GROUPS, Motion, Skeleton, concatenate
from ..phase.period import autocorrelation_period, circular_autocorrelation, period_from_autocorrelation, periodic_hann
from ..rotations import axis_angle_quats, quat_conj, quat_exp, quat_log, quat_multiply
from ..threads import limit_threads
from .lct import COLUMNS as LCT_COLUMNS
from .lct import block_edges, ilct, lct

__all__ = [
    "StretchReport",
    "fundamental_cycles",
    "group_cycle",
    "joint_groups",
    "periodic_regions",
    "refine_window",
    "stretch_motion",
    "warp_curves",
]

#: Groups in the order they are reported.
GROUP_NAMES = ("legs", "arms", "spine")
#: A per-curve cycle counts when its autocorrelation maximum reaches this fraction of ``r(0)``.
CURVE_MIN_STRENGTH = 0.3
#: Curves whose standard deviation is below this fraction of the group's largest do not vote for the window.
WEAK_CURVE = 0.25
#: The integer window is refined within this fraction of the estimated cycle (see :func:`refine_window`).
REFINE_SPAN = 0.15
#: A rotation curve is split into line + residual when the line's rise over the take exceeds this many times
#: the residual's peak-to-peak range.
TREND_DOMINATED = 2.0


# -- curves --------------------------------------------------------------------------------------------------------


def _factor(factor) -> float:
    return _validate.positive("factor", factor)


def _frames_out(n_frames: int, factor: float, n_joints: int = 1) -> int:
    check_frames(round(n_frames * factor), n_joints, f"stretching {n_frames} frames by {factor:g}")
    n = int(round(n_frames * factor))
    if n < 2:
        raise MocycleError(f"factor {factor:g} leaves {n} frame(s) of {n_frames}; the result needs at least 2")
    return n


def _window(window, n_frames: int) -> int:
    """A window of 1 to half the take's frames."""
    return _validate.integer("window", window, 1, max(n_frames // 2, 1), note=f"half the take's {n_frames} frames")


def warp_curves(X, factor: float, window: int, overlap: int | None = None) -> np.ndarray:
    """Time-frequency warping of curves (paper 004 §4): ``(T,)`` or ``(T, D)`` -> ``round(T * factor)`` frames.

    ``window``: the block length N in frames (the fundamental cycle; ``1 <= N <= T // 2``).  ``overlap``: the
    fold half-width (default ``N // 2``, the smoothest).  The LCT image on blocks of N frames is dilated in
    time by replicating blocks (module notes), then inverted.  ``factor = 1`` returns ``X`` (to rounding);
    ``factor < 1`` drops whole blocks (time compression), which keeps frequencies too.
    """
    try:
        A = np.asarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MocycleError(f"X must be a (T,) or (T, D) array of numbers; got {type(X).__name__} ({exc})") from None
    one = A.ndim == 1
    if one:
        A = A[:, None]
    if A.ndim != 2 or A.shape[0] < 2:
        raise MocycleError(f"X must be a (T,) or (T, D) array with at least 2 frames; got shape {np.shape(X)}")
    if not np.all(np.isfinite(A)):
        raise MocycleError("X must be finite (no NaN or infinite values)")
    T = A.shape[0]
    factor = _factor(factor)
    N = _window(window, T)
    n_out = _frames_out(T, factor)
    if overlap is None:
        overlap = N // 2
    overlap = _validate.integer("overlap", overlap, 0, N // 2)

    edges = block_edges(T, N)
    K = edges.size - 1  # >= 2 since N <= T // 2
    last = T - (K - 1) * N  # the last block: one cycle plus the remainder, never replicated
    C = lct(A, edges, overlap)
    first_cyclic = C[:N]
    if overlap:
        # Block 0 folded on its left against the end of its own cycle, for copies that follow another copy.
        Z = np.concatenate([A[N - overlap: N], A[: N + overlap]])
        first_cyclic = lct(Z, np.array([0, overlap, overlap + N, 2 * overlap + N]), overlap)[overlap: overlap + N]
    r = K - 1  # replicable blocks
    m = max(1, math.ceil((n_out - last) / N))
    # Output block k stands for input time (k + 1/2) N K / (m + 1): nearest-block replication of the image
    # dilated by (m + 1) / K ~ factor; the final input block is the last output block.
    sources = np.minimum(((np.arange(m) + 0.5) * K / (m + 1)).astype(np.int64), r - 1)
    parts = [first_cyclic if (s == 0 and k > 0) else C[s * N: (s + 1) * N] for k, s in enumerate(sources)]
    parts.append(C[(K - 1) * N:])
    out_edges = np.concatenate([np.arange(m + 1) * N, [m * N + last]])
    Y = ilct(np.concatenate(parts), out_edges, overlap)[:n_out]
    return Y[:, 0] if one else Y


def fundamental_cycles(X, min_strength: float = CURVE_MIN_STRENGTH) -> np.ndarray:
    """The fundamental cycle (frames) of every curve of ``X`` (``(T, D)``): ``(D,)``, NaN where none is found.

    Paper 004 eq. 1, curve by curve: what :func:`mocycle.phase.period.autocorrelation_period` gives on each
    column (Hann-windowed circular autocorrelation, highest maximum in ``[2, T // 2]``), with a maximum needed
    of ``min_strength * r(0)`` (0.3: drifting, weakly periodic curves such as a head slowly turning give no
    cycle rather than a spurious long one).  Constant curves give NaN.  The autocorrelations of all columns
    come from one FFT; only the choice of each column's maximum is done column by column.
    """
    A = np.asarray(X, dtype=np.float64)
    if A.ndim == 1:
        A = A[:, None]
    if A.ndim != 2:
        raise MocycleError(f"X must be a (T,) or (T, D) array; got shape {A.shape}")
    T = A.shape[0]
    if T < 4:
        raise MocycleError(f"the fundamental cycle needs at least 4 frames; got {T}")
    min_strength = _validate.real("min_strength", min_strength, 0.0, 1.0, high_open=True)
    out = np.full(A.shape[1], np.nan)
    use = np.flatnonzero((np.ptp(A, axis=0) > 0) & np.all(np.isfinite(A), axis=0))
    if use.size == 0:
        return out
    B = A[:, use]
    B = B - np.mean(B, axis=0)
    window = periodic_hann(T)
    r = circular_autocorrelation(B * window[:, None], per_column=True)  # (T, n)
    env = circular_autocorrelation(window)
    for k, d in enumerate(use.tolist()):
        if r[0, k] > 0.0:
            out[d] = period_from_autocorrelation(r[:, k] / r[0, k], env, 2, T // 2, min_strength)
    return out


def group_cycle(X, min_strength: float = CURVE_MIN_STRENGTH, weak: float = WEAK_CURVE) -> float:
    """The window of a group of curves (``(T, D)``): the largest fundamental cycle among its curves (§6).

    Curves whose standard deviation is below ``weak`` times the group's largest do not vote (fingers and
    twist bones that barely move carry mostly noise).  NaN when no voting curve has a cycle (a still or
    aperiodic group: :func:`stretch_motion` then borrows the largest cycle of the other groups).
    """
    A = np.asarray(X, dtype=np.float64)
    if A.ndim == 1:
        A = A[:, None]
    if A.size == 0:
        return float("nan")
    sd = A.std(axis=0)
    if not sd.max() > 0:
        return float("nan")
    cycles = fundamental_cycles(A[:, sd >= weak * sd.max()], min_strength=min_strength)
    return float(np.nanmax(cycles)) if np.any(np.isfinite(cycles)) else float("nan")


def refine_window(X, cycle: float, span: float = REFINE_SPAN) -> int:
    """The integer window near ``cycle`` (frames) over which the curves ``X`` (``(T, D)``) repeat best.

    Minimises the mean squared difference ``x[t + N] - x[t]`` over ``N`` within ``cycle * (1 +- span)``
    (and ``2 <= N <= T // 2``): what replicating a block of N frames puts side by side at a seam.  The
    autocorrelation peak of eq. 1 is biased by the window on short takes (two or three cycles) and has
    to be rounded anyway; this picks the integer that makes the seams smoothest.  Returns
    ``round(cycle)`` clipped to the allowed range when the range is empty.
    """
    A = np.asarray(X, dtype=np.float64)
    if A.ndim == 1:
        A = A[:, None]
    T = A.shape[0]
    limit = max(1, T // 2)
    lo = max(2, int(math.floor(cycle * (1 - span))))
    hi = min(limit, int(math.ceil(cycle * (1 + span))))
    if lo > hi or A.shape[1] == 0:
        return int(min(max(1, round(cycle)), limit))
    candidates = np.arange(lo, hi + 1)
    A = A - A.mean(axis=0)
    errors = [float(np.sum((A[n:] - A[:-n]) ** 2) / max(np.sum(A[n:] ** 2 + A[:-n] ** 2), 1e-300))
              for n in candidates]
    return int(candidates[int(np.argmin(errors))])


# -- motions -------------------------------------------------------------------------------------------------------


def joint_groups(skeleton: Skeleton) -> dict[str, list[int]]:
    """Joints grouped as paper 004 §6 does: ``{"legs": [...], "arms": [...], "spine": [...]}``.

    A joint whose name matches a pattern of :data:`mocycle.motion.JOINT_GROUPS` (tried in the order legs,
    arms, spine) belongs to that group; any other joint to its parent's group (fingers follow the hand, eyes
    the head); the root and joints above every match belong to ``spine`` (the torso).  Empty groups are left
    out.  Every joint is in exactly one group.
    """
    group_of: list[str] = []
    match = {g: re.compile("|".join(fnmatch.translate(p.lower()) for p in JOINT_GROUPS[g])).match for g in GROUP_NAMES}
    for j, name in enumerate(skeleton.names):
        low = name.lower()
        own = next((g for g in GROUP_NAMES if match[g](low)), None)
        if own is None:
            parent = int(skeleton.parents[j])
            own = "spine" if parent < 0 else group_of[parent]
        group_of.append(own)
    groups = {g: [j for j, h in enumerate(group_of) if h == g] for g in GROUP_NAMES}
    return {g: js for g, js in groups.items() if js}


@dataclass(frozen=True, kw_only=True)
class StretchReport:
    """What :func:`stretch_motion` did.

    factor : the requested factor; frames_in, frames_out : lengths (``frames_out = round(frames_in * factor)``).
    windows : ``{group: window in frames}`` used for each joint group.
    cycles : ``{group: fundamental cycle in frames}`` as estimated (``None`` when ``window`` was given).
    groups : ``{group: joint names}``.
    trend_curves : rotation curves warped as line + residual (e.g. ``"Hips:qy"``).
    regions, regions_out : the periodic frame ranges warped, in the input and where they are in the output
        (the frames outside them are kept as captured).
    forced : the take has no periodic motion and was warped whole anyway (``force=True``).
    """

    factor: float
    frames_in: int
    frames_out: int
    windows: dict[str, int]
    cycles: dict[str, float | None]
    groups: dict[str, tuple[str, ...]] = field(repr=False)
    trend_curves: tuple[str, ...] = ()
    regions: tuple[tuple[int, int], ...] = ()
    regions_out: tuple[tuple[int, int], ...] = ()
    forced: bool = False

    def to_dict(self) -> dict:
        return {
            "factor": self.factor,
            "frames_in": self.frames_in,
            "frames_out": self.frames_out,
            "windows": dict(self.windows),
            "cycles": {g: (None if c is None else round(float(c), 3)) for g, c in self.cycles.items()},
            "trend_curves": list(self.trend_curves),
            "periodic_regions": [list(r) for r in self.regions],
            "periodic_regions_out": [list(r) for r in self.regions_out],
            "forced": self.forced,
        }


#: Columns per block of :func:`_line_fit` and the trend test (its least-squares solver copies the columns it is given)
LINE_COLUMNS = 16


def _line_fit(Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares line per column of ``Y`` (``(T, D)``): ``(intercept (D,), slope per frame (D,))``, a block
    of :data:`LINE_COLUMNS` columns at a time (each column's line is its own: no ``(T, D)`` copy is made)."""
    t = np.arange(Y.shape[0], dtype=np.float64)
    slope, intercept = np.empty(Y.shape[1]), np.empty(Y.shape[1])
    for c0 in range(0, Y.shape[1], LINE_COLUMNS):
        cs = slice(c0, c0 + LINE_COLUMNS)
        slope[cs], intercept[cs] = np.polyfit(t, Y[:, cs], 1)
    return intercept, slope


def _warp_detrended(Y: np.ndarray, factor: float, window: int) -> np.ndarray:
    """Warp ``Y - line`` and add the line extended over the new length (the mean velocity kept)."""
    a, v = _line_fit(Y)
    t = np.arange(Y.shape[0], dtype=np.float64)[:, None]
    res = warp_curves(Y - (a + v * t), factor, window)
    t_out = np.arange(res.shape[0], dtype=np.float64)[:, None]
    return res + a + v * t_out


def _warp_take(motion: Motion, factor: float, window: str | int = "auto",
               travel: int | None = None) -> tuple[Motion, StretchReport]:
    """The whole take warped by ``factor`` (paper 004 §6): :func:`stretch_motion` on one periodic region.
    ``travel``: the travelling joint (default: the take's own)."""
    T = motion.n_frames
    n_out = _frames_out(T, factor, motion.n_joints)
    skel = motion.skeleton
    groups = joint_groups(skel)
    X, decoder = pose_matrix(motion, rep="quatlog", root_features="drop")
    owner = decoder.dof_joint
    group_of = np.empty(skel.n_joints, dtype=object)
    for g, js in groups.items():
        group_of[js] = g
    cols = {g: np.flatnonzero(np.isin(owner, js)) for g, js in groups.items()}

    cycles: dict[str, float | None] = {}
    windows: dict[str, int] = {}
    window = _validate.integer("window", window, 1, max(T // 2, 1), words={"auto": "auto"},
                               note=f"half the take's {T} frames")
    if window == "auto":
        limit = T // 2
        found = {g: group_cycle(X[:, c]) if c.size else float("nan") for g, c in cols.items()}
        group_cycles: dict[str, float] = {}  # the groups with a cycle of their own
        for g, cycle in found.items():
            if np.isfinite(cycle):
                A = X[:, cols[g]]
                sd = A.std(axis=0)
                group_cycles[g], windows[g] = cycle, refine_window(A[:, sd >= WEAK_CURVE * sd.max()], cycle)
        if group_cycles:  # a still or aperiodic group borrows the largest cycle (and its window) of the others
            lender = max(group_cycles, key=lambda g: group_cycles[g])
            fallback, fallback_window = group_cycles[lender], windows[lender]
        else:  # no group has a cycle: the whole pose matrix (autocorrelation summed over every curve)
            fallback = autocorrelation_period(X) if X.shape[1] else float("nan")
            if not np.isfinite(fallback):
                raise MocycleError(f"no fundamental cycle found in any joint group ({', '.join(groups)}) of this "
                                   f"{T}-frame take: it does not look periodic; give the window in frames "
                                   f"(1 to {limit})")
            fallback_window = refine_window(X, fallback)
        for g in groups:
            if g not in group_cycles:
                group_cycles[g], windows[g] = float(fallback), fallback_window
        cycles = {g: float(group_cycles[g]) for g in groups}
        windows = {g: int(windows[g]) for g in groups}
    else:
        N = _window(window, T)
        for g in groups:
            cycles[g] = None
            windows[g] = N

    # Rotations: continuous curves about the mean pose; trend-dominated curves as line + residual.
    Y = np.empty((n_out, X.shape[1]))
    trend_cols: list[int] = []
    if X.shape[1]:
        a, v = _line_fit(X)
        rise = np.abs(v) * (T - 1)
        t = np.arange(T)[:, None]
        resid_ptp = np.empty(X.shape[1])
        for c0 in range(0, X.shape[1], LINE_COLUMNS):  # the residuals a block of columns at a time (memory)
            cs = slice(c0, c0 + LINE_COLUMNS)
            resid_ptp[cs] = np.ptp(X[:, cs] - (a[cs] + v[cs] * t), axis=0)
        trend = rise > TREND_DOMINATED * np.maximum(resid_ptp, 1e-12)
        trend_cols = [int(i) for i in np.flatnonzero(trend)]
        by_window: dict[int, list[np.ndarray]] = {}  # groups with the same window warp in one transform
        for g, c in cols.items():
            if not c.size:
                continue
            plain, tr = c[~trend[c]], c[trend[c]]
            if plain.size:
                by_window.setdefault(windows[g], []).append(plain)
            if tr.size:
                Y[:, tr] = _warp_detrended(X[:, tr], factor, windows[g])
        for N, parts in by_window.items():
            plain = np.concatenate(parts)
            for c0 in range(0, plain.size, LCT_COLUMNS):  # the columns the transform takes at a time (memory)
                block = plain[c0:c0 + LCT_COLUMNS]
                Y[:, block] = warp_curves(X[:, block], factor, N)
    del X  # the input's curves: not needed to decode (memory)
    quats, _ = decoder.decode_arrays(Y, translations=False)
    del Y

    # Translations: the travelling joint as mean velocity + warped residual; other moving joints warped.
    travel = motion.travel_joint if travel is None else travel
    tracks = {}
    for j in sorted(set(motion.tracked_joints) | {travel}):
        P = motion.joint_translations(j)
        if j == travel:
            tracks[j] = _warp_detrended(P, factor, windows[group_of[j]])
        elif np.ptp(P, axis=0).max() > 1e-9 * (1.0 + np.abs(P).max()):
            tracks[j] = warp_curves(P, factor, windows[group_of[j]])
    new = Motion(skel, quats, motion.translations_at(0), motion.frame_time, tracks=tracks,
                 copy=False)  # the arrays were made here

    report = StretchReport(
        factor=factor,
        frames_in=T,
        frames_out=n_out,
        windows=windows,
        cycles=cycles,
        groups={g: tuple(skel.names[j] for j in js) for g, js in groups.items()},
        trend_curves=tuple(decoder.columns[i] for i in trend_cols),
    )
    return new, report


# -- periodic regions -----------------------------------------------------------------------------------------------


def periodic_regions(motion: Motion, phase=None) -> tuple[list[tuple[int, int]], float, str]:
    """The frame ranges ``[(start, stop), ...]`` of the take's periodic motions, the longest period among them
    (frames) and the phase's reason when there are none.

    The excitation regions of every periodic motion :func:`~mocycle.phase.find_phase` finds (or ``phase``, a
    :class:`~mocycle.phase.PhaseResult` of this take), merged where they overlap or are less than a period
    apart; an end within half a period of the take's is moved to it (excitation ends are not that precise).
    """
    from ..phase import find_phase

    if phase is None:
        phase = find_phase(motion)
    if not phase.classes:
        return [], float("nan"), phase.reason
    T = motion.n_frames
    period = float(max(c.period_frames for c in phase.classes))
    spans = sorted((int(s), int(e)) for c in phase.classes for s, e in c.excitation if e > s)
    merged: list[list[int]] = []
    for s, e in spans:
        if merged and s <= merged[-1][1] + period:
            merged[-1][1] = max(merged[-1][1], e)
        else:
            merged.append([s, e])
    for r in merged:
        if r[0] < 0.5 * period:
            r[0] = 0
        if T - r[1] < 0.5 * period:
            r[1] = T
    return [(s, e) for s, e in merged], period, ""


def _shares(lengths: list[int], extra: int) -> list[int]:
    """``extra`` frames (may be negative) shared among regions in proportion to their ``lengths``
    (largest remainders get the rounding)."""
    total = float(sum(lengths))
    raw = np.array([extra * n / total for n in lengths])
    base = np.floor(raw).astype(int)
    left = extra - int(base.sum())
    order = np.argsort(-(raw - base))
    base[order[:left]] += 1
    return base.tolist()


def _smooth(n: int) -> np.ndarray:
    """Weights 1 -> 0 over ``n`` frames (smoothstep)."""
    x = (np.arange(n) + 1.0) / (n + 1.0)
    return 1.0 - x * x * (3.0 - 2.0 * x)


class _Placer:
    """Where the captured frames go in the output: a turn about the vertical and a shift of the travelling
    joint (in its parent's frame) that grows at every warped region, so what follows it carries on from where
    the region ends (a stretched walk travels further and turns more)."""

    def __init__(self, motion: Motion, travel: int):
        from ..cycle.representation import CycleSpace, axis_rotations

        self.space = CycleSpace.fit(motion)
        self.turn_about = axis_rotations
        self.travel = travel
        self.angle = 0.0
        self.anchor = np.zeros(3)
        self.offset = np.zeros(3)

    def _R(self) -> np.ndarray:
        return self.turn_about(self.space.up, np.array([self.angle]))[0]

    def place(self, m: Motion) -> Motion:
        R = self._R()
        q = m.rotations.copy()
        j = self.travel
        q[:, j] = quat_multiply(axis_angle_quats(self.space.up, np.array([self.angle]))[0], q[:, j])
        path = (m.joint_translations(j) - self.anchor) @ R.T + self.anchor + self.offset
        return m.replace(rotations=q, tracks={j: path}, copy=False)

    def heading(self, quat: np.ndarray) -> float:
        return float(self.space.heading(Rotation.from_quat(quat[None]).as_matrix())[0])

    def carry_on(self, captured_last: Motion, placed_last: Motion) -> None:
        """Place what follows so that the captured frame ``captured_last`` (one frame) lands on ``placed_last``."""
        j = self.travel
        turn = self.heading(placed_last.rotations[0, j]) - self.heading(captured_last.rotations[0, j])
        self.angle = float(np.angle(np.exp(1j * turn)))
        self.anchor = captured_last.joint_translations(j)[0].copy()
        self.offset = placed_last.joint_translations(j)[0] - self.anchor


def _fade(warped: Motion, target: Motion, at_start: bool, n: int) -> Motion:
    """Bend the first (or last) ``n`` frames of ``warped`` so that its first (last) frame is ``target``'s
    (one frame): the rotation and translation differences, faded out by a smoothstep (no pop at a join)."""
    if n < 1:
        return warped
    n = min(n, warped.n_frames)
    k = 0 if at_start else warped.n_frames - 1
    d = quat_multiply(target.rotations[0], quat_conj(warped.rotations[k]))
    diff = quat_log(d * np.where(d[:, 3:4] < 0, -1.0, 1.0))  # rotation vectors, angle <= π
    dt = target.translations_at(0) - warped.translations_at(k)
    w = _smooth(n) if at_start else _smooth(n)[::-1]
    rows = np.arange(n) if at_start else np.arange(warped.n_frames - n, warped.n_frames)
    q = warped.rotations.copy()
    q[rows] = quat_multiply(quat_exp(w[:, None, None] * diff[None]), q[rows])
    tracks = {}
    for j in np.flatnonzero(dt.any(axis=1)).tolist():  # the joints whose translations differ at the join
        tracks[j] = np.array(warped.joint_translations(j))
        tracks[j][rows] += w[:, None] * dt[j]
    return warped.replace(rotations=q, tracks=tracks, copy=False)


@limit_threads
def stretch_motion(motion: Motion, factor: float, window: str | int = "auto", force: bool = False,
                   phase=None) -> tuple[Motion, StretchReport]:
    """Lengthen (or shorten) a take by time-frequency warping its periodic part: paper 004 §6.

    Only the periodic region(s) are warped (:func:`periodic_regions`: the excitation regions of the take's
    phase); the frames before, between and after them are kept as captured, turned and moved on so that they
    follow the stretched regions, and each join is faded over a window so that nothing pops.  The regions
    absorb the whole change, in proportion to their lengths; the output has ``round(T * factor)`` frames,
    or within half a window of it per region when captured frames follow the last region (a region with
    frames after it grows by whole windows, so that it ends as captured).

    Parameters
    ----------
    motion : the take (at least 8 frames).
    factor : length ratio (> 0); the result has about ``round(T * factor)`` frames at the same frame time.
    window : ``"auto"`` (each joint group's largest fundamental cycle in the region, :func:`group_cycle`) or
        a number of frames used for every group (``1 <= window <= region // 2``).
    force : warp the whole take when it has no periodic motion (a warning) instead of raising
        :class:`~mocycle.errors.NoPeriodicMotion` (a one-off gesture would be repeated, a standing start
        shuffled twice).
    phase : a :class:`~mocycle.phase.PhaseResult` of ``motion`` already computed.

    Returns
    -------
    ``(new motion, StretchReport)``.  Raises NoPeriodicMotion when the take has no periodic motion (or its
    periodic region is too short to warp) and ``force`` is off; MocycleError for bad input.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion
    >>> longer, report = stretch_motion(walk, factor=1.5)
    >>> longer.n_frames, report.windows
    (450, {'legs': 60, 'arms': 60, 'spine': 60})
    """
    if not isinstance(motion, Motion):
        raise MocycleError(f"stretch_motion needs a Motion; got {type(motion).__name__}")
    T = motion.n_frames
    if T < 8:
        raise MocycleError(f"stretching needs a take of at least 8 frames; got {T}")
    factor = _factor(factor)
    n_out = _frames_out(T, factor, motion.n_joints)
    window = _validate.integer("window", window, 1, max(T // 2, 1), words={"auto": "auto"},
                               note=f"half the take's {T} frames")
    try:
        regions, period, reason = periodic_regions(motion, phase)
    except MocycleError as exc:  # too short for a phase
        regions, period, reason = [], float("nan"), str(exc)
    short = [(s, e) for s, e in regions if e - s < 2 * max(period, 2.0 if isinstance(window, str) else window)]
    if short and len(short) == len(regions):
        reason = (f"the periodic region(s) {', '.join(f'{s}:{e}' for s, e in short)} hold fewer than two periods "
                  f"of {period:.1f} frames")
        regions = []
    regions = [r for r in regions if r not in short]
    if not regions:
        if not force:
            raise NoPeriodicMotion(f"no periodic motion to stretch ({reason}): warping would repeat what happens "
                                   f"once; option 'force' warps the whole take anyway")
        warnings.warn(f"the take has no periodic motion ({reason}); warping it whole (option 'force') repeats what "
                      f"happens once", MocycleWarning, stacklevel=2)
        new, report = _warp_take(motion, factor, window)
        return new, replace(report, factor=factor, forced=True)
    if regions == [(0, T)]:
        new, report = _warp_take(motion, factor, window)
        return new, replace(report, factor=factor, regions=((0, T),), regions_out=((0, n_out),))

    travel = motion.travel_joint
    placer = _Placer(motion, travel)
    lengths = [e - s for s, e in regions]
    shares = _shares(lengths, n_out - T)
    parts: list[Motion] = []
    reports: list[StretchReport] = []
    regions_out = []
    done, frames = 0, 0
    for (s, e), extra in zip(regions, shares, strict=True):
        if s > done:
            parts.append(placer.place(motion[done:s]))
            frames += s - done
        n_seg = e - s + extra
        if n_seg < 2:
            raise MocycleError(f"factor {factor:g} leaves {n_seg} frame(s) of the periodic region {s}:{e}")
        if not isinstance(window, str) and window > (e - s) // 2:
            raise MocycleError(f"window must be between 1 and half the periodic region {s}:{e} "
                               f"({(e - s) // 2} frames); got {window}")
        warped, rep = _warp_take(motion[s:e], n_seg / (e - s), window, travel)
        if e < T:
            # The warp copies whole windows and keeps the last block (one window plus the remainder) last; a
            # length between two whole numbers of copies would cut that block, and the captured frames after
            # the region would not follow.  So a region with frames after it grows by whole windows.
            N = max(rep.windows.values())
            last = N + (e - s) % N
            whole = last + max(0, int(round((n_seg - last) / N))) * N
            if whole != n_seg:
                n_seg = whole
                warped, rep = _warp_take(motion[s:e], n_seg / (e - s), window, travel)
        elif (s, e) == regions[-1]:
            n_seg = n_out - frames  # the last region ends the take: it takes what is left (cut mid-cycle)
            warped, rep = _warp_take(motion[s:e], n_seg / (e - s), window, travel) if n_seg != warped.n_frames \
                else (warped, rep)
        warped = placer.place(warped)
        fade = int(min(max(rep.windows.values()), n_seg // 3))
        if s > 0:
            warped = _fade(warped, placer.place(motion[s:s + 1]), True, fade)
        if e < T:
            captured_last = motion[e - 1:e]
            placer.carry_on(captured_last, warped[n_seg - 1:n_seg])
            warped = _fade(warped, placer.place(captured_last), False, fade)
        parts.append(warped)
        reports.append(rep)
        regions_out.append((frames, frames + n_seg))
        frames += n_seg
        done = e
    if done < T:
        parts.append(placer.place(motion[done:T]))
    new = concatenate(parts)
    main = reports[int(np.argmax(lengths))]
    report = replace(main, factor=factor, frames_in=T, frames_out=new.n_frames, regions=tuple(regions),
                     regions_out=tuple(regions_out),
                     trend_curves=tuple(sorted({c for r in reports for c in r.trend_curves})))
    return new, report
