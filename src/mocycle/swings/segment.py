"""Joint-swing segmentation (paper 003, "Motion Segmentation Based on Joint Swings", section 4.2).

For each chosen joint:

1. **Angular velocity** from consecutive local rotations as an exponential map,
   ``ω_t = log(R_{t+1} R_tᵀ)`` (radians per frame, parent frame), ``(T-1, 3)``.
2. **Box filter** of ``window_s`` seconds (the paper's 20 frames at 120 fps =
   1/6 s, so other frame rates get the same time span).
3. **Geodesic-swing error** ``E_t`` of the window centred on each frame: the
   mean of ``1 - cos`` of the angle between frame ``t``'s rotation axis and the
   axes in the window (0 = perfectly geodesic, 2 = reversed).
4. **Greedy growth** from the unprocessed frame with the lowest error: add the
   left or right neighbour whose axis is closer to the seed's, while the
   average error of the swing stays within the *Acceptable Swing Error*
   (``threshold``, default 0.4, range 0-2).
5. Each swing gets its axis (mean of the frame axes), the angles about that
   axis at its ends (and, beyond the paper, the angular speeds at its ends so
   playback can follow the ease-in / ease-out of a real swing); the still
   parts between swings become **holds** with their mean rotation.

The result :class:`Segmentation` is a table of :class:`Swing` and :class:`Hold`
records (``to_records()``) that playback, the codecs, search and editing read; the records live in
:mod:`mocycle.segmentation`, below this module and the codecs.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Iterable

import numpy as np
from scipy.ndimage import uniform_filter1d

from .. import _validate
from ..errors import MocycleError
from ..motion import Motion
from ..rotations import (
    quat_conj,
    quat_log,
    quat_multiply,
)
from ..segmentation import DEFAULT_THRESHOLD, PAPER_WINDOW_S, Hold, Segmentation, Swing, swing_angles
from ..threads import limit_threads

__all__ = ["DEFAULT_THRESHOLD", "PAPER_WINDOW_S", "Hold", "Segmentation", "Swing", "choose_joints", "segment",
           "swing_angles"]  # the records are mocycle.segmentation's


#: Name patterns of small bones left out by default (fingers, toes, twist and helper bones, face).
MINOR_JOINT_PATTERNS = (
    "*finger*", "*thumb*", "*index*", "*middle*", "*mid[0-9]*", "*ring[0-9]*", "*ring", "*pinky*",
    "*toe*", "*twist*", "*sharebone*", "*eye*", "*jaw*", "*tongue*", "*teeth*", "*facial*",
    "*breast*", "*end*", "*nub*",
)
#: frames per block where a whole take's angular velocities would otherwise be held at once
SPEED_BLOCK = 8192


# ---------------------------------------------------------------- the paper's steps
def window_frames(window_s: float, fps: float) -> int:
    """Box-filter length in frames for ``window_s`` seconds at ``fps`` (at least 1)."""
    return max(1, int(round(window_s * fps)))


def angular_velocity(quats: np.ndarray, frame_time: float) -> np.ndarray:
    """Angular velocity as an exponential map, ``(T-1, ...)`` → rad/s: ``log(q_{t+1} ⊗ q_t⁻¹) / dt``.

    ``quats``: ``(T, ..., 4)`` local rotations.  The velocity is in the parent's
    frame (left difference), so a joint turning about a fixed parent axis gives
    a constant direction.
    """
    q = np.asarray(quats, dtype=np.float64)
    dq = quat_multiply(q[1:], quat_conj(q[:-1]))
    dq = dq * np.where(dq[..., 3:4] < 0, -1.0, 1.0)  # shortest way
    return quat_log(dq) / frame_time


def smooth_velocity(omega: np.ndarray, n: int) -> np.ndarray:
    """Box filter of ``n`` frames along time (the paper's convolution of the exponential maps)."""
    if n <= 1 or omega.shape[0] == 0:
        return np.array(omega, dtype=np.float64)
    return uniform_filter1d(np.asarray(omega, dtype=np.float64), size=n, axis=0, mode="nearest")


def unit_axes(omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation axes (unit, 0 where the joint is still) and speeds of ``(n, 3)`` velocities."""
    speed = np.linalg.norm(omega, axis=-1)
    axes = omega / np.maximum(speed, 1e-12)[..., None]
    axes[speed < 1e-9] = 0.0
    return axes, speed


def swing_error(axes: np.ndarray, n: int) -> np.ndarray:
    """``E_t``: mean of ``1 - cos(angle(axis_t, axis_k))`` over the ``n``-frame window centred on ``t`` (0-2)."""
    if axes.shape[0] == 0:
        return np.zeros(0)
    mean_axis = uniform_filter1d(axes, size=max(n, 1), axis=0, mode="nearest")
    return 1.0 - np.sum(axes * mean_axis, axis=-1)


def grow_swings(axes: np.ndarray, error: np.ndarray, eligible: np.ndarray, threshold: float,
                min_length: int) -> list[tuple[int, int, float]]:
    """Greedy growth (paper 4.2): swings as ``(first, last, mean error)`` velocity-sample ranges.

    Seeds are taken in order of increasing ``error``; a swing adds its left or
    right neighbour, whichever has the smaller axis error ``1 - cos`` against
    the seed, while the average error stays ``<= threshold``.  Swings shorter
    than ``min_length`` samples are dropped (their frames stay free).
    """
    n = axes.shape[0]
    taken = ~np.asarray(eligible, dtype=bool)
    ax = axes.tolist()
    free = (~taken).tolist()
    out = []
    for f in np.argsort(error, kind="stable").tolist():
        if not free[f]:
            continue
        rx, ry, rz = ax[f]
        lo = hi = f
        total, count = 0.0, 1
        el = er = None
        while True:
            if el is None and lo > 0 and free[lo - 1]:
                a = ax[lo - 1]
                el = 1.0 - (a[0] * rx + a[1] * ry + a[2] * rz)
            if er is None and hi < n - 1 and free[hi + 1]:
                a = ax[hi + 1]
                er = 1.0 - (a[0] * rx + a[1] * ry + a[2] * rz)
            if el is None and er is None:
                break
            go_left = er is None or (el is not None and el <= er)
            e = el if go_left else er
            assert e is not None  # the side chosen is open (both closed broke out above)
            if (total + e) / (count + 1) > threshold:
                break
            total += e
            count += 1
            if go_left:
                lo -= 1
                el = None
            else:
                hi += 1
                er = None
        if hi - lo + 1 >= min_length:
            for k in range(lo, hi + 1):
                free[k] = False
            out.append((lo, hi, total / count))
        else:
            free[f] = False  # processed: it seeds nothing, and other swings may not grow over it either
    return sorted(out)


# ---------------------------------------------------------------- joint choice
def choose_joints(motion: Motion, joints: str | Iterable[str] | None = None, min_energy: float = 0.05,
                  exclude: Iterable[str] = MINOR_JOINT_PATTERNS) -> list[int]:
    """Joints to segment: ``joints`` (names, globs, groups) when given, else the major bones.

    The default leaves out fingers, toes, twist and face bones by name
    (``exclude`` patterns) and keeps the joints whose motion energy (mean
    angular speed) is at least ``min_energy`` times the largest among the rest.
    """
    skel = motion.skeleton
    if joints is not None:
        chosen = skel.select(joints)
        if not chosen:
            raise MocycleError("option 'joints' selected no joint")
        return chosen
    pats = [p.lower() for p in exclude]
    major = [j for j, n in enumerate(skel.names) if not any(fnmatch.fnmatch(n.lower(), p) for p in pats)]
    if motion.n_frames < 2 or not major:
        return major
    T = motion.n_frames
    speeds = np.empty((T - 1, len(major)))
    for f0 in range(0, T - 1, SPEED_BLOCK):  # blocks of frames (one frame of overlap): no (T, J, 4) temporaries
        q = motion.rotations[f0:min(f0 + SPEED_BLOCK, T - 1) + 1, major]
        speeds[f0:f0 + q.shape[0] - 1] = np.linalg.norm(angular_velocity(q, 1.0), axis=-1)
    speed = speeds.mean(axis=0)
    top = float(speed.max())
    if top <= 1e-9:
        return []
    return [j for j, s in zip(major, speed, strict=True) if s >= min_energy * top]


# ---------------------------------------------------------------- fitting
def _ranges(first: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All indices of the ranges ``first[i] .. first[i] + count[i] - 1`` and the range each belongs to."""
    owner = np.repeat(np.arange(first.size), count)
    offsets = np.cumsum(count) - count
    return first[owner] + np.arange(owner.size) - offsets[owner], owner


def _range_sums(values: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Sums of ``values[first[i]:last[i] + 1]`` along axis 0 for disjoint, increasing ranges (added in order)."""
    padded = np.concatenate([values, np.zeros((1,) + values.shape[1:])])  # reduceat's indices must be < len
    edges = np.stack([first, last + 1], axis=1).ravel()
    return np.add.reduceat(padded, edges, axis=0)[::2]


def _range_unwrap(p: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """``np.unwrap`` of each range of ``p`` (ranges are consecutive runs of ``owner``)."""
    dd = np.diff(p)
    ddmod = np.mod(dd + np.pi, 2 * np.pi) - np.pi
    ddmod[(ddmod == -np.pi) & (dd > 0)] = np.pi
    correct = ddmod - dd
    correct[np.abs(dd) < np.pi] = 0.0
    correct[owner[1:] != owner[:-1]] = 0.0  # no correction carried across ranges
    if not correct.any():
        return p
    total = np.concatenate([[0.0], np.cumsum(correct)])
    starts = np.flatnonzero(np.concatenate([[True], owner[1:] != owner[:-1]]))
    return p + total - total[starts][np.searchsorted(starts, np.arange(p.size), side="right") - 1]


def _twists(q: np.ndarray, axis: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """:func:`~mocycle.rotations.twist_angles` of each range: ``q`` (m, 4), ``axis`` (m, 3) per row."""
    return _range_unwrap(2.0 * np.arctan2(np.einsum("ij,ij->i", q[:, :3], axis), q[:, 3]), owner)


def fit_swings(q: np.ndarray, axes: np.ndarray, speed: np.ndarray, spans: list[tuple[int, int, float]],
               joint: int, name: str, frame_time: float) -> list[Swing]:
    """Swing records of one joint for the ``spans`` ``(first, last, error)`` of :func:`grow_swings` (velocity
    samples ``first..last``, frames ``first..last+1``), all at once: :func:`fit_swing` for each.

    ``q`` (T, 4) the joint's quaternions, ``axes`` (T-1, 3) and ``speed`` (T-1,) its smoothed velocity axes and
    speeds (rad/s)."""
    if not spans:
        return []
    first = np.array([f for f, _, _ in spans])
    last = np.array([la for _, la, _ in spans])
    axis = _range_sums(axes * speed[:, None], first, last)
    norm = np.linalg.norm(axis, axis=1)
    axis = np.where(norm[:, None] < 1e-12, axes[first], axis / np.maximum(norm, 1e-300)[:, None])
    count = last - first + 2  # frames
    rows, owner = _ranges(first, count)
    qs = q[rows]
    ax = axis[owner]
    theta = _twists(qs, ax, owner)
    half = -0.5 * theta
    rest = quat_multiply(np.concatenate([np.sin(half)[:, None] * ax, np.cos(half)[:, None]], axis=1), qs)
    starts = np.cumsum(count) - count
    ends = starts + count - 1
    rest *= np.where(np.einsum("ij,ij->i", rest, rest[starts][owner]) < 0, -1.0, 1.0)[:, None]
    base = _range_sums(rest, starts, ends)  # mean_quat of each range: the sign-aligned normalised sum
    base /= np.linalg.norm(base, axis=1, keepdims=True)
    theta = _twists(quat_multiply(qs, quat_conj(base)[owner]), ax, owner)
    a0, a1 = theta[starts], theta[ends]
    n = count.astype(np.float64)
    u = (rows - first[owner]) / (n - 1)[owner]
    dur = (n - 1) * frame_time
    h0 = (u**3 - 2 * u**2 + u) * dur[owner]
    h1 = (u**3 - u**2) * dur[owner]
    r = theta - (2 * u**3 - 3 * u**2 + 1) * a0[owner] - (-2 * u**3 + 3 * u**2) * a1[owner]
    # least squares of [h0 h1] (v0, v1) = r per swing (the ends are kept exactly; the end speeds fit the inside)
    ata = np.stack([_range_sums(h0 * h0, starts, ends), _range_sums(h0 * h1, starts, ends),
                    _range_sums(h1 * h1, starts, ends)], axis=1)
    atb = np.stack([_range_sums(h0 * r, starts, ends), _range_sums(h1 * r, starts, ends)], axis=1)
    det = ata[:, 0] * ata[:, 2] - ata[:, 1] ** 2
    v0 = (ata[:, 2] * atb[:, 0] - ata[:, 1] * atb[:, 1]) / np.where(det != 0, det, 1.0)
    v1 = (ata[:, 0] * atb[:, 1] - ata[:, 1] * atb[:, 0]) / np.where(det != 0, det, 1.0)
    short = count < 3
    v0[short] = v1[short] = ((a1 - a0) / dur)[short]
    # ill-conditioned normal equations (3 frames: one inner frame, two unknowns): lstsq's minimum-norm answer
    for i in np.flatnonzero(~short & ~(np.abs(det) > 1e-10 * (ata[:, 0] + ata[:, 2]) ** 2)):
        s, e = starts[i], ends[i] + 1
        (v0[i], v1[i]), *_ = np.linalg.lstsq(np.stack([h0[s:e], h1[s:e]], axis=1), r[s:e], rcond=None)
    shift = 2 * np.pi * np.round(a0 / (2 * np.pi))  # Rot(a, θ) has period 2π: keep the start in [-π, π]
    base = np.where(base[:, 3:4] < 0, -base, base)
    rotvec = quat_log(base)
    return [Swing(joint=joint, name=name, start=f, end=la + 1, axis=tuple(a), start_angle=s0, end_angle=s1,
                  start_speed=w0, end_speed=w1, base=tuple(b), error=float(err))
            for (f, la, err), a, s0, s1, w0, w1, b in zip(
                spans, axis.tolist(), (a0 - shift).tolist(), (a1 - shift).tolist(), v0.tolist(), v1.tolist(),
                rotvec.tolist(), strict=True)]


def fit_swing(q: np.ndarray, axes: np.ndarray, speed: np.ndarray, first: int, last: int, joint: int, name: str,
              frame_time: float, err: float) -> Swing:
    """Swing record for velocity samples ``first..last`` (frames ``first..last+1``) of one joint's quats ``q``.

    The swing's axis is the speed-weighted mean of its frames' axes; ``base`` the mean of what is left off
    that axis; the angles about the axis at its ends are kept exactly and the end speeds are the least-squares
    fit of the cubic Hermite to the inside.  (:func:`fit_swings` does many at once.)"""
    return fit_swings(q, axes, speed, [(first, last, err)], joint, name, frame_time)[0]


def _holds(q: np.ndarray, spans: list[tuple[int, int]], n_frames: int, joint: int, name: str,
           max_hold: int | None) -> list[Hold]:
    """Holds for the frames outside the swing ``spans`` (inclusive frame ranges), split every ``max_hold`` frames."""
    covered = np.zeros(n_frames, dtype=bool)
    for s, e in spans:
        covered[s:e + 1] = True
    free = np.flatnonzero(~covered)
    if free.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(free) > 1) + 1
    run_first = free[np.concatenate([[0], breaks])]
    run_last = free[np.concatenate([breaks - 1, [free.size - 1]])]
    length = run_last - run_first + 1
    pieces = np.ones_like(length) if not max_hold else np.maximum(1, np.ceil(length / max_hold).astype(int))
    first, last = [], []
    for a, b, k in zip(run_first.tolist(), (run_last + 1).tolist(), pieces.tolist(), strict=True):
        if k == 1:
            first.append(a)
            last.append(b - 1)
        else:
            edges = np.linspace(a, b, k + 1).round().astype(int)
            first += edges[:-1].tolist()
            last += (edges[1:] - 1).tolist()
    first_a, last_a = np.array(first), np.array(last)
    rows, owner = _ranges(first_a, last_a - first_a + 1)
    qs = q[rows]
    starts = np.searchsorted(owner, np.arange(first_a.size))
    qs = qs * np.where(np.einsum("ij,ij->i", qs, qs[starts][owner]) < 0, -1.0, 1.0)[:, None]
    mean = _range_sums(qs, starts, starts + last_a - first_a)  # mean_quat of each hold
    mean /= np.linalg.norm(mean, axis=1, keepdims=True)
    mean = quat_log(np.where(mean[:, 3:4] < 0, -mean, mean))
    return [Hold(joint=joint, name=name, start=s, end=e, mean=tuple(m))
            for s, e, m in zip(first, last, mean.tolist(), strict=True)]


#: Translation tracks are simplified in spans of this many frames (a key at every multiple): the
#: Ramer-Douglas-Peucker splits cost the span's length each, so long periodic paths stay linear in time.
TRACK_SPAN = 8192


def translation_track(values: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Piecewise-linear keys ``(frames, values)`` within ``tol`` of ``values`` (T, 3) (Ramer-Douglas-Peucker,
    with a key every :data:`TRACK_SPAN` frames)."""
    values = np.asarray(values, dtype=np.float64)
    T = values.shape[0]
    if T == 1 or np.ptp(values, axis=0).max() <= 1e-9:
        return np.array([0]), values[:1].copy()
    keep = np.zeros(T, dtype=bool)
    fixed = list(range(0, T - 1, TRACK_SPAN)) + [T - 1]
    keep[fixed] = True
    stack = list(zip(fixed[:-1], fixed[1:], strict=True))
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        u = (np.arange(a + 1, b) - a) / (b - a)
        line = values[a] + u[:, None] * (values[b] - values[a])
        dev = np.linalg.norm(values[a + 1:b] - line, axis=1)
        k = int(np.argmax(dev))
        if dev[k] > tol:
            m = a + 1 + k
            keep[m] = True
            stack += [(a, m), (m, b)]
    frames = np.flatnonzero(keep)
    return frames, values[frames].copy()


# ---------------------------------------------------------------- entry point
@limit_threads
def segment(motion: Motion, threshold: float = DEFAULT_THRESHOLD, joints: str | Iterable[str] | None = None,
            window_s: float = PAPER_WINDOW_S, min_swing_s: float | None = None, still_deg_s: float = 20.0,
            max_hold_s: float | None = 0.5, translation_tol: float | None = None) -> Segmentation:
    """Segment ``motion`` into joint swings and holds (paper 003, section 4.2).

    Parameters
    ----------
    threshold : the Acceptable Swing Error, 0-2 (0 accepts only perfectly geodesic swings).
    joints : joints to segment (names, globs, groups); ``None`` chooses the major bones
        (:func:`choose_joints`).  The other joints become holds.
    window_s : box filter and error window in seconds (paper: 20 frames at 120 fps).
    min_swing_s : shortest swing kept, seconds (default half the window, at least 2 frames).
    still_deg_s : smoothed angular speed (deg/s) under which a joint counts as still: such
        frames seed no swing and join none (their axis is noise).
    max_hold_s : long holds are split into holds of at most this many seconds (``None``: never),
        so slow drifts are kept by interpolation between their means.
    translation_tol : tolerance of the piecewise-linear translation track in file units
        (default 0.1 % of the skeleton's height).

    Returns
    -------
    Segmentation
        ``swings`` and ``holds`` per joint (``swings_of(j)``, ``holds_of(j)``), ``to_records()``,
        ``to_dict()``; :func:`~mocycle.swings.playback` rebuilds the motion, ``mocycle.write(seg,
        "take.mosw")`` stores it.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60).motion
    >>> seg = segment(walk, threshold=0.4)
    >>> seg.n_swings, len(seg.joints), seg.swings_of(seg.joints[1])[0].name
    (205, 20, 'LeftUpLeg')
    """
    if not isinstance(motion, Motion):
        raise MocycleError(f"segment() needs a Motion; got {type(motion).__name__}")
    threshold = _validate.real("threshold", threshold, 0.0, 2.0)  # the Acceptable Swing Error
    window_s = _validate.real("window_s", window_s, 0.0, 10.0, low_open=True)
    if still_deg_s < 0 or not np.isfinite(still_deg_s):
        raise MocycleError(f"still_deg_s must be >= 0 degrees per second; got {still_deg_s}")
    if max_hold_s is not None and not max_hold_s > 0:
        raise MocycleError(f"max_hold_s must be > 0 seconds or None; got {max_hold_s}")
    skel, T, dt = motion.skeleton, motion.n_frames, motion.frame_time
    n_win = window_frames(window_s, motion.fps)
    min_len = max(2, int(round((0.5 * window_s if min_swing_s is None else min_swing_s) / dt)))
    max_hold = None if max_hold_s is None else max(1, int(round(max_hold_s / dt)))
    chosen = choose_joints(motion, joints)
    swings: list[Swing] = []
    holds: list[Hold] = []
    for j in chosen if T >= 3 else []:
        omega = smooth_velocity(angular_velocity(motion.rotations[:, j], dt), n_win)  # (T-1, 3); joint by joint
        axes, speed = unit_axes(omega)
        error = swing_error(axes, n_win)
        eligible = speed >= np.radians(still_deg_s)
        error = np.where(eligible, error, np.inf)
        spans_j = grow_swings(axes, error, eligible, threshold, min_len)
        swings += fit_swings(motion.rotations[:, j], axes, speed, spans_j, j, skel.names[j], dt)
    spans: dict[int, list[tuple[int, int]]] = {}
    for s in swings:
        spans.setdefault(s.joint, []).append((s.start, s.end))
    for j in range(skel.n_joints):
        holds += _holds(motion.rotations[:, j], spans.get(j, []), T, j, skel.names[j], max_hold)
    if translation_tol is None:
        height = float(np.ptp(Motion.rest(skel).world_positions(end_sites=True)[0], axis=0).max())
        translation_tol = 1e-3 * max(height, 1e-9)
    keys = {j: translation_track(motion.joint_translations(j), translation_tol) for j in range(skel.n_joints)}
    return Segmentation(skeleton=skel, n_frames=T, frame_time=dt, joints=list(chosen), swings=swings, holds=holds,
                        translation_keys=keys, threshold=threshold, window_s=window_s,
                        params=dict(min_swing_frames=min_len, still_deg_s=float(still_deg_s),
                                    max_hold_s=max_hold_s, translation_tol=float(translation_tol),
                                    window_frames=n_win))
