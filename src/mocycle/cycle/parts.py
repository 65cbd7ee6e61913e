"""The cycle of one steady part of a take (the parts of :func:`~mocycle.activities.segment_activities`).

A take that does several things (a capture session: walk, turn, run, wave, ...) has no one cycle. Every loop
is therefore made from the frames of one part only, with the part's own phase (a line through its landings,
or the periodic motion found inside it), and checked as every loop is
(:func:`~mocycle.cycle.checks.check_loop`) and against its part (:func:`part_checks`: its period against the
strides there, its turn against the hips' there).  Nothing is fitted across a part's borders, so what fails
in one part (too short, a check, a fit error) leaves the others as they are, and a part costs time and
memory in proportion to its own frames.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..activities import (
    Activities,
    Activity,
    Landings,
    heading_degrees,
    nothing_to_loop,
    segment_activities,
    stride_reference,
)
from ..errors import LoopRefused, MocycleError, MocycleWarning, NoPeriodicMotion, OptionError
from ..motion import Motion
from ..phase.analysis import PhaseResult
from .checks import FailedCheck, check_loop
from .extract import extract_cycle
from .metrics import loop_metrics
from .result import Cycle

#: A loop's cycle more than this share off the stride period (the landings of each foot) is not written.
STRIDE_AGREEMENT = 0.06
#: A loop's turn per cycle more than max(TURN_SLACK_DEG, TURN_SLACK_SHARE x the take's) off the take's is not
#: written (degrees, share).
TURN_SLACK_DEG, TURN_SLACK_SHARE = 10.0, 0.25


@dataclass(kw_only=True)
class PartPiece:
    """What looping one part needs, in the part's own frames (frame 0 is the part's first): its ``motion``
    (a view of the take's frames, or a copy once sent to another process), the take's hips ``heading``
    ``(n,)`` in degrees over them (the heading frame fitted once on the take), the take's foot ``landings``
    near them (a stride or two either side, as the stride ruler reads them), the ``part`` itself and its
    ``index`` among the take's parts, ``offset`` its first frame in the take and ``alone`` whether the take is
    this one part.  Its size is the part's: a process that loops it needs nothing else of the take."""

    index: int
    part: Activity
    motion: Motion
    heading: np.ndarray
    landings: Landings | None
    offset: int
    alone: bool


def part_piece(motion: Motion, acts: Activities, index: int) -> PartPiece:
    """The :class:`PartPiece` of part ``index`` of ``acts`` (the parts of ``motion``)."""
    part = acts.parts[index]
    a, b = part.start, part.stop
    landings = None
    if acts.landings is not None:
        L = acts.landings
        P = part.period_frames if np.isfinite(part.period_frames) else b - a
        lo, hi = max(0, int(a - 2 * P)), min(motion.n_frames, int(np.ceil(b + 2 * P)) + 1)
        keep = (L.frames >= lo) & (L.frames < hi)
        landings = Landings(L.frames[keep] - a, L.foot[keep], L.sides, L.down[a:b])
    rebased = replace(part, start=0, stop=b - a, landings={k: [f - a for f in v] for k, v in part.landings.items()})
    return PartPiece(index=index, part=rebased, motion=motion[a:b], heading=heading_degrees(motion)[a:b].copy(),
                     landings=landings, offset=a, alone=len(acts.parts) == 1)


@dataclass(kw_only=True)
class PartLoop:
    """One part's loop: ``index`` in the take's parts, the ``part`` (in its own frames, ``offset`` its first
    frame in the take), the ``cycle`` fitted on its frames (frame 0 of the cycle's time axis is the part's
    first frame), the loop ``metrics`` against those frames and the checks it ``failed`` (kept only when
    forced)."""

    index: int
    part: Activity
    offset: int
    cycle: Cycle
    metrics: dict
    failed: list[FailedCheck]


def part_phase(part: Activity) -> PhaseResult:
    """The phase of a part's frames as :func:`~mocycle.cycle.extract_cycle` takes it: the part's one periodic
    motion.  Raises :class:`NoPeriodicMotion` (with the part's reason) for a part that does not loop."""
    pm = part.periodic
    if not part.loop or pm is None:
        raise NoPeriodicMotion(part.reason or f"the {part.kind} part does not repeat")
    return PhaseResult(classes=[pm], barcode=np.zeros((0, 2)), reason=pm.period_reason,
                       autocorrelation_period_frames=float("nan"), n_frames=part.n_frames,
                       frame_time=pm.frame_time, joints_used=pm.joints_used)


def part_checks(piece: PartPiece, cycle: Cycle) -> list[FailedCheck]:
    """The checks a part's loop must pass beside :func:`~mocycle.cycle.checks.loop_checks`, on the take's own
    evidence over the frames the loop was fitted on (``cycle`` fitted on the piece's frames): a gait part's
    cycle agrees with the stride period there (within :data:`STRIDE_AGREEMENT` of the landings' median stride
    or of the legs' own period, :func:`~mocycle.activities.stride_reference`; the landings found once on the
    take), and every loop turns as the hips do there (within max(:data:`TURN_SLACK_DEG`,
    :data:`TURN_SLACK_SHARE` × the take's turn))."""
    failed = []
    s, e = cycle.axis.regions[0][0], cycle.axis.regions[-1][1]
    P = cycle.period_frames
    if piece.landings is not None and piece.part.gait:
        rulers, _ = stride_reference(piece.motion, piece.landings, s, e)
        if rulers:  # the cycle must agree with one: the landings' median stride, or the legs' own period
            stride = min(rulers, key=lambda r: abs(P / r - 1.0))
            off = P / stride - 1.0
            if abs(off) > STRIDE_AGREEMENT:
                failed.append(FailedCheck(
                    "stride", float(abs(off)), STRIDE_AGREEMENT,
                    f"the cycle ({P:.1f} frames) is {abs(off):.0%} off the strides (each foot lands every "
                    f"{stride:.1f} frames here, the legs repeating)"))
    # the hips' heading over the frames looped, read two ways a ruler might: a line through it, and its change
    # between the ends (a tenth of a period each) over the periods between; the loop must agree with one
    heading = piece.heading[s:e]
    t = np.arange(heading.size, dtype=np.float64)
    h = min(max(1, int(round(0.1 * P))), max(1, heading.size // 4))
    line = float(np.polyfit(t, heading, 1)[0]) * P if heading.size > 2 else 0.0
    ends = float(heading[-h:].mean() - heading[:h].mean()) / max(heading.size - h, 1) * P
    loop_turn = float(cycle.to_dict()["turn_per_cycle_deg"])
    take_turn = min((line, ends), key=lambda v: abs(loop_turn - v))
    slack = max(TURN_SLACK_DEG, TURN_SLACK_SHARE * abs(take_turn))
    if abs(loop_turn - take_turn) > slack:
        failed.append(FailedCheck(
            "turn", float(abs(loop_turn - take_turn)), float(slack),
            f"the loop turns {loop_turn:.0f} degrees per cycle where the take turns {take_turn:.0f} over the frames "
            f"it loops"))
    return failed


def loop_piece(piece: PartPiece, *, method: str = "harmonic", model: str = "M1", harmonics: int | str = "auto",
               time_axis: str = "smooth", force: bool = False, label: str = "",
               timer: Callable[[str], contextlib.AbstractContextManager] | None = None) -> PartLoop:
    """The loop of one part (:class:`PartPiece`): its cycle fitted on the part's frames with the part's phase,
    its metrics, and its checks (:func:`~mocycle.cycle.checks.check_loop` with :func:`part_checks`).  ``label``
    names the take in messages; ``timer(name)``: a context that times the ``"cycle"`` and ``"metrics"`` stages.

    A take that is one cycle (``part.one_cycle``: a game clip) is its own loop: its frames as they are (method
    ``clip``, :func:`~mocycle.cycle.cut.clip_cycle`), whatever ``method`` says.

    Raises :class:`NoPeriodicMotion` when the part does not loop (its reason), :class:`LoopRefused` when its
    cycle fails a check (``force``: a warning instead, the failures in ``failed``), :class:`MocycleError` when
    the fit cannot be made on the part's frames."""
    timer = timer or (lambda name: contextlib.nullcontext())
    part = piece.part
    phase = part_phase(part)
    with timer("cycle"), warnings.catch_warnings():
        if part.one_cycle:  # a clip that is one cycle is its own loop: its frames as they are, not a fit of them
            method = "clip"
            warnings.filterwarnings("ignore", "only .* periods found", MocycleWarning)
        cycle = extract_cycle(piece.motion, method=method, model=model, harmonics=harmonics, time_axis=time_axis,
                              phase=phase)
    with timer("metrics"):
        metrics = loop_metrics(piece.motion, cycle, cycle.repeat(2, root="motion"))
        a, b = piece.offset, piece.offset + part.n_frames
        where = label if piece.alone else \
            f"{label + ' ' if label else ''}part {piece.index} ({part.kind}, frames {a}-{b})"
        failed = check_loop(piece.motion, cycle, metrics, force=force, label=where,
                            extra=part_checks(piece, cycle), skip=("seam", "fit") if part.one_cycle else ())
    return PartLoop(index=piece.index, part=part, offset=piece.offset, cycle=cycle, metrics=metrics, failed=failed)


def loop_part(motion: Motion, acts: Activities, index: int, **options) -> PartLoop:
    """:func:`loop_piece` of part ``index`` of ``acts`` (the parts of ``motion``); ``options``: its."""
    return loop_piece(part_piece(motion, acts, index), **options)


def parts_to_try(acts: Activities, which: int | str | None) -> list[int]:
    """The parts to loop, in the order to try them: ``"all"`` every part that loops, in frame order; an index
    that part alone (checked against the parts there are); ``None`` the parts that loop, the one with the most
    cycles first (the next ones are tried only when it is refused)."""
    parts = acts.parts
    if which == "all":
        return [k for k, p in enumerate(parts) if p.loop]
    if which is None:
        return sorted((k for k, p in enumerate(parts) if p.loop), key=lambda k: -parts[k].n_periods)
    if not 0 <= int(which) < len(parts):
        raise OptionError("which", f"the take has {len(parts)} part(s) (0 to {len(parts) - 1}); got {which}")
    return [int(which)]


def part_cycle(motion: Motion, *, which: int | None = None, method: str = "harmonic", model: str = "M1",
               harmonics: int | str = "auto", time_axis: str = "smooth", force: bool = False, label: str = "",
               **segment_options) -> Cycle:
    """The checked cycle of one part of ``motion`` (``which``; default the part with the most cycles that passes
    its checks): what :func:`~mocycle.cycle.blend_cycles` and :func:`~mocycle.cycle.transition` blend, the
    same loop ``mocycle loop`` writes.  ``segment_options``: :func:`~mocycle.activities.segment_activities`'.
    Raises :class:`NoPeriodicMotion` when no part loops and :class:`LoopRefused` when every part's cycle fails
    a check (the first refusal)."""
    acts = segment_activities(motion, **segment_options)
    refusals: list[LoopRefused] = []
    reasons: list[str] = []
    for k in parts_to_try(acts, which):
        try:
            return loop_part(motion, acts, k, method=method, model=model, harmonics=harmonics,
                             time_axis=time_axis, force=force, label=label).cycle
        except LoopRefused as exc:
            refusals.append(exc)
        except OptionError:
            raise
        except MocycleError as exc:  # NoPeriodicMotion too: that part's own reason
            reasons.append(f"part {k} ({acts.parts[k].kind}): {exc}")
    if refusals:
        raise refusals[0]
    where = f"{label}: " if label else ""
    if reasons:
        raise NoPeriodicMotion(where + "; ".join(reasons))
    raise NoPeriodicMotion(where + nothing_to_loop(acts))
