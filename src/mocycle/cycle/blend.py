"""New periodic motion from old: blends of cycles and transitions between them (paper 001 §4.5).

Paper 001 §4.5 (*Interpolation*): each input's typical cycle ``x_i`` is a loop
parametrised by the circle ``[0, 1)``; resampled to a common number of frames
and brought to a common phase, their convex combination
``y(θ) = Σ w_i x_i(θ)`` is again a loop.  Moving the weight from 0 to 1 gives a
*homotopy* between two loops: a transition.

Here, with the cycles of :func:`~mocycle.cycle.extract_cycle`:

* **common space** — every cycle is read in the :class:`CycleSpace` of the
  first one (its skeleton, frame time, vertical axis and heading convention);
  its in-place loop is turned about the vertical so that it travels in the
  first one's direction (so a style whose pelvis is turned a little off its
  walking direction keeps that), or, for loops on the spot or turns of more
  than 45° off the facing, so that its mean heading is the first one's; its
  horizontal path is centred (where a take started in the room is not blended).
* **common length** — ``N = round(Σ w_i T_i)`` frames for periods ``T_i`` in the
  first input's frames (periods in seconds are blended, so inputs at other frame
  rates work too); each loop is read at phases ``k / N`` by slerp of its
  rotations and linear interpolation of its translations, on the circle
  (the wrap from its last frame to its first is an ordinary step):
  :func:`resample_cycle`.
* **phase alignment** — paper 001 §7 "aligning motions becomes a 1-dimensional
  search": the circular shift of each loop against the first that minimises the
  mean chordal pose distance ``Σ_j ||R_j - R'_j||²_F`` over the joints (local
  rotation matrices, the travel joint's heading left out), found for all shifts
  at once by circular cross-correlation and refined below a frame by a parabola:
  :func:`align_phase`.  Offsets are in cycles, ``[0, 1)``.
* **rotation blend** — per joint and frame the weighted chordal L2 mean of the
  rotation matrices (the weighted sum projected back onto SO(3) by SVD).  That
  is exactly what ``scipy`` ``Rotation.mean(weights=)`` computes (Markley's
  quaternion mean minimises the same loss); it is done here in one vectorised
  step and checked against scipy in the tests.  Never Euler angles.  The travel
  joint's heading about the vertical is blended as an angle (all headings are
  aligned first), its tilt as a rotation.
* **root** — the in-place path (sway, bob) and the per-cycle drift (travel and
  turn per cycle) are blended with the same weights, so the blend is a loop
  whose repetition walks on at the blended stride.  The loop is then started at
  its calmest pose (:func:`~mocycle.cycle.seam.calmest_start`), like every
  extracted cycle.

:func:`transition` is the homotopy: over ``n`` cycles the weight of the second
cycle moves from 0 to 1 by a smoothstep of the unwrapped phase ``φ``; the
period ``T(w)`` changes with it, so the phase is integrated,
``dφ/dt = 1 / T(w(φ))`` (closed form for the smoothstep), and travel and turn
are integrated along the same phase.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from dataclasses import replace as dc_replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError, NoPeriodicMotion, OptionError
from ..limits import check_frames
from ..motion import Motion, Skeleton
from ..rotations import axis_rotations, nearest_rotations
from ..threads import limit_threads
from .checks import check_loop
from .extract import extract_cycle
from .metric_rows import loop_blocks, metric_features
from .representation import CycleSpace
from .result import ROOT_MODES, Cycle, drifting_L
from .seam import LOCAL, calmest_start, seam_ratios
from .timeaxis import TimeAxis

MAX_LISTED = 8  # joints named in a skeleton error before "and N more"
TRAVEL_OR_FACING = np.radians(45.0)  # align travel directions unless that turns a take this much off its facing


# ------------------------------------------------------------------ validation
def _names(items: list[str]) -> str:
    shown = ", ".join(repr(n) for n in items[:MAX_LISTED])
    return shown + (f" and {len(items) - MAX_LISTED} more" if len(items) > MAX_LISTED else "")


#: Rest offsets this close (a share of the skeleton's largest offset) are the same bone: a file's takes read
#: through float32 node transforms differ in the last digits (RobotExpressive's palms: 3.8e-7 of 1.7 units)
OFFSET_TOLERANCE = 1e-5


def skeleton_differences(a: Skeleton, b: Skeleton) -> list[str]:
    """What differs between two skeletons, each item naming the joints (empty when they can be blended).

    Joint names, their order and parents must agree; rest offsets must agree (within :data:`OFFSET_TOLERANCE`
    of the larger skeleton's largest offset) except for
    joints that have position channels in both skeletons, whose offset is replaced by the channels (BVH
    exporters such as Bandai Namco's write the take's start position there).
    """
    problems = []
    if a.names != b.names:
        only_a = [n for n in a.names if n not in b.names]
        only_b = [n for n in b.names if n not in a.names]
        if only_a:
            problems.append(f"joints only in the first: {_names(only_a)}")
        if only_b:
            problems.append(f"joints only in the second: {_names(only_b)}")
        if not only_a and not only_b:
            moved = [n for i, n in enumerate(a.names) if b.names[i] != n]
            problems.append(f"the same joints in another order (first out of place: {_names(moved)})")
        return problems
    parent = [a.names[j] for j in range(a.n_joints) if a.parents[j] != b.parents[j]]
    if parent:
        problems.append(f"joints with another parent: {_names(parent)}")
    size = max(float(np.abs(a.offsets).max(initial=0.0)), float(np.abs(b.offsets).max(initial=0.0)))
    offset = [a.names[j] for j in range(a.n_joints)
              if not (a.position_axes(j) and b.position_axes(j))
              and not np.allclose(a.offsets[j], b.offsets[j], rtol=0.0, atol=OFFSET_TOLERANCE * size)]
    if offset:
        problems.append(f"joints with other rest offsets (bone lengths): {_names(offset)}")
    return problems


def check_weights(weights, n: int) -> np.ndarray:
    """``n`` weights ``>= 0`` normalised to sum 1 (``None``: equal weights)."""
    if weights is None:
        return np.full(n, 1.0 / n)
    try:
        w = np.asarray(weights, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise OptionError("weights", f"must be numbers, one per take; got {weights!r}") from None
    if w.size != n:
        raise OptionError("weights", f"must be {n} numbers, one per take; got {w.size}")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise OptionError("weights", f"must be finite and >= 0; got {w.tolist()}")
    if w.sum() <= 0:
        raise OptionError("weights", "must have at least one weight > 0; got all zero")
    return w / w.sum()


def _period_frames(cycle: Cycle) -> float:
    """The duration of one loop in the cycle's own frames (the cut's own length, else the input's period)."""
    return float(cycle.n_frames if cycle.method == "cut" else cycle.period_frames)


def _cycles(takes, labels, extract_options, force: bool = False) -> list[Cycle]:
    """The takes' cycles (Motions are extracted, then checked as loops: :func:`~mocycle.cycle.checks.check_loop`
    raises LoopRefused, or warns with ``force``)."""
    if isinstance(takes, (Motion, Cycle)) or not isinstance(takes, Sequence) or len(takes) == 0:
        raise MocycleError("expected a non-empty list of takes (Motion or Cycle objects)")
    labels = list(labels) if labels is not None else [f"take {i + 1}" for i in range(len(takes))]
    if len(labels) != len(takes):
        raise MocycleError(f"expected {len(takes)} labels, one per take; got {len(labels)}")
    skeletons = []
    for take, label in zip(takes, labels, strict=True):
        if not isinstance(take, (Motion, Cycle)):
            raise MocycleError(f"{label}: expected a Motion or a Cycle; got {type(take).__name__}")
        skeletons.append(take.skeleton if isinstance(take, Motion) else take.space.skeleton)
    for skel, label in zip(skeletons[1:], labels[1:], strict=True):   # before the (slower) extraction
        problems = skeleton_differences(skeletons[0], skel)
        if problems:
            raise MocycleError(f"{label} has another skeleton than {labels[0]}: " + "; ".join(problems))
    cycles = []
    for take, label in zip(takes, labels, strict=True):
        if isinstance(take, Cycle):
            cycles.append(take)
            continue
        try:
            cycle = extract_cycle(take, **extract_options)
        except NoPeriodicMotion as exc:
            raise NoPeriodicMotion(f"{label}: {exc}") from None
        except MocycleError as exc:  # say which take: the user gave several
            raise MocycleError(f"{label}: {exc}") from None
        check_loop(take, cycle, force=force, label=label)
        cycles.append(cycle)
    first = cycles[0].space
    for cycle, label in zip(cycles[1:], labels[1:], strict=True):
        if cycle.space.travel != first.travel:
            names = first.skeleton.names
            raise MocycleError(f"{label} travels on joint {names[cycle.space.travel]!r}, {labels[0]} on "
                               f"{names[first.travel]!r}: the takes cannot be blended")
    return cycles


def _common_space(cycles: list[Cycle]) -> CycleSpace:
    """The first cycle's space, with every joint whose translation moves in any cycle kept as moving."""
    space = cycles[0].space
    moving = sorted(set().union(*(c.space.moving for c in cycles)) - {space.travel})
    return dc_replace(space, moving=tuple(moving))


# ------------------------------------------------------------------ resampling
def _circular_sample(motion: Motion, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Quaternions ``(T, J, 4)`` and translations ``(T, J, 3)`` of a loop ``motion`` (frame ``n`` = frame 0)
    read at fractional frame ``positions`` ``(T,)``: rotations by slerp, translations linearly."""
    n, J = motion.n_frames, motion.n_joints
    pos = np.asarray(positions, dtype=np.float64)
    base = np.floor(pos)
    f = pos - base
    i0 = base.astype(np.int64) % n
    i1 = (i0 + 1) % n
    q0 = Rotation.from_quat(motion.rotations[i0].reshape(-1, 4))
    q1 = Rotation.from_quat(motion.rotations[i1].reshape(-1, 4))
    step = (q0.inv() * q1).as_rotvec() * np.repeat(f, J)[:, None]   # slerp: the shortest arc, a fraction f
    quats = (q0 * Rotation.from_rotvec(step)).as_quat().reshape(pos.size, J, 4)
    trans = (1 - f)[:, None, None] * motion.translations_at(i0) + f[:, None, None] * motion.translations_at(i1)
    return quats, trans


def resample_cycle(cycle: Motion, n_frames: int, shift: float = 0.0, frame_time: float | None = None) -> Motion:
    """A loop of ``n_frames`` frames read from the loop ``cycle`` (its frame ``N`` would equal frame 0).

    New frame ``k`` is the old loop at phase ``k / n_frames + shift`` (cycles), i.e. old frame
    ``(k / n_frames + shift) * N``: rotations by slerp, translations linearly, the wrap included.
    ``frame_time``: seconds per new frame (default: the same duration, ``cycle.frame_time * N / n_frames``).
    """
    if not isinstance(cycle, Motion):
        raise MocycleError(f"resample_cycle needs a Motion; got {type(cycle).__name__}")
    if isinstance(n_frames, bool) or not isinstance(n_frames, (int, np.integer)) or n_frames < 2:
        raise MocycleError(f"a loop needs an integer number of frames >= 2; got {n_frames!r}")
    if not np.isfinite(shift):
        raise MocycleError(f"the shift must be a finite number of cycles; got {shift!r}")
    N = cycle.n_frames
    quats, trans = _circular_sample(cycle, (np.arange(n_frames) / n_frames + shift) * N)
    return Motion(cycle.skeleton, quats, trans, frame_time or cycle.frame_time * N / n_frames, copy=False)


# ----------------------------------------------------------- prepared inputs
@dataclass(frozen=True)
class _Loop:
    """One input cycle in the common space: its in-place loop and how to bring it to the first one's facing."""

    motion: Motion         # in-place loop on the common skeleton, n frames (frame n = frame 0)
    period: float          # period in the common (first input's) frames
    drift: np.ndarray      # (4,) travel and turn per cycle in the common space, facing-aligned
    turn_to: float         # radians added to the heading (about the vertical) to face like the first
    heading_mean: float    # mean heading of the loop (radians, unwrapped) before turn_to
    centre: np.ndarray     # (3,) horizontal mean of the travel joint's in-place path (file units)
    travel_direction: float | None  # direction of travel per cycle after turn_to (radians), None if on the spot


def _on(skeleton: Skeleton, motion: Motion) -> Motion:
    return Motion(skeleton, motion.rotations, motion.translations_at(0), motion.frame_time,
                  tracks=motion.tracks)


def _prepare(cycle: Cycle, space: CycleSpace, reference: _Loop | None) -> _Loop:
    skel = space.skeleton
    inplace = _on(skel, cycle.motion("inplace"))
    n = cycle.n_frames
    L = space.path(inplace)
    L2 = space.path(_on(skel, cycle.repeat(2, root="motion")))
    drift = L2[n] - L2[0]
    heading = float(L[:, 3].mean())
    pos = L[:, :3] - np.outer(L[:, :3] @ space.up, space.up)
    centre = pos.mean(axis=0)
    travel = _travel_direction(drift, pos, space)
    turn = 0.0
    if reference is not None:
        turn = reference.heading_mean - heading           # facing like the reference
        if travel is not None and reference.travel_direction is not None:
            # both travel: walk in the reference's direction, keeping this style's facing relative to its travel
            # (unless that differs from the facing alignment by more than TRAVEL_OR_FACING)
            extra = float(np.angle(np.exp(1j * (reference.travel_direction - travel - turn))))
            if abs(extra) <= TRAVEL_OR_FACING:
                turn += extra
    drift = drift.copy()
    drift[:3] = axis_rotations(space.up, np.array([turn]))[0] @ drift[:3]
    period = _period_frames(cycle) * cycle.space.frame_time / space.frame_time
    return _Loop(inplace, period, drift, turn, heading, centre, None if travel is None else travel + turn)


def _travel_direction(drift: np.ndarray, path: np.ndarray, space: CycleSpace) -> float | None:
    """Direction (radians, like the heading) of the horizontal travel per cycle, or ``None`` when the loop
    travels less than half the horizontal extent of its own in-place path (walking on the spot)."""
    d = drift[:3] - (drift[:3] @ space.up) * space.up
    extent = float(np.ptp(path, axis=0).max()) if path.size else 0.0
    if np.linalg.norm(d) <= max(1e-9, 0.5 * extent):
        return None
    return float(np.arctan2(d @ space.e2, d @ space.e1))


def _read(loop: _Loop, space: CycleSpace, phases: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``P (T, n_periodic)`` and in-place ``L (T, 4)`` of a loop at ``phases`` (cycles), facing like the first
    input, its horizontal path centred on the origin."""
    quats, trans = _circular_sample(loop.motion, np.mod(phases, 1.0) * loop.motion.n_frames)
    P, L = space.encode(Motion(loop.motion.skeleton, quats, trans, loop.motion.frame_time))
    L = L.copy()
    # encode unwraps the heading from wherever the read starts: bring it to the loop's own branch of 2π
    L[:, 3] += 2 * np.pi * np.round((loop.heading_mean - L[:, 3].mean()) / (2 * np.pi)) + loop.turn_to
    R = axis_rotations(space.up, np.array([loop.turn_to]))[0]
    L[:, :3] = (L[:, :3] - loop.centre) @ R.T
    return P, L


def _rotation_block(P: np.ndarray, n_joints: int) -> np.ndarray:
    return P[:, : 9 * n_joints]


def _best_shift(A: np.ndarray, B: np.ndarray) -> tuple[float, np.ndarray]:
    """The circular shift ``s`` (frames, sub-frame) minimising ``mean_k ||A_k - B_{k+s}||²`` for loops
    ``A``, ``B`` ``(N, D)``, and the cost of every integer shift ``(N,)``."""
    N = A.shape[0]
    corr = np.fft.irfft((np.conj(np.fft.rfft(A, axis=0)) * np.fft.rfft(B, axis=0)).sum(axis=1), n=N)
    cost = ((A ** 2).sum() + (B ** 2).sum() - 2 * corr) / N      # cost[s] = mean_k ||A_k - B_{k+s}||^2
    s = int(np.argmin(cost))
    before, here, after = cost[s - 1], cost[s], cost[(s + 1) % N]
    curve = before - 2 * here + after
    frac = float(np.clip(0.5 * (before - after) / curve, -0.5, 0.5)) if curve > 0 else 0.0
    return s + frac, cost


def _align(loops: list[_Loop], space: CycleSpace, N: int) -> np.ndarray:
    """Phase offsets ``(K,)`` in cycles of every loop against the first (the first gets 0)."""
    J = space.n_joints
    grid = np.arange(N) / N
    ref = _rotation_block(_read(loops[0], space, grid)[0], J)
    offsets = [0.0]
    for loop in loops[1:]:
        shift, _ = _best_shift(ref, _rotation_block(_read(loop, space, grid)[0], J))
        offsets.append(float(np.mod(shift / N, 1.0)))
    return np.array(offsets)


def align_phase(reference: Cycle, other: Cycle, n_frames: int | None = None) -> float:
    """The phase offset (cycles, ``[0, 1)``) at which ``other`` best matches ``reference``.

    ``other`` read from phase ``θ + offset`` matches ``reference`` at phase ``θ``: for
    ``other = reference.rolled(k)`` the offset is ``-k / N`` (mod 1).  Both loops are read at
    ``n_frames`` phases (default: the reference's frames); the search is over every circular shift of the
    mean chordal distance of the joints' rotations (paper 001 §7: a one-dimensional search), refined below a
    frame by a parabola through the best shift and its neighbours.
    """
    cycles = _cycles([reference, other], ["the reference", "the other cycle"], {})
    space = _common_space(cycles)
    first = _prepare(cycles[0], space, None)
    loops = [first, _prepare(cycles[1], space, first)]
    n = reference.n_frames if n_frames is None else n_frames
    n = _validate.integer("n_frames", n, 2)
    return float(_align(loops, space, int(n))[1])


# ------------------------------------------------------------------ blending
def _blend_L(Ls: Sequence[np.ndarray], w: np.ndarray) -> np.ndarray:
    """Weighted sum of in-place ``L`` blocks; ``w`` ``(K,)`` or ``(K, T)`` per frame."""
    w = np.asarray(w, dtype=np.float64)
    w = w[:, :, None] if w.ndim == 2 else w[:, None, None]
    return (w * np.stack(Ls)).sum(axis=0)


def _blend_P(Ps: Sequence[np.ndarray], w: np.ndarray, n_joints: int) -> np.ndarray:
    """Weighted chordal L2 mean of the rotation blocks (projected by SVD here, not left to decode) and the
    weighted mean of the moving translations; ``w`` ``(K,)`` or ``(K, T)``."""
    w = np.asarray(w, dtype=np.float64)
    w = w[:, :, None] if w.ndim == 2 else w[:, None, None]
    P = (w * np.stack(Ps)).sum(axis=0)
    T = P.shape[0]
    P[:, : 9 * n_joints] = nearest_rotations(P[:, : 9 * n_joints].reshape(T, n_joints, 3, 3)).reshape(T, -1)
    return P


def cycle_seam(cycle: Cycle) -> dict[str, float]:
    """Seam ratios of a loop as :func:`~mocycle.cycle.loop_metrics` measures them (rotations in the metrics'
    rotation-matrix space, and the travel joint's in-place path; the larger of the two)."""
    C, root = loop_blocks(cycle)
    seams = [seam_ratios(C), seam_ratios(root)]
    return {f"seam_{k}": max(r[k] for r in seams) for k in ("pose", "velocity", "pose_local", "velocity_local")}


@dataclass(kw_only=True)
class BlendedCycle:
    """A blend of ``K`` cycles (paper 001 §4.5): a loop like :class:`~mocycle.cycle.Cycle`.

    ``cycle``: the blend as a :class:`Cycle` (method ``"blend"``; ``motion(root)``, ``repeat(k, root)``);
    ``weights`` ``(K,)`` summing to 1; ``phase_offsets`` ``(K,)`` in cycles, each input read from that phase
    of its own loop (the first: 0) at the first one's phase 0; ``start_phase``: the phase of the first input
    the blend's frame 0 is at (cycles; the calmest start); ``input_periods`` ``(K,)`` in output frames;
    ``heading_offsets`` ``(K,)``: radians each input was turned about the vertical to travel (or face) like
    the first; ``inputs``: the input cycles.
    """

    cycle: Cycle
    weights: np.ndarray
    phase_offsets: np.ndarray
    start_phase: float
    input_periods: np.ndarray
    heading_offsets: np.ndarray
    inputs: list[Cycle] = field(repr=False)
    seconds: float = 0.0

    @property
    def n_frames(self) -> int:
        return self.cycle.n_frames

    @property
    def period_frames(self) -> float:
        """The weighted period ``Σ w_i T_i`` in output frames (the loop has ``round`` of it)."""
        return self.cycle.period_frames

    @property
    def drift(self) -> np.ndarray:
        return self.cycle.drift

    def motion(self, root: str = "inplace") -> Motion:
        return self.cycle.motion(root)

    def repeat(self, count: int, root: str = "inplace") -> Motion:
        return self.cycle.repeat(count, root)

    def seam(self) -> dict[str, float]:
        """``seam_pose``, ``seam_velocity`` (and ``_local``) of the blend, as :func:`loop_metrics` measures."""
        return cycle_seam(self.cycle)

    def to_dict(self) -> dict:
        return {
            "period_frames": self.period_frames,
            "cycle_frames": self.n_frames,
            "weights": self.weights.tolist(),
            "phase_offsets": self.phase_offsets.tolist(),
            "start_phase": self.start_phase,
            "input_periods_frames": self.input_periods.tolist(),
            "heading_offsets_deg": np.degrees(self.heading_offsets).tolist(),
            "travel_per_cycle": self.drift[:3].tolist(),
            "turn_per_cycle_deg": float(np.degrees(self.drift[3])),
        }


@limit_threads
def blend_cycles(takes: Sequence[Motion | Cycle], weights=None, *, align: bool = True, roll: bool = True,
                 labels: Sequence[str] | None = None, force: bool = False, **extract_options) -> BlendedCycle:
    """Paper 001 §4.5: the convex combination of the takes' cycles, a new loop.

    ``takes``: Motions (their cycle is extracted with ``extract_cycle(**extract_options)``, e.g.
    ``method``, ``model``, ``harmonics``) or :class:`Cycle` objects, all on one skeleton; ``weights``:
    one per take, ``>= 0``, normalised to sum 1 (default equal); ``align``: search each take's phase offset
    against the first (off: every loop is read from its own frame 0); ``roll``: start the blend at its
    calmest pose, as :func:`extract_cycle` does (off: at the first cycle's frame 0); ``labels``: names for
    messages; ``force``: blend a take's cycle that fails a loop check (with a warning) instead of raising
    :class:`~mocycle.errors.LoopRefused`.  The result has ``round(Σ w_i T_i)`` frames at the first take's
    frame time, travels (or, on the spot, faces) like the first take, and its root drifts by the weighted
    travel and turn per cycle.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> slow = synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion
    >>> fast = synthetic_walk(n_frames=300, fps=60, period_s=0.8, seed=1).motion
    >>> blend = blend_cycles([slow, fast], weights=[0.5, 0.5])
    >>> blend.n_frames, blend.weights.tolist()      # (60 + 48) / 2 frames
    (54, [0.5, 0.5])
    """
    t0 = time.perf_counter()
    cycles = _cycles(takes, labels, extract_options, force)
    w = check_weights(weights, len(cycles))
    space = _common_space(cycles)
    first = _prepare(cycles[0], space, None)
    loops = [first] + [_prepare(c, space, first) for c in cycles[1:]]
    periods = np.array([loop.period for loop in loops])
    period = float(w @ periods)
    N = max(2, int(round(period)))
    offsets = _align(loops, space, N) if align else np.zeros(len(loops))
    grid = np.arange(N) / N
    reads = [_read(loop, space, grid + off) for loop, off in zip(loops, offsets, strict=True)]
    J = space.n_joints
    P = _blend_P([r[0] for r in reads], w, J)
    L = _blend_L([r[1] for r in reads], w)
    L[:, :3] += first.centre
    drift = w @ np.stack([loop.drift for loop in loops])
    L = drifting_L(space.up, L, drift)               # the Cycle convention: L carries its drift
    axis = TimeAxis(x=grid.copy(), regions=((0, N),), period_frames=period, method="blend")
    cycle = Cycle(space=space, P=P, L=L, drift=drift, method="blend", model=None, harmonics=None, axis=axis,
                  positions=np.arange(N, dtype=np.float64), periodic=None)
    start = calmest_start(*loop_blocks(cycle)) if roll else 0
    cycle = cycle.rolled(start)
    cycle.seconds = time.perf_counter() - t0
    return BlendedCycle(cycle=cycle, weights=w, phase_offsets=offsets, start_phase=start / N, input_periods=periods,
                        heading_offsets=np.array([loop.turn_to for loop in loops]), inputs=cycles,
                        seconds=cycle.seconds)


# ---------------------------------------------------------------- transition
def _smoothstep(x: np.ndarray) -> np.ndarray:
    return x * x * (3 - 2 * x)


def _smoothstep_integral(x: np.ndarray) -> np.ndarray:
    """``∫_0^x smoothstep``."""
    return x ** 3 - 0.5 * x ** 4


@dataclass(kw_only=True)
class Transition:
    """A motion that starts as the first cycle and ends as the second (paper 001 §4.5, the homotopy).

    ``motion``: ``T`` frames at the first take's frame time; ``phase`` ``(T,)``: unwrapped phase in cycles
    (0 at frame 0; frame ``T`` would be phase ``cycles``); ``weights`` ``(T,)``: the second cycle's weight;
    ``period_frames`` ``(T,)``: the local period in frames; ``phase_offset``: the second cycle's phase
    offset (cycles) against the first; ``periods``: the two input periods in output frames.
    """

    motion: Motion
    phase: np.ndarray
    weights: np.ndarray
    period_frames: np.ndarray
    phase_offset: float
    periods: tuple[float, float]
    cycles: int
    inputs: list[Cycle] = field(repr=False)
    seconds: float = 0.0

    def to_dict(self) -> dict:
        return {
            "frames": self.motion.n_frames,
            "cycles": self.cycles,
            "period_frames_start": float(self.period_frames[0]),
            "period_frames_end": float(self.period_frames[-1]),
            "input_periods_frames": list(self.periods),
            "phase_offset": self.phase_offset,
        }


@limit_threads
def transition(a: Motion | Cycle, b: Motion | Cycle, cycles: int = 3, root: str = "motion", *,
               align: bool = True, labels: Sequence[str] | None = None, force: bool = False,
               **extract_options) -> Transition:
    """Over ``cycles`` cycles, move from ``a``'s cycle to ``b``'s (paper 001 §4.5: a homotopy of loops).

    The weight of ``b`` is ``smoothstep(φ / cycles)`` of the unwrapped phase ``φ``; the local period
    ``T(w) = (1 - w) T_a + w T_b``; the phase is integrated, ``dφ/dt = 1 / T(w)``
    (``t(φ) = T_a φ + (T_b - T_a) n (x³ - x⁴/2)``, ``x = φ / n``), and the time axis is scaled by less than
    half a frame so that frame ``T`` would be phase ``n`` exactly: the result can be preceded by ``a``'s loop
    and followed by ``b``'s loop read from its phase offset.  ``root="motion"``: travel and turn per cycle
    blended with the same weight and integrated along the phase; ``"inplace"``: no travel.  A take whose
    cycle fails a loop check raises :class:`~mocycle.errors.LoopRefused` (``force``: a warning instead).

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> slow = synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion
    >>> fast = synthetic_walk(n_frames=300, fps=60, period_s=0.8, seed=1).motion
    >>> tr = transition(slow, fast, cycles=2)
    >>> tr.motion.n_frames, round(float(tr.period_frames[0])), round(float(tr.period_frames[-1]))
    (108, 60, 48)
    """
    t0 = time.perf_counter()
    _validate.choice("root", root, ROOT_MODES)
    cycles = _validate.integer("cycles", cycles, 1)
    cyc = _cycles([a, b], labels if labels is not None else ["the first take", "the second take"],
                  extract_options, force)
    space = _common_space(cyc)
    first = _prepare(cyc[0], space, None)
    loops = [first, _prepare(cyc[1], space, first)]
    pa, pb = loops[0].period, loops[1].period
    offset = float(_align(loops, space, max(2, int(round(0.5 * (pa + pb)))))[1]) if align else 0.0
    n = int(cycles)
    total = n * 0.5 * (pa + pb)                       # t(n): frames over the n cycles
    check_frames(round(total), space.skeleton.n_joints,
                 f"a transition over {n} cycles")
    T = max(2, int(round(total)))
    scale = T / total
    grid = np.linspace(0.0, n, 256 * n + 1)
    t_grid = scale * (pa * grid + (pb - pa) * n * _smoothstep_integral(grid / n))
    phase = np.interp(np.arange(T, dtype=np.float64), t_grid, grid)
    w = _smoothstep(phase / n)
    Pa, La = _read(loops[0], space, phase)
    Pb, Lb = _read(loops[1], space, phase + offset)
    W = np.stack([1 - w, w])
    P = _blend_P([Pa, Pb], W, space.n_joints)
    L = _blend_L([La, Lb], W)
    if root == "motion":
        from scipy.integrate import cumulative_trapezoid  # transitions only: not loaded by `mocycle loop`

        drift = np.outer(1 - w, loops[0].drift) + np.outer(w, loops[1].drift)   # (T, 4) per cycle
        turn = cumulative_trapezoid(drift[:, 3], phase, initial=0.0)
        Rt = axis_rotations(space.up, turn)                                      # (T, 3, 3)
        travel = cumulative_trapezoid(np.einsum("tij,tj->ti", Rt, drift[:, :3]), phase, axis=0, initial=0.0)
        L[:, :3] = np.einsum("tij,tj->ti", Rt, L[:, :3]) + travel
        L[:, 3] += turn
    L[:, :3] += first.centre
    motion = space.decode(P, L)
    seconds = time.perf_counter() - t0
    return Transition(motion=motion, phase=phase, weights=w, period_frames=scale * ((1 - w) * pa + w * pb),
                      phase_offset=offset, periods=(pa, pb), cycles=n, inputs=cyc, seconds=seconds)


def _local_ratios(x: np.ndarray, periodic: bool) -> float:
    """Largest ``x[k]`` over the median of its ``2 * LOCAL`` neighbours (a pop detector, as for seams)."""
    offsets = np.r_[-LOCAL:0, 1:LOCAL + 1]
    if periodic:
        near = x[(np.arange(x.size)[:, None] + offsets) % x.size]
    else:
        padded = np.concatenate([np.full(LOCAL, np.nan), x, np.full(LOCAL, np.nan)])
        near = padded[np.arange(x.size)[:, None] + LOCAL + offsets]
    ref = np.nanmedian(near, axis=1)
    return float(np.max(x / np.maximum(ref, 1e-12 * max(float(x.max()), 1e-300))))


def transition_smoothness(tr: Transition) -> dict[str, float]:
    """Whether a transition jumps anywhere: its largest pose step and velocity change (in the loop metrics'
    rotation-matrix space, :func:`~mocycle.cycle.metric_rows.metric_features`) over the median of the 8 nearest
    (``step_local``, ``velocity_local``) and over the median of all (``step_ratio``, ``velocity_ratio``); the
    same for the two input loops (``input_*``)."""
    def ratios(m: Motion, periodic: bool) -> dict[str, float]:
        F = metric_features(m)
        if periodic:
            step = np.linalg.norm(F - np.roll(F, 1, axis=0), axis=1)
            acc = np.linalg.norm(np.roll(F, -1, axis=0) - 2 * F + np.roll(F, 1, axis=0), axis=1)
        else:
            step = np.linalg.norm(np.diff(F, axis=0), axis=1)
            acc = np.linalg.norm(np.diff(F, 2, axis=0), axis=1)
        return {"step_ratio": float(step.max() / np.median(step)), "velocity_ratio": float(acc.max() / np.median(acc)),
                "step_local": _local_ratios(step, periodic), "velocity_local": _local_ratios(acc, periodic)}

    out = ratios(tr.motion, False)
    ins = [ratios(c.motion("inplace"), True) for c in tr.inputs]
    out.update({f"input_{k}": max(r[k] for r in ins) for k in list(out)})
    return out
