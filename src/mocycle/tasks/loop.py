"""``loop``: one seamless typical cycle of a take (paper 001 harmonic regression, centroid or cut)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import OptionError
from . import fields
from .options import Choice, Flag, Integer, option
from .options import Options as _Options
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

TIME_AXES = ("smooth", "rank", "gmm", "line")


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
class Options(_Options):
    """Options of ``loop``."""

    method: str = fields.method("harmonic (regression), centroid (paper 001) or cut (baseline).")
    model: str = fields.model("Harmonic model: M1 (FGLS-weighted positions, velocities, accelerations), M2 "
                              "(positions only; velocity/acceleration off), M3 (unweighted).")
    harmonics: int | str = fields.harmonics()
    root: str = fields.root("inplace", "inplace (walks on the spot, facing kept) or motion (moves on).")
    frame_range: str | None = option(None, "Use frames START:STOP of the take.", _range_text, flag="--range")
    step: int = option(1, "Find the phase on every STEP-th frame (faster on long takes).", Integer(1))
    joints: str | None = fields.phase_joints()
    cycles: int = fields.cycles(1, "Repeat the cycle this many times in the output.")
    classes: int | str = fields.classes()
    which: int | str | None = fields.which("Which periodic motion to loop (0-based; default: the one covering most "
                                           "frames), or 'all': one file per periodic motion, OUT.class0.bvh, "
                                           "OUT.class1.bvh, ...", words=("all",))
    pca: int | str | None = fields.pca()
    delay: int = fields.delay()
    min_periods: float = fields.min_periods()
    time_axis: str = option("smooth", "Phase to time: smooth (default), rank (thesis eq. 3.20), gmm (eq. 3.21) "
                                      "or line.", Choice(TIME_AXES), flag="--time")
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()
    force: bool = option(False, "Write the cycle even when it fails a loop check (longer than the take, fits much "
                                "worse than a plain cut, seam jumps); a warning names the check. It also lets an "
                                "output replace an input file.", Flag())
    feet: str = fields.feet()
    foot_joints: str | None = fields.foot_joints()


def run(take, options: Options | None = None) -> Report:
    """Extract one seamless cycle; ``motions["loop"]`` is it repeated ``cycles`` times with the chosen root.

    With ``which="all"``: one loop per periodic motion, ``motions["loop.class<k>"]``, and ``facts["loops"]``
    holds the figures of each (every cycle is made and checked before the report is returned).
    Raises :class:`~mocycle.errors.NoPeriodicMotion` when the take holds no periodic motion and
    :class:`~mocycle.errors.LoopRefused` when a cycle fails a loop check (``force``: a warning instead).
    """
    from ..cycle import cycle_phase, extract_cycle, loop_metrics
    from ..cycle.checks import check_loop
    from .feet import clean_feet

    o = options or Options()
    everything = o.which == "all"
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        start, stop = parse_range(o.frame_range, motion.n_frames)
        motion = motion[start:stop]
        with rec.part("cycle"):
            phase = cycle_phase(motion, phase_step=o.step, joints=o.joints, classes=o.classes, pca=o.pca,
                                delay=o.delay, min_periods=o.min_periods)
        targets = list(range(len(phase.classes))) if everything else [o.which]
        if everything and not targets:
            targets = [None]  # extract_cycle says why there is nothing to loop
        loops, motions, cycles, extras = [], {}, [], {}
        for k in targets:
            with rec.part("cycle"):
                fitted = extract_cycle(motion, method=o.method, model=o.model, n_harmonics=o.harmonics,
                                       time_axis_method=o.time_axis, which=k, phase=phase)
            with rec.part("metrics"):
                # the metrics and checks judge the fitted cycle against the take (locking changes the legs on
                # purpose); the feet block says what locking did
                travelling = fitted.repeat(2, root="motion")
                metrics = loop_metrics(motion, fitted, travelling)
                label = f"{label_of(take)} class {k}" if everything else label_of(take)
                failed = check_loop(motion, fitted, metrics, force=o.force, label=label)
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
            loops.append({
                "class": index,
                "frames_in": motion.n_frames,
                "frames_out": result.n_frames,
                "fps": motion.fps,
                **cycle.to_dict(),
                "excitation": [[int(s), int(e)] for s, e in cycle.axis.regions],
                "model": o.model if o.method == "harmonic" else None,
                "root": o.root,
                "cycles": o.cycles,
                "metrics": metrics,
                "failed_checks": [f.to_dict() for f in failed],
                "feet": feet_facts,
                "excited_regions": len(cycle.periodic.excitation),
            })
            role = f"loop.class{index}" if everything else "loop"
            motions[role] = result
            extras[role] = {"fitted": fitted, "contacts": contacts}
            cycles.append(cycle)
    motions["input"] = motion
    facts = {"loops": loops} if everything else loops[0]
    return rec.report("loop", facts, motions, cycles if everything else cycles[0], extras)
