"""How good is a loop?  The numbers ``mocycle loop --json`` and ``benchmarks/cycles.py`` print.

All pose errors are measured in one space for every method: each joint's
rotation matrix, its 9 entries divided by √2 (``(T, 9J)``;
:func:`~mocycle.cycle.metric_rows.metric_features`).  Per joint the distance is
``2 sin(θ/2)`` for a relative rotation of ``θ``: radians for small angles
(0.5 % short at 20°), and continuous for a joint that turns a full circle
every cycle, where a rotation vector would wrap at ±π and call a correct
loop broken.

* ``rmse_h``, ``rmse_dh``, ``rmse_ddh`` — KTH thesis eq. 4.1-4.3: the cycle read
  at each input frame's phase against the input, for poses (rad), velocities
  (rad/s) and accelerations (rad/s², 8th-order central differences).  Unlike
  the thesis the velocity and acceleration errors are not weighted by the M1
  weights, so every method is measured with the same ruler.
* ``template_error`` — eq. 4.4-4.5: the repeated cycle slid along the input's
  longest excited region; the RMS pose error (rad per frame) at the best offset.
* ``jerk_ratio`` — paper 001 §6.3: RMS jerk (4th-order forward differences) of
  the looped cycle over that of the input; 1 means as smooth as the capture.
* ``seam_pose``, ``seam_velocity`` — the change across the wrap (frame N-1 to 0)
  of the pose, and of the velocity (second difference), divided by the median
  of the same change between the cycle's other frames; the larger of the
  rotations' and the in-place root path's ratio.  1 means the wrap is an
  ordinary frame step.  ``seam_pose_local``, ``seam_velocity_local`` divide by
  the median over the eight frames next to the wrap instead: a pop detector
  that does not depend on where in the motion the wrap is placed
  (:mod:`~mocycle.cycle.seam`).
* ``foot_sliding`` and ``input_foot_sliding`` — mean horizontal speed (file
  units/s) of each foot while it is within 2 % of the body height of its
  floor, for the cycle repeated twice with its root motion and for the input.
* ``skate`` and ``input_skate`` — the foot-skate measure of
  :func:`mocycle.contacts.skate` (units/s: horizontal speed of each ankle and
  toe weighted by ``2 - 2**(h/H)`` below ``H`` = 2.5 % of the body height,
  averaged over frames) for the same two motions; ``nan`` when the rig's feet
  are not found by name.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_circulant

from ..axes import vertical_axis
from ..contacts.skate import skate
from ..errors import MocycleError
from ..motion import Motion
from .differences import FORWARD_3, HALF, central_acceleration, central_velocity, forward_jerk
from .metric_rows import MetricRows, loop_blocks
from .result import Cycle
from .seam import seam_ratios

CONTACT_HEIGHT = 0.02  # of the body height
FORK_HEIGHT = 0.25  # of the body height: the leg fork (hips) is at least this far above the lowest leaf
FOOT_BAND = 0.1  # of the body height: a branch whose lowest leaf is this close to the lowest one reaches the floor


class PeriodicSpline:
    """The periodic cubic spline through a cycle ``F`` ``(N, D)`` at positions ``0 .. N - 1`` (position ``N`` is
    frame 0 again): ``spline(x, nu)`` gives the value (``nu=0``), first or second derivative at positions ``x``
    ``(M,)`` -> ``(M, D)``, wrapped into ``[0, N)``.

    The spline of ``scipy.interpolate.CubicSpline(range(N + 1), [*F, F[0]], bc_type="periodic")`` (the tests
    compare them): on unit knots its second derivatives ``m`` solve the circulant system
    ``m[i-1] + 4 m[i] + m[i+1] = 6 (F[i-1] - 2 F[i] + F[i+1])`` (``scipy.linalg.solve_circulant``).  Importing
    ``scipy.interpolate`` loads ``scipy.optimize`` too, about 0.1 s of every ``mocycle loop``.
    """

    def __init__(self, F: np.ndarray):
        F = np.asarray(F, dtype=np.float64)
        N = F.shape[0]
        column = np.zeros(N)
        np.add.at(column, [0, 1 % N, -1 % N], [4.0, 1.0, 1.0])
        self.F, self.N = F, N
        self.m = m = solve_circulant(column, 6.0 * (np.roll(F, 1, axis=0) - 2.0 * F + np.roll(F, -1, axis=0)))
        m1 = np.roll(m, -1, axis=0)  # each knot's polynomial, once (not once per point it is read at)
        self.b = (np.roll(F, -1, axis=0) - F) - (2.0 * m + m1) / 6.0
        self.c = m / 2.0
        self.d = (m1 - m) / 6.0

    def _knots(self, x) -> tuple[np.ndarray, np.ndarray]:
        x = np.mod(np.asarray(x, dtype=np.float64), self.N)
        i = np.minimum(np.floor(x).astype(np.intp), self.N - 1)
        return i, (x - i)[:, None]

    def derivatives(self, x) -> tuple[np.ndarray, np.ndarray]:
        """``(spline(x, 1), spline(x, 2))``, the knots' polynomials read once for both."""
        i, t = self._knots(x)
        c, d = self.c[i], self.d[i]
        return self.b[i] + t * (2.0 * c + 3.0 * t * d), 2.0 * c + 6.0 * t * d

    def __call__(self, x, nu: int = 0) -> np.ndarray:
        i, t = self._knots(x)
        b, c, d = self.b[i], self.c[i], self.d[i]
        if nu == 0:
            y0 = self.F[i]
            return y0 + t * (b + t * (c + t * d))
        if nu == 1:
            return b + t * (2.0 * c + 3.0 * t * d)
        if nu == 2:
            return 2.0 * c + 6.0 * t * d
        raise ValueError(f"nu must be 0, 1 or 2; got {nu}")


def _spline(F: np.ndarray) -> PeriodicSpline:
    """Periodic cubic spline through a cycle ``(N, D)`` on positions ``0 .. N``."""
    return PeriodicSpline(F)


def _rms(E: np.ndarray) -> float:
    return float(np.sqrt((E ** 2).sum(axis=1).mean())) if E.size else float("nan")


#: Rows per block of the long metric passes (their (rows, D) temporaries stay a few MB).
_ROWS = 8192
#: Rows per block where the cycle's spline is read: a dozen (rows, D) temporaries a block (its knots' polynomials,
#: the derivatives, the errors): 100 MB at 8192 rows of a 22-joint rig, more than the (T, 9J) features held
_SPLINE_ROWS = 2048


def regression_errors(Y: np.ndarray | MetricRows, C: np.ndarray, positions: np.ndarray, regions, frames: np.ndarray,
                      frame_time: float, rate: float) -> tuple[float, float, float]:
    """Eq. 4.1-4.3 (unweighted): the cycle ``C (N, D)`` read at ``positions`` (cycle frames) against ``Y``.

    ``rate``: cycle frames per input frame (the cycle's length over the input's period).  Summed block by
    block of frames, so no error array as large as ``Y`` is held.
    """
    spline = _spline(C)
    frames = np.asarray(frames)
    positions = np.asarray(positions, dtype=np.float64)
    pos_of = np.full(Y.shape[0], np.nan)
    pos_of[frames] = positions
    sums, counts = [0.0, 0.0, 0.0], [0, 0, 0]
    for b in range(0, frames.size, _SPLINE_ROWS):
        e = spline(positions[b:b + _SPLINE_ROWS]) - Y[frames[b:b + _SPLINE_ROWS]]
        sums[0] += float(np.einsum("ij,ij->", e, e))
        counts[0] += e.shape[0]
    for s, e in regions:
        if e - s < 2 * HALF + 1:
            continue
        for r0 in range(s + HALF, e - HALF, _SPLINE_ROWS):  # output rows r0 .. r1-1 need Y[r0 - HALF : r1 + HALF]
            r1 = min(r0 + _SPLINE_ROWS, e - HALF)
            p = pos_of[r0:r1]
            window = Y[r0 - HALF:r1 + HALF]
            first, second = spline.derivatives(p)
            ev = first * rate / frame_time - central_velocity(window, frame_time)
            ea = second * (rate / frame_time) ** 2 - central_acceleration(window, frame_time)
            sums[1] += float(np.einsum("ij,ij->", ev, ev))
            sums[2] += float(np.einsum("ij,ij->", ea, ea))
            counts[1] += ev.shape[0]
            counts[2] += ea.shape[0]
    rms = [float(np.sqrt(t / n)) if n else float("nan") for t, n in zip(sums, counts, strict=True)]
    return rms[0], rms[1], rms[2]


def template_error(Y: np.ndarray | MetricRows, C: np.ndarray) -> tuple[float, int]:
    """Eq. 4.4-4.5: slide the repeated cycle ``C (N, D)`` along ``Y (M, D)``; (RMS error, best offset n).

    The ``(M, N)`` distances are computed block by block of rows (twice: to choose ``n``, then its error)."""
    M, N = Y.shape[0], C.shape[0]
    c2 = (C ** 2).sum(1)[None, :]

    made: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def d2_block(r0: int) -> tuple[np.ndarray, np.ndarray]:
        if r0 in made:  # a take of one block: its distances are made once for both passes
            return made.pop(r0)
        Yb = Y[r0:r0 + _ROWS]
        rows = np.arange(r0, r0 + Yb.shape[0])
        d2 = (Yb ** 2).sum(1)[:, None] + c2 - 2 * Yb @ C.T, rows  # squared distances
        if M <= _ROWS:
            made[r0] = d2
        return d2

    total = np.zeros(N)
    for r0 in range(0, M, _ROWS):
        d2, rows = d2_block(r0)
        idx = (rows[:, None] + np.arange(N)[None, :]) % N                   # [i, n] -> cycle frame i + n
        total += np.sqrt(np.maximum(np.take_along_axis(d2, idx, axis=1), 0.0)).sum(axis=0)
    n = int(np.argmin(total))                                               # eq. 4.4
    sq = 0.0
    for r0 in range(0, M, _ROWS):
        d2, rows = d2_block(r0)
        sq += float(np.maximum(d2[np.arange(rows.size), (rows + n) % N], 0).sum())
    return float(np.sqrt(sq / M)), n                                         # eq. 4.5


def jerk_ratio(Y_regions: list[np.ndarray] | list[MetricRows], C: np.ndarray, frame_time: float) -> float:
    """RMS jerk of the looped cycle over the RMS jerk of the input regions (paper 001 §6.3)."""
    width = FORWARD_3.size - 1  # rows lost at the end of each region
    total, rows = 0.0, 0
    for Y in Y_regions:
        for r0 in range(0, Y.shape[0] - width, _ROWS):  # in blocks: no jerk array as large as the input
            j = forward_jerk(Y[r0:r0 + _ROWS + width], frame_time)
            total += float(np.einsum("ij,ij->", j, j))
            rows += j.shape[0]
    if not rows:
        return float("nan")
    return _rms(forward_jerk(C, frame_time, periodic=True)) / float(np.sqrt(total / rows))


def foot_points(motion: Motion, up: np.ndarray | None = None, positions: np.ndarray | None = None) -> list[int]:
    """Indices (in ``world_positions(end_sites=True)``) of the feet: the lowest leaf (joint without children,
    or End Site) on each side of the hips, by the skeleton's structure alone.

    The hips are the *leg fork*: the lowest joint, at least ``FORK_HEIGHT`` of the body height above the
    lowest leaf, with two child branches that each reach within ``FOOT_BAND`` of it (both legs); a knee or an
    ankle is too low, the chest's branches do not reach the floor.  A rig without such a joint falls back to
    the two branches below the travel joint whose leaves hang lowest.  The fork, not the travel joint, splits
    the legs because on some rigs (iClone's ``RL_BoneRoot`` -> ``CC_Base_Hip``) the travel joint has a single
    child that carries both legs and the spine.  ``up``: the vertical axis (default: detected,
    :func:`~mocycle.axes.vertical_axis`); ``positions``: ``motion.world_positions(end_sites=True)`` when the
    caller has it; heights are the mean pose's (of at most 50 frames)."""
    skel = motion.skeleton
    up = vertical_axis(motion, up)
    parents = [int(p) for p in skel.parents] + [int(site.parent) for site in skel.end_sites]  # Python ints: fast
    children: dict[int, list[int]] = {}
    for i, p in enumerate(parents):
        if p >= 0:
            children.setdefault(p, []).append(i)
    leaves = [i for i in range(len(parents)) if i not in children]
    step = max(1, motion.n_frames // 50)
    W = motion[::step].world_positions(end_sites=True) if positions is None else positions[::step]
    heights = W.mean(axis=0) @ up
    # the lowest leaf of each joint's subtree (joints before their children; End Sites after every joint)
    low = [i if i not in children else -1 for i in range(len(parents))]
    for i in range(len(parents) - 1, -1, -1):  # children before their parents
        p = parents[i]
        if p >= 0 and low[i] >= 0 and (low[p] < 0 or heights[low[i]] < heights[low[p]]):
            low[p] = low[i]
    floor = min(heights[i] for i in leaves)
    body = float(np.ptp(heights))
    forks = []
    for j, kids in children.items():
        reaching = sorted((heights[low[c]], low[c]) for c in kids if heights[low[c]] <= floor + FOOT_BAND * body)
        if len(reaching) >= 2 and heights[j] >= floor + FORK_HEIGHT * body:
            forks.append((heights[j], [leaf for _, leaf in reaching[:2]]))
    if forks:
        return sorted(min(forks)[1], key=lambda i: heights[i])
    travel = motion.travel_joint

    def branch(i: int) -> int:
        path = [i]
        while parents[path[-1]] >= 0:
            path.append(parents[path[-1]])
        return path[path.index(travel) - 1] if travel in path and path.index(travel) > 0 else path[-1]

    lowest: dict[int, int] = {}
    for leaf in leaves:
        b = branch(leaf)
        if b not in lowest or heights[leaf] < heights[lowest[b]]:
            lowest[b] = leaf
    feet = sorted(lowest.values(), key=lambda i: heights[i])
    return feet[:2]


def foot_sliding(motion: Motion, up: np.ndarray | None = None, positions: np.ndarray | None = None) -> float:
    """Mean horizontal speed (units/s) of the feet while they touch the floor.

    A foot touches the floor on a frame step when it is, at both ends of the step, within
    ``CONTACT_HEIGHT`` of the body height above its own floor (its 5th-percentile height over the take).
    ``up``: the vertical axis (default: detected); ``positions``: ``motion.world_positions(end_sites=True)``
    when the caller has it.
    """
    up = vertical_axis(motion, up)
    W = motion.world_positions(end_sites=True) if positions is None else positions
    feet = foot_points(motion, up, W)
    body = np.ptp(W.mean(axis=0) @ up)
    per_foot = []
    for f in feet:
        p = W[:, f]
        h = p @ up
        down = h <= np.percentile(h, 5) + CONTACT_HEIGHT * body
        contact = down[:-1] & down[1:]
        step = np.diff(p, axis=0)
        horiz = step - np.outer(step @ up, up)
        per_foot.append(np.linalg.norm(horiz, axis=1)[contact] / motion.frame_time)
    speeds = np.concatenate(per_foot)
    return float(speeds.mean()) if speeds.size else float("nan")


def _skate(motion: Motion, up: np.ndarray, positions: np.ndarray | None = None) -> float:
    try:
        return skate(motion, up=up, positions=positions)
    except MocycleError:  # no feet found by name
        return float("nan")


def loop_metrics(motion: Motion, cycle: Cycle, travelling: Motion | None = None) -> dict[str, float]:
    """Every metric of the module docstring for ``cycle`` extracted from ``motion``.

    ``travelling``: ``cycle.repeat(2, root="motion")`` when the caller has it (the feet are measured on it).

    Returns
    -------
    dict of floats: ``rmse_h``, ``rmse_dh``, ``rmse_ddh``, ``template_error`` (rad) and its
    ``template_offset`` (frames), ``jerk_ratio``, ``seam_pose``, ``seam_velocity`` (and ``_local``: a seam
    ratio <= 1 means the wrap is no bigger a step than the loop's own), ``foot_sliding``,
    ``input_foot_sliding``, ``skate`` and ``input_skate`` (units/s).

    Examples
    --------
    >>> from mocycle.cycle import extract_cycle
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60).motion
    >>> metrics = loop_metrics(walk, extract_cycle(walk))
    >>> metrics["template_error"] < 0.1, metrics["seam_pose"] <= 1.0
    (True, True)
    """
    Y = MetricRows(motion)  # the (T, 9J) metric features, made block by block as they are read
    C, root = loop_blocks(cycle)
    # columns that hold one value in the take and in the cycle (joints that never move, the fixed entries of a
    # joint turning about one axis) add only rounding to every pose figure: left out (a 100-joint rig's fingers)
    still = Y.still() & (np.ptp(C, axis=0) == 0)
    if still.any() and not still.all():
        Y, C = Y.select(~still), C[:, ~still]
    frames = cycle.axis.frames()
    rate = cycle.n_frames / cycle.period_frames
    rmse_h, rmse_dh, rmse_ddh = regression_errors(Y, C, cycle.positions, cycle.axis.regions, frames,
                                                  motion.frame_time, rate)
    s, e = max(cycle.axis.regions, key=lambda r: r[1] - r[0])
    tmpl, offset = template_error(Y.region(s, e), C)
    jerk = jerk_ratio([Y.region(a, b) for a, b in cycle.axis.regions], C, motion.frame_time)
    seams = [seam_ratios(C), seam_ratios(root)]
    travelling = cycle.repeat(2, root="motion") if travelling is None else travelling
    captured = motion[frames[0]:frames[-1] + 1]
    up = cycle.space.world_up
    # every joint's world positions once per motion: the feet, the body's height and the skate all read them
    W_travelling, W_captured = travelling.world_positions(end_sites=True), captured.world_positions(end_sites=True)
    return {
        "rmse_h": rmse_h,
        "rmse_dh": rmse_dh,
        "rmse_ddh": rmse_ddh,
        "template_error": tmpl,
        "template_offset": offset,
        "jerk_ratio": jerk,
        "seam_pose": max(r["pose"] for r in seams),
        "seam_velocity": max(r["velocity"] for r in seams),
        "seam_pose_local": max(r["pose_local"] for r in seams),
        "seam_velocity_local": max(r["velocity_local"] for r in seams),
        "foot_sliding": foot_sliding(travelling, up, W_travelling),
        "input_foot_sliding": foot_sliding(captured, up, W_captured),
        "skate": _skate(travelling, up, W_travelling),
        "input_skate": _skate(captured, up, W_captured),
    }
