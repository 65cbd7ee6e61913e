"""What ``mocycle batch`` does per command: the output it writes for a take and the figures a results row
shows (a few of the task report's ``facts``; the whole facts go to ``results.json``)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from ..errors import MocycleError

__all__ = ["COMMANDS", "Command", "check_suffix"]

#: the suffixes ``mocycle.write`` writes that do not hold a motion (every other one it writes does)
_NOT_MOTION = (".mck", ".mosw", ".json")


@dataclass(frozen=True)
class Command:
    """A task as batch runs it.

    name : the task (``mocycle.tasks.<name>``).
    writes : what goes to ``OUTDIR/<rel><suffix>``: ``"motion"`` (the report's motions), ``"compressed"``
        (the ``.mck`` take), ``"swings"`` (the segmentation) or ``None`` (the per-take JSON record only).
    suffix : the default output suffix.
    figures : results column -> how to read it from the report's facts.
    imports : the modules the task imports when it runs (its algorithm package, the scipy parts it loads in
        its functions): a LocalCluster's workers get them preloaded (:mod:`.forkserver`), so they are imported
        once per batch, not once per worker at its first take. Only a matter of speed: a module missing here
        is imported by the first take (``tests/batch/test_commands.py`` checks that none is).
    """

    name: str
    writes: str | None
    suffix: str | None
    figures: Mapping[str, Callable[[Mapping], object]]
    imports: tuple[str, ...] = ()

    def suffixes(self) -> tuple[str, ...]:
        """The output suffixes this command can write (asked of ``mocycle.io`` at run time, so a new motion
        format of ``mocycle.write`` is one for batch too)."""
        from ..io import WRITE_SUFFIXES

        if self.writes == "motion":
            return tuple(s for s in WRITE_SUFFIXES if s not in _NOT_MOTION)
        if self.writes == "swings":
            return (".mosw", ".json")
        if self.writes == "compressed":
            return (".mck",)
        return ()


def check_suffix(command: Command, suffix: str | None) -> str | None:
    """The output suffix for ``command`` (``None`` when it writes only its record); one clear error when
    ``suffix`` is not one it writes."""
    if suffix is None:
        return command.suffix
    suffix = suffix.lower() if suffix.startswith(".") else "." + suffix.lower()
    allowed = command.suffixes()
    if not allowed:
        raise MocycleError(f"--suffix: batch {command.name} writes no file but its record (<take>.{command.name}"
                           f".json); leave --suffix out")
    if suffix not in allowed:
        raise MocycleError(f"--suffix: batch {command.name} writes {' or '.join(allowed)}; got {suffix}")
    return suffix


def _first_class(facts: Mapping, key: str):
    classes = facts.get("classes") or []
    return classes[0][key] if classes else None


def _loop(facts: Mapping) -> Mapping:
    """The first loop's facts (a loop report lists its loops, one per part with ``--part all``)."""
    return facts["loops"][0] if "loops" in facts else facts


def _skate(facts: Mapping):
    """Foot skate of the cycle written, units/s: after locking when the feet were locked, else as fitted."""
    f = _loop(facts)
    locked = f["feet"].get("skate_after") if isinstance(f.get("feet"), Mapping) else None
    return locked if locked is not None else f["metrics"]["skate"]


COMMANDS: dict[str, Command] = {c.name: c for c in (
    Command("info", None, None, {
        "frames": lambda f: f["frames"], "fps": lambda f: f["fps"], "duration_s": lambda f: f["duration_s"],
        "joints": lambda f: f["joints"], "root_displacement": lambda f: f["root_displacement"]},
        imports=("mocycle.tasks.info", "mocycle.io.bvh")),
    Command("phase", None, None, {
        "frames": lambda f: f["frames"], "fps": lambda f: f["fps"], "classes": lambda f: len(f["classes"]),
        "period_frames": lambda f: _first_class(f, "period_frames"),
        "periods": lambda f: _first_class(f, "n_periods"),
        "autocorrelation_period_frames": lambda f: f["autocorrelation_period_frames"]},
        imports=("mocycle.tasks.phase", "mocycle.phase", "pyRipser")),
    Command("loop", "motion", ".bvh", {
        "part": lambda f: _loop(f)["part"], "kind": lambda f: _loop(f)["kind"],
        "frames": lambda f: "{}-{}".format(*_loop(f)["frames"]),
        "turn_per_cycle_deg": lambda f: _loop(f)["turn_per_cycle_deg"],
        "period_frames": lambda f: _loop(f)["period_frames"], "periods": lambda f: _loop(f)["n_periods"],
        "cycle_frames": lambda f: _loop(f)["cycle_frames"],
        "seam_pose": lambda f: _loop(f)["metrics"]["seam_pose"],
        "seam_velocity": lambda f: _loop(f)["metrics"]["seam_velocity"],
        "foot_skate": _skate},
        imports=("mocycle.tasks.loop", "mocycle.activities", "mocycle.phase", "pyRipser", "mocycle.cycle",
                 "mocycle.cycle.checks",
                 "mocycle.tasks.feet", "mocycle.contacts")),
    Command("swings", "swings", ".mosw", {
        "frames": lambda f: f["frames"], "swings": lambda f: f["n_swings"],
        "per_angle_error_deg": lambda f: f["per_angle_error_deg"], "compressed_bytes": lambda f: f["compressed_bytes"],
        "ratio_bvh": lambda f: f["ratio_bvh"]},
        imports=("mocycle.tasks.swings", "mocycle.swings", "mocycle.io.mosw", "scipy.optimize", "scipy.ndimage")),
    Command("compress", "compressed", ".mck", {
        "frames": lambda f: f["frames"], "keyframes": lambda f: f["keyframes"],
        "keys_per_period": lambda f: f["keys_per_period"],
        "error_per_frame_per_joint": lambda f: f["error_per_frame_per_joint"],
        "compressed_bytes": lambda f: f["compressed_bytes"], "real_ratio": lambda f: f["real_ratio"]},
        imports=("mocycle.tasks.compress", "mocycle.keyframes", "mocycle.phase", "pyRipser", "mocycle.io.mck",
                 "scipy.optimize")),
    Command("stretch", "motion", ".bvh", {
        "factor": lambda f: f["factor"], "frames_in": lambda f: f["frames_in"], "frames_out": lambda f: f["frames_out"],
        "periodic_regions": lambda f: len(f["periodic_regions"])},
        imports=("mocycle.tasks.stretch", "mocycle.warp", "mocycle.phase", "pyRipser", "mocycle.cycle",
                 "mocycle.tasks.feet", "mocycle.contacts", "scipy.ndimage")),
)}


def motion_targets(report, target: Path) -> dict[str, Path]:
    """The motions a report holds that batch writes, by role, and where: ``loop`` -> ``target``; with
    ``--part all`` each loop's file as ``mocycle loop`` names it (``<target stem>.part1-walk-turning-left<suffix>``,
    ``.class<K>`` for a take looped whole: :func:`mocycle.tasks.loop.output_path`); ``stretched`` -> ``target``."""
    if "stretched" in report.motions:
        return {"stretched": target}
    from ..tasks.loop import output_path

    return {f["role"]: output_path(target, f) for f in report.facts.get("loops", []) if f.get("role") in report.motions}


def part_rows(command: Command, facts: Mapping) -> list[dict]:
    """One set of figures per loop of a ``loop`` report (a take cut into parts gets a results row per part)."""
    return [_part_figures(command, {**facts, "loops": [loop]}) for loop in facts.get("loops") or []]


def _part_figures(command: Command, facts: Mapping) -> dict:
    out = {}
    for name, get in command.figures.items():
        try:
            out[name] = get(facts)
        except (KeyError, IndexError, TypeError):
            out[name] = None
    return out
