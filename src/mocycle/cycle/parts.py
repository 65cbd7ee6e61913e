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
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..activities import Activities, Activity, heading_degrees, nothing_to_loop, segment_activities, stride_reference
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion, OptionError
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
class PartLoop:
    """One part's loop: ``index`` in the take's parts, the ``part``, the ``cycle`` fitted on its frames (frame 0
    of the cycle's time axis is the part's first frame), the loop ``metrics`` against those frames and the checks
    it ``failed`` (kept only when forced)."""

    index: int
    part: Activity
    cycle: Cycle
    metrics: dict
    failed: list[FailedCheck]

    @property
    def offset(self) -> int:
        """The part's first frame in the take."""
        return self.part.start


def part_phase(part: Activity) -> PhaseResult:
    """The phase of a part's frames as :func:`~mocycle.cycle.extract_cycle` takes it: the part's one periodic
    motion.  Raises :class:`NoPeriodicMotion` (with the part's reason) for a part that does not loop."""
    pm = part.periodic
    if not part.loop or pm is None:
        raise NoPeriodicMotion(part.reason or f"the {part.kind} part does not repeat")
    return PhaseResult(classes=[pm], barcode=np.zeros((0, 2)), reason=pm.period_reason,
                       autocorrelation_period_frames=float("nan"), n_frames=part.n_frames,
                       frame_time=pm.frame_time, joints_used=pm.joints_used)


def part_checks(motion: Motion, acts: Activities, part: Activity, cycle: Cycle) -> list[FailedCheck]:
    """The checks a part's loop must pass beside :func:`~mocycle.cycle.checks.loop_checks`, on the take's own
    evidence over the frames the loop was fitted on (``motion``: the whole take; ``cycle`` fitted on the part's
    frames): a gait part's cycle agrees with the stride period of the landings there (within
    :data:`STRIDE_AGREEMENT`; the landings found once, ``acts.landings``), and every loop turns as the hips do
    there (within max(:data:`TURN_SLACK_DEG`, :data:`TURN_SLACK_SHARE` × the take's turn))."""
    failed = []
    s, e = part.start + cycle.axis.regions[0][0], part.start + cycle.axis.regions[-1][1]
    P = cycle.period_frames
    if acts.landings is not None and part.gait:
        rulers, _ = stride_reference(motion, acts.landings, s, e)
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
    heading = heading_degrees(motion)[s:e]
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


def loop_part(motion: Motion, acts: Activities, index: int, *, method: str = "harmonic", model: str = "M1",
              harmonics: int | str = "auto", time_axis: str = "smooth", force: bool = False, label: str = "",
              timer: Callable[[str], contextlib.AbstractContextManager] | None = None) -> PartLoop:
    """The loop of part ``index`` of ``acts`` (the parts of ``motion``): its cycle fitted on the part's frames
    with the part's phase, its metrics, and its checks (:func:`~mocycle.cycle.checks.check_loop` with
    :func:`part_checks`).  ``label`` names the take in messages; ``timer(name)``: a context that times the
    ``"cycle"`` and ``"metrics"`` stages.

    Raises :class:`NoPeriodicMotion` when the part does not loop (its reason), :class:`LoopRefused` when its
    cycle fails a check (``force``: a warning instead, the failures in ``failed``), :class:`MocycleError` when
    the fit cannot be made on the part's frames."""
    timer = timer or (lambda name: contextlib.nullcontext())
    part = acts.parts[index]
    phase = part_phase(part)
    piece = motion[part.start:part.stop]  # a view: the part's frames only
    with timer("cycle"):
        cycle = extract_cycle(piece, method=method, model=model, harmonics=harmonics, time_axis=time_axis,
                              phase=phase)
    with timer("metrics"):
        metrics = loop_metrics(piece, cycle, cycle.repeat(2, root="motion"))
        where = label if len(acts.parts) == 1 else \
            f"{label + ' ' if label else ''}part {index} ({part.kind}, frames {part.start}-{part.stop})"
        failed = check_loop(piece, cycle, metrics, force=force, label=where,
                            extra=part_checks(motion, acts, part, cycle))
    return PartLoop(index=index, part=part, cycle=cycle, metrics=metrics, failed=failed)


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
