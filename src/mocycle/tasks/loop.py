"""``loop``: one seamless typical cycle of a take (paper 001 harmonic regression, centroid or cut)."""

from __future__ import annotations

from dataclasses import dataclass

from ..defaults import TIME_AXES
from ..errors import LoopRefused, NoPeriodicMotion, OptionError
from . import fields
from .options import Choice, Flag, Integer, option
from .report import Recorder, Report, label_of, load

#: the loop metrics (``facts["metrics"]``): key -> (label, unit)
METRIC_LABELS = {
    "template_error": ("template error", "rad"),
    "rmse_h": ("RMSE h", "rad"),
    "rmse_dh": ("RMSE h'", "rad/s"),
    "rmse_ddh": ("RMSE h''", "rad/s²"),
    "jerk_ratio": ("jerk, cycle / input", ""),
    "seam_pose": ("seam jump, pose", "× median step"),
    "seam_velocity": ("seam jump, velocity", "× median change"),
    "seam_pose_local": ("seam jump, pose (local)", "× nearby steps"),
    "seam_velocity_local": ("seam jump, velocity (local)", "× nearby changes"),
    "foot_sliding": ("foot sliding, cycle", "units/s"),
    "input_foot_sliding": ("foot sliding, input", "units/s"),
    "skate": ("foot skate, cycle (as fitted)", "units/s"),
    "input_skate": ("foot skate, input", "units/s"),
}


def parse_range(text: str | None, n_frames: int) -> tuple[int, int]:
    """``"START:STOP"`` (frame numbers; negative counts from the end; either may be empty) -> (start, stop)."""
    if not text:
        return 0, n_frames
    try:
        a, _, b = text.partition(":")
        start = int(a) if a.strip() else 0
        stop = int(b) if b.strip() else n_frames
    except ValueError:
        raise OptionError("frame_range", f"must look like START:STOP (frame numbers); got {text!r}") from None
    if start < 0:
        start += n_frames
    if stop < 0:
        stop += n_frames
    if not 0 <= start < stop <= n_frames:
        raise OptionError("frame_range", f"{text} is outside the take's {n_frames} frames")
    return start, stop


def _range_text(name: str, value):
    if value is None or value == "":
        return None
    if not isinstance(value, str) or ":" not in value:
        raise OptionError(name, f"must look like START:STOP (frame numbers); got {value!r}")
    parse_range(value, 2**62)  # the syntax; the bounds are checked against the take
    return value


_range_text.schema = lambda: {"anyOf": [{"type": "string", "pattern": r"^-?\d*:-?\d*$"}, {"type": "null"}]}


@dataclass(frozen=True)
class Options(fields.CycleOptions):
    """Options of ``loop``: how the take's cycle is found (:class:`~mocycle.tasks.fields.CycleOptions`, with the
    loop's own words for a few), which part is looped, and how the loop is written."""

    method: str = fields.method("harmonic (regression), centroid (paper 001) or cut (baseline).")
    model: str = fields.model("Harmonic model: M1 (FGLS-weighted positions, velocities, accelerations), M2 "
                              "(positions only; velocity/acceleration off), M3 (unweighted).")
    which: int | str | None = option(
        None, "Which part of the take to loop (0-based, as listed; default: the steady part with the most cycles), or "
              "'all': one file per part that loops, named OUT.part<k>-<kind>.bvh (kind: walk-straight, "
              "walk-turning-left, run-..., arms, periodic). --class is the old name.",
        Integer(0, words={"all": "all"}, optional=True), flag="--part")
    force: bool = option(False, "Write the cycle even when it fails a loop check (longer than the take, fits much "
                                "worse than a plain cut, seam jumps); a warning names the check. It also lets an "
                                "output replace an input file.", Flag())
    root: str = fields.root("inplace", "inplace (walks on the spot, facing kept) or motion (moves on).")
    frame_range: str | None = option(None, "Use frames START:STOP of the take.", _range_text, flag="--range")
    step: int = option(1, "Find the phase on every STEP-th frame (faster on long takes).", Integer(1))
    cycles: int = fields.cycles(1, "Repeat the cycle this many times in the output.")
    time_axis: str = option("smooth", "Phase to time: smooth (default), rank (thesis eq. 3.20), gmm (eq. 3.21) "
                                      "or line.", Choice(TIME_AXES), flag="--time")


#: A loop's cycle more than this share off the stride period (the landings of each foot) is not written.
STRIDE_AGREEMENT = 0.06
#: A loop's turn per cycle more than max(TURN_SLACK_DEG, TURN_SLACK_SHARE x the take's) off the take's is not written.
TURN_SLACK_DEG, TURN_SLACK_SHARE = 10.0, 0.25


def run(take, options: Options | None = None) -> Report:
    """Cut the take into steady activities (:func:`~mocycle.activities.segment_activities`) and loop them.

    ``motions["loop"]`` is the chosen part's cycle repeated ``cycles`` times with the chosen root; with
    ``which="all"`` every part that loops gets ``motions["loop.part<k>"]`` (``k``: the part's index in
    ``facts["parts"]``).  ``facts``: ``status``, ``reason`` (plain words), ``loops`` (each loop's figures:
    ``part``, ``kind``, ``frames``, period, speed, turn per cycle, metrics, checks, feet), ``not_looped`` (the
    parts that were not, each with its reason), ``parts`` (every part of the take) and, at the top level, the
    figures of the first loop (what ``loop`` printed before parts existed).
    Raises :class:`~mocycle.errors.NoPeriodicMotion` when no part of the take repeats and
    :class:`~mocycle.errors.LoopRefused` when every cycle made fails a loop check (``force``: a warning
    instead); both carry ``facts`` with the same shape (``status`` ``no-periodic-motion`` or ``refused``).
    """
    from ..activities import segment_activities

    o = options or Options()
    everything = o.which == "all"
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        start, stop = parse_range(o.frame_range, motion.n_frames)
        motion = motion[start:stop]
        label = label_of(take)
        with rec.part("cycle"):
            acts = segment_activities(motion, min_periods=o.min_periods) if o.joints is None and o.step == 1 \
                else None
        parts = acts.parts if acts is not None else []
        plan = _plan(acts)
        whole = plan != "parts"
        if isinstance(o.which, int) and not whole and o.which >= len(parts):
            raise OptionError("which", f"the take has {len(parts)} part(s) (0 to {len(parts) - 1}); got {o.which}")
        jobs = _jobs(motion, acts, plan, o, rec, start)
        loops, not_looped, motions, cycles, extras, refusals = [], [], {}, [], {}, []
        for index, piece, offset, phase, k, part in jobs:
            try:
                facts, result, extra, cycle = _loop_one(piece, phase, k, o, label, offset, part, rec)
            except NoPeriodicMotion as exc:
                if whole:
                    raise _no_loop(exc, acts, start) from None
                not_looped.append({"part": index, "kind": part.kind,
                                   "frames": [start + part.start, start + part.stop], "reason": str(exc)})
                continue
            except LoopRefused as exc:
                refusals.append(exc)
                if part is not None:
                    not_looped.append({"part": index, "kind": part.kind,
                                       "frames": [start + part.start, start + part.stop], "reason": f"refused: {exc}"})
                continue
            facts["part"] = index
            facts["frames"] = [f + start for f in facts["frames"]]
            facts["excitation"] = [[a + start, b + start] for a, b in facts["excitation"]]
            role = _role(index, k, everything)
            facts["role"] = role
            loops.append(facts)
            motions[role] = result
            extras[role] = extra
            cycles.append(cycle)
            if not everything:
                break
        for k, p in enumerate(parts if plan != "whole" else []):  # looped whole: the parts are only shown
            if not p.loop:
                not_looped.append({"part": k, "kind": p.kind, "frames": [start + p.start, start + p.stop],
                                   "reason": p.reason})
        not_looped.sort(key=lambda d: (d["frames"] or [0])[0])
        if not loops:
            if refusals:
                exc = refusals[0] if len(refusals) == 1 else \
                    LoopRefused("; ".join(map(str, refusals)), [f for r in refusals for f in r.failed])
                exc.facts = _facts("refused", str(exc), [], not_looped, acts, start)
                raise exc
            reason = nothing_to_loop(acts)
            exc = NoPeriodicMotion(reason)
            exc.facts = _facts("no-periodic-motion", reason, [], not_looped, acts, start)
            raise exc
    motions["input"] = motion
    facts = _facts("ok", _chosen_reason(loops, parts, everything), loops, not_looped, acts, start)
    return rec.report("loop", facts, motions, cycles if everything else cycles[0], extras)


#: every :func:`output_tag` of a loop with ``--part all``, as a regular expression (batch claims those names
#: before any take has run, when the parts are not known yet)
TAG_PATTERN = r"class\d+|part\d+-[a-z-]+"


def output_tag(facts) -> str | None:
    """What a loop's output name adds before its suffix (``OUT.<tag>.bvh``), from its figures: ``None`` for the
    one loop (``role`` ``loop``), ``part1-walk-turning-left`` for a part, ``class0`` for a periodic motion of
    a take looped whole.  The CLI and batch name files by it."""
    role = facts.get("role", "loop")
    if role == "loop":
        return None
    tag = role.split(".", 1)[1]
    return f"{tag}-{facts['kind'].replace(' ', '-')}" if tag.startswith("part") else tag


def output_path(target, facts):
    """``target`` (a ``pathlib.Path``) with :func:`output_tag` of a loop's figures before its suffix."""
    tag = output_tag(facts)
    return target if tag is None else target.with_suffix(f".{tag}{target.suffix}")


def _role(index, k, everything) -> str:
    if not everything:
        return "loop"
    return f"loop.part{index}" if index is not None else f"loop.class{k or 0}"


def _jobs(motion, acts, plan: str, o: Options, rec, start: int) -> list[tuple]:
    """What to loop, in order: ``(part index or None, motion to loop, its first frame in the take, PhaseResult,
    class index or None, Activity or None)`` for each try (``plan``: :func:`_plan`)."""
    from ..cycle import cycle_phase

    parts = acts.parts if acts is not None else []
    loopable = [k for k, p in enumerate(parts) if p.loop]
    everything = o.which == "all"
    jobs = []
    if plan != "parts":
        part = parts[loopable[0]] if plan == "single" else None
        with rec.part("cycle"):
            try:
                phase = cycle_phase(motion, step=o.step, joints=o.joints, classes=o.classes, pca=o.pca,
                                    delay=o.delay, min_periods=o.min_periods)
            except NoPeriodicMotion as exc:
                if part is None:
                    raise _no_loop(exc, acts, start) from None
                phase = None  # a take of little more than a stride: its strides' phase decides
        if part is not None and (phase is None or not phase.classes):
            jobs.append((loopable[0], motion[part.start:part.stop], part.start, _part_phase(part), None, part))
        elif part is not None and not isinstance(o.which, int) and _off_strides(phase, part):
            # the cohomology's period disagrees with the landings: the part's stride phase decides
            jobs.append((loopable[0], motion[part.start:part.stop], part.start, _part_phase(part, phase), None,
                         part))
        elif part is not None:
            jobs.append((loopable[0], motion, 0, phase, o.which if isinstance(o.which, int) else None, part))
        else:
            ks = list(range(len(phase.classes))) or [None] if everything else \
                [o.which if isinstance(o.which, int) else None]
            jobs.extend((None, motion, 0, phase, k, None) for k in ks)
    else:
        if isinstance(o.which, int):
            chosen = [o.which] if parts[o.which].loop else []
        else:
            # all: in frame order; by default the part with the most cycles first, the next ones only if it
            # is refused
            chosen = loopable if everything else sorted(loopable, key=lambda k: -parts[k].n_periods)
        for k in chosen:
            p = parts[k]
            jobs.append((k, motion[p.start:p.stop], p.start, _part_phase(p), None, p))
    return jobs


def _plan(acts) -> str:
    """How the take is looped: ``"parts"`` (each steady part on its own), ``"single"`` (it does one thing: one
    gait part to loop, the rest under a tenth of its frames; looped whole, its phase found on all of it and
    checked against the strides) or ``"whole"`` (as before parts existed: the rig's feet were not found, or
    the parts do not account for the take (the legs move where no foot lands in a gait: contacts were
    missed, and the cohomology of the whole take, which finds several periodic motions and their regions,
    has the last word), or nothing in it loops)."""
    if acts is None or not acts.feet:
        return "whole"
    loopable = acts.loopable()
    if not loopable or any(not p.gait and not p.legs_still for p in acts.parts):
        return "whole"
    rest = acts.n_frames - sum(p.n_frames for p in loopable)
    return "single" if len(loopable) == 1 and loopable[0].gait and rest < 0.1 * acts.n_frames else "parts"


def _off_strides(phase, part) -> bool:
    """Whether the main periodic motion found on the whole take is more than :data:`STRIDE_AGREEMENT` off
    the stride period of the take's one gait part."""
    from ..cycle.extract import choose_periodic

    period = choose_periodic(phase).period_frames
    return part.periodic is not None and abs(period / part.period_frames - 1) > STRIDE_AGREEMENT


def _no_loop(exc, acts, offset):
    """``exc`` (nothing periodic found on the whole take) in plain words, with the technical why in the JSON."""
    reason = nothing_to_loop(acts) if acts is not None and acts.parts else "no repeating motion found in the take"
    out = NoPeriodicMotion(reason)
    out.facts = _facts("no-periodic-motion", reason, [], [], acts, offset)
    out.facts["detail"] = str(exc)
    return out


def _part_phase(part, found=None):
    """The PhaseResult of one part's frames: its stride phase (gait) or the phase found on its limbs;
    ``found``: the phase found on the whole take whose period the strides overrule (named in the reason)."""
    from dataclasses import replace

    import numpy as np

    from ..cycle.extract import choose_periodic
    from ..phase.analysis import PhaseResult

    pm = part.periodic
    if found is not None:
        other = choose_periodic(found)
        pm = replace(pm, period_candidates={**other.period_candidates, "strides": pm.period_frames},
                     period_reason=(f"the strides: the {other.period_source}'s period on the whole take "
                                    f"({other.period_frames:.2f} frames) is more than {STRIDE_AGREEMENT:.0%} off "
                                    f"the landings' ({pm.period_frames:.2f})"))
    return PhaseResult(classes=[pm], barcode=np.zeros((0, 2)), reason=pm.period_reason,
                       autocorrelation_period_frames=float("nan"), n_frames=part.n_frames,
                       frame_time=pm.frame_time, joints_used=pm.joints_used)


def nothing_to_loop(acts) -> str:
    """Why nothing in the take loops, in plain words (the technical why goes in the JSON's ``detail``)."""
    if acts is None or not acts.parts:
        return "no repeating motion found in the take"
    kinds = {p.kind for p in acts.parts}
    if kinds == {"standing"}:
        return "no repeating motion: the actor stands still"
    gait = [p for p in acts.parts if p.gait or p.landings]
    if gait and not any(p.loop for p in acts.parts):
        longest = max(gait, key=lambda p: p.n_periods if p.n_periods == p.n_periods else 0.0)
        return (f"no steady part repeats long enough to loop: the longest ({longest.kind or 'steps'}, frames "
                f"{longest.start}-{longest.stop}) holds {longest.n_periods:.1f} strides")
    if kinds <= {"gesture", "standing", "transition"}:
        return "no repeating motion: the take does one gesture, it does not repeat"
    return "no repeating motion found: the body moves, but nothing in it repeats"


def _chosen_reason(loops, parts, everything) -> str:
    if everything or not parts:
        return f"{len(loops)} loop(s)"
    f = loops[0]
    if f["part"] is None:
        return "the take does one thing: it is looped as a whole"
    others = sum(1 for p in parts if p.loop) - 1
    return (f"looped part {f['part']} ({f['kind']}, frames {f['frames'][0]}-{f['frames'][1]}): the steady part with "
            f"the most cycles" + (f"; {others} other part(s) can loop too (--part all writes every one)"
                                  if others > 0 else ""))


def _facts(status, reason, loops, not_looped, acts, offset) -> dict:
    parts = []
    for p in acts.parts if acts is not None else []:
        d = p.to_dict()
        d["frames"] = [d["frames"][0] + offset, d["frames"][1] + offset]
        d["landings"] = {k: [f + offset for f in v] for k, v in d["landings"].items()}
        parts.append(d)
    first = dict(loops[0]) if loops else {}
    return {**first, "status": status, "reason": reason, "loops": loops, "not_looped": not_looped,
            "parts": parts, "first_frame": int(offset)}


def _loop_one(motion, phase, k, o, label, offset, part, rec):
    """One loop: the cycle of ``motion`` (a part of the take starting at take frame ``offset``), its metrics,
    checks and feet.  Returns ``(facts, repeated cycle, extras, cycle)``; raises LoopRefused."""
    from ..cycle import extract_cycle, loop_metrics
    from ..cycle.checks import check_loop
    from .feet import clean_feet

    with rec.part("cycle"):
        fitted = extract_cycle(motion, method=o.method, model=o.model, harmonics=o.harmonics,
                               time_axis=o.time_axis, which=k, phase=phase)
    with rec.part("metrics"):
        # the metrics and checks judge the fitted cycle against the take (locking changes the legs on
        # purpose); the feet block says what locking did
        travelling = fitted.repeat(2, root="motion")
        metrics = loop_metrics(motion, fitted, travelling)
        name = f"{label} part {part.kind}" if part is not None and offset else label
        extra_checks = _activity_checks(motion, fitted, part, offset)
        failed = check_loop(motion, fitted, metrics, force=o.force, label=name, extra=extra_checks)
    with rec.part("feet"):
        frames = fitted.axis.frames()   # the swing clearance of the looped region of the take
        # the fitted cycle's skate is the metrics' when the feet are the ones found by name
        cycle, feet_facts, contacts = clean_feet(fitted, o.feet, o.root, o.foot_joints,
                                                 reference=motion[frames[0]:frames[-1] + 1],
                                                 before=travelling,
                                                 skate_before=None if o.foot_joints else metrics["skate"])
    with rec.part("cycle"):
        result = cycle.repeat(o.cycles, root=o.root)
    index = next(i for i, c in enumerate(phase.classes) if c is cycle.periodic)
    regions = [[int(s) + offset, int(e) + offset] for s, e in cycle.axis.regions]
    looped = [regions[0][0], regions[-1][1]]
    facts = {
        "class": index,
        "kind": part.kind if part is not None else "periodic",
        "frames": looped,
        "frames_in": motion.n_frames,
        "frames_out": result.n_frames,
        "fps": motion.fps,
        **cycle.to_dict(),
        "speed": _speed(cycle),
        "excitation": regions,
        "model": o.model if o.method == "harmonic" else None,
        "root": o.root,
        "cycles": o.cycles,
        "metrics": metrics,
        "failed_checks": [f.to_dict() for f in failed],
        "feet": feet_facts,
        "excited_regions": len(cycle.periodic.excitation),
    }
    return facts, result, {"fitted": fitted, "contacts": contacts, "offset": offset}, cycle


def _speed(cycle) -> float:
    """Units per second of the loop's travel (horizontal distance per cycle over the cycle's time)."""
    import numpy as np

    move = np.asarray(cycle.to_dict()["travel_per_cycle"], dtype=np.float64)
    up = np.asarray(cycle.space.world_up, dtype=np.float64)
    flat = move - (move @ up) * up
    return float(np.linalg.norm(flat) / (cycle.period_frames * cycle.space.frame_time))


def _activity_checks(motion, cycle, part, offset) -> list:
    """The checks a loop of a part must pass beside :func:`~mocycle.cycle.checks.loop_checks`: its cycle
    agrees with the stride period of the landings in the frames it loops, and it turns as the take does
    there (the hips' heading)."""
    import numpy as np

    from ..activities import find_landings, heading_degrees, stride_reference
    from ..cycle.checks import FailedCheck

    failed = []
    s, e = cycle.axis.regions[0][0], cycle.axis.regions[-1][1]
    landings = find_landings(motion)
    if landings is not None:
        stride, count = stride_reference(motion, landings, s, e)
        # one stride measured from contacts that come and go (a gliding foot) is no ruler; a gait part's
        # strides are (its phase was made from them)
        enough = count >= 2 if part is None or not part.gait else count >= 1
        if enough and (part is None or part.gait):
            off = cycle.period_frames / stride - 1.0
            if abs(off) > STRIDE_AGREEMENT:
                failed.append(FailedCheck(
                    "stride", float(abs(off)), STRIDE_AGREEMENT,
                    f"the cycle ({cycle.period_frames:.1f} frames) is {abs(off):.0%} off the strides (each foot "
                    f"lands every {stride:.1f} frames here, the legs repeating)"))
    # the hips' heading over the frames looped, read two ways a ruler might: a line through it, and its change
    # between the ends (a tenth of a period each) over the periods between; the loop must agree with one
    heading = heading_degrees(motion)[s:e]
    P = cycle.period_frames
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
