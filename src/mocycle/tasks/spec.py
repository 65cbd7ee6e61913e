"""One declaration per task: what every front end needs to offer it.

A :class:`Spec` names a task's inputs, its ``Options`` (the task module's, with the library's own parameter
names), the files it writes (:class:`Output`: role, suffixes, naming, closing frame), and the figures of its
results row. The CLI command (:func:`mocycle.cli.common.task_command`), the batch command
(:mod:`mocycle.batch.commands`), the studio's forms (``/api/options``) and the Blender operators are made from
it; a front end keeps only what is its own (``--json``, plots, where the output goes).

This module is light: it imports no task module (``mocycle --help`` lists the commands from :data:`SPECS`);
:attr:`Spec.options` imports the task's module when first asked for.

    >>> SPECS["loop"].outputs[0].suffixes
    ('.bvh', '.glb')
    >>> SPECS["loop"].options.__name__
    'Options'
"""

from __future__ import annotations

import importlib
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ..suffixes import MOTION_WRITE_SUFFIXES
from .words import written_skate

__all__ = ["SPECS", "Output", "Spec", "row_figures"]


@dataclass(frozen=True)
class Output:
    """One file a task writes.

    role : where the written thing is in the report: a key of ``report.motions`` (``"loop"``, ``"stretched"``),
        or ``"result"`` for ``report.result`` (a compressed take, a segmentation).
    writes : ``"motion"``, ``"compressed"`` (``.mck``) or ``"swings"`` (``.mosw`` / ``.json``).
    suffixes : the suffixes it may have; the first is the default (batch's ``--suffix``).
    flag, help : its CLI option (the CLI's ``-o`` is ``--output``).
    required : the CLI asks for it; else it is written only when named.
    loop : the motion is a seamless loop: glTF gets the closing frame unless told otherwise, and with
        ``--part all`` each loop of the report goes to its own file (:func:`mocycle.tasks.loop.output_path`).
    """

    role: str
    writes: str
    suffixes: tuple[str, ...]
    flag: str = "--output"
    help: str = ""
    required: bool = True
    loop: bool = False

    def every_target(self, path: Path, options) -> re.Pattern | None:
        """For a loop with ``--part all`` (``options.which == "all"``), the names its files may have beside
        ``path`` (``OUT.part<k>-<kind>.bvh``, ``OUT.class<k>.bvh``: :data:`mocycle.tasks.loop.TAG_PATTERN`),
        as one pattern on the normalised path; ``None`` when the output is the one file ``path``."""
        if not (self.loop and getattr(options, "which", None) == "all"):
            return None
        from .loop import TAG_PATTERN

        stem = os.path.normcase(str(path.with_suffix("")))
        return re.compile(re.escape(stem) + rf"\.({TAG_PATTERN})" + re.escape(os.path.normcase(path.suffix)) + r"\Z")

    def targets(self, report, path: Path) -> dict[str, Path]:
        """The report's things this output writes, by role, and where: ``{role: path}``; for a loop, one file
        per loop of the report (``OUT.part1-walk-turning-left.bvh``, ...)."""
        if self.loop and "loops" in report.facts:
            from .loop import output_path

            return {f["role"]: output_path(path, f) for f in report.facts["loops"] if f.get("role") in report.motions}
        return {self.role: path}


@dataclass(frozen=True)
class Spec:
    """What a task is to every front end.

    name : the task (``mocycle.tasks.<name>``) and its command (``mocycle <name>``).
    summary : one line: the first paragraph of its help everywhere.
    inputs : the CLI arguments that name its input files, in order (a ``*`` in front: one or more).
    outputs : the files it writes (:class:`Output`), the first one is the batch output.
    figures : results-row column -> how to read it from the report's facts (batch; ``None`` when missing).
    imports : the modules it imports when it runs (batch preloads them in its workers).
    batch : ``mocycle batch`` runs it (it takes one file).
    studio : the fields of its ``Options`` the studio's forms show (the others keep their defaults).
    cli : it is a ``mocycle`` command; ``command_module``: the module of ``mocycle.cli`` that defines it (its
        typer command is made from this spec there), default the task's name.
    facts : the keys every report of the task has in ``facts`` (its shape; ``tests/tasks/test_spec.py``
        runs each task and checks), and ``optional_facts`` the few it adds only when asked (the optimised
        projection, the takes of a glTF or FBX file).
    """

    name: str
    summary: str
    inputs: tuple[str, ...] = ("path",)
    outputs: tuple[Output, ...] = ()
    figures: Mapping[str, Callable[[Mapping], object]] = field(default_factory=dict)
    imports: tuple[str, ...] = ()
    batch: bool = False
    studio: tuple[str, ...] = ()
    cli: bool = True
    command_module: str = ""
    facts: tuple[str, ...] = ()
    optional_facts: tuple[str, ...] = ()

    @property
    def module(self):
        """The task's module (``run``, ``Options``), imported on first use."""
        return importlib.import_module(f"{__package__}.{self.name}")

    @property
    def options(self) -> type:
        """The task's ``Options`` class: its fields are the options of every front end."""
        return self.module.Options

    @property
    def cli_module(self) -> str:
        """The module of ``mocycle.cli`` that defines the command."""
        return self.command_module or self.name

    def writes_motion(self) -> bool:
        return any(o.writes == "motion" for o in self.outputs)


def row_figures(spec: Spec, facts: Mapping) -> dict:
    """The results-row figures of a report's facts (``None`` for one a report does not hold)."""
    out = {}
    for name, get in spec.figures.items():
        try:
            out[name] = get(facts)
        except (KeyError, IndexError, TypeError):
            out[name] = None
    return out


def _first_class(facts: Mapping, key: str):
    classes = facts.get("classes") or []
    return classes[0][key] if classes else None


def _loop(facts: Mapping) -> Mapping:
    """The first loop's facts (a loop report lists its loops, one per part with ``--part all``)."""
    return facts["loops"][0] if "loops" in facts else facts


def _skate(facts: Mapping):
    """Foot skate of the cycle written, units/s (:func:`~mocycle.tasks.words.written_skate`)."""
    f = _loop(facts)
    return written_skate(f.get("feet"), f["metrics"])


def _motion(role: str, help: str, **kwargs) -> Output:
    return Output(role, "motion", MOTION_WRITE_SUFFIXES, help=help, **kwargs)


SPECS: dict[str, Spec] = {s.name: s for s in (
    Spec("info", "Frames, frame time, fps, duration, joints, channels, root travel and rotation ranges.",
         figures={"frames": lambda f: f["frames"], "fps": lambda f: f["fps"], "duration_s": lambda f: f["duration_s"],
                  "joints": lambda f: f["joints"], "root_displacement": lambda f: f["root_displacement"]},
         imports=("mocycle.tasks.info", "mocycle.io.bvh"), batch=True,
         facts=("channels", "duration_s", "end_sites", "fps", "frame_time", "frames", "joints", "root_displacement",
                "root_end", "root_path_length", "root_start", "rotation_range_deg", "rotation_spread_deg",
                "travel_joint"),
         optional_facts=("takes", "take")),
    Spec("phase", "Find the steady parts of a take and the periodic motion and phase of each part that repeats.",
         figures={"frames": lambda f: f["frames"], "fps": lambda f: f["fps"], "classes": lambda f: len(f["classes"]),
                  "period_frames": lambda f: _first_class(f, "period_frames"),
                  "periods": lambda f: _first_class(f, "n_periods"), "parts": lambda f: len(f["parts"])},
         imports=("mocycle.tasks.phase", "mocycle.activities", "mocycle.phase", "pyRipser"), batch=True,
         facts=("autocorrelation_period_frames", "classes", "fps", "frames", "joints_used", "legs_period_frames",
                "parts", "reason")),
    Spec("loop", "Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH or glTF.",
         outputs=(_motion("loop", "The cycle as a .bvh or .glb file.", loop=True),),
         figures={"part": lambda f: _loop(f)["part"], "kind": lambda f: _loop(f)["kind"],
                  "frames": lambda f: "{}-{}".format(*_loop(f)["frames"]),
                  "turn_per_cycle_deg": lambda f: _loop(f)["turn_per_cycle_deg"],
                  "period_frames": lambda f: _loop(f)["period_frames"], "periods": lambda f: _loop(f)["n_periods"],
                  "cycle_frames": lambda f: _loop(f)["cycle_frames"],
                  "seam_pose": lambda f: _loop(f)["metrics"]["seam_pose"],
                  "seam_velocity": lambda f: _loop(f)["metrics"]["seam_velocity"], "foot_skate": _skate},
         imports=("mocycle.tasks.loop", "mocycle.activities", "mocycle.phase", "pyRipser", "mocycle.cycle",
                  "mocycle.cycle.parts", "mocycle.cycle.checks", "mocycle.tasks.feet_option", "mocycle.contacts"),
         batch=True, studio=("method", "model", "root", "feet", "cycles"),
         facts=("cycle_frames", "cycles", "excitation", "excited_regions", "failed_checks", "feet",
                "first_frame", "fps", "frames", "frames_in", "frames_out", "half_cycle_doubled", "harmonics",
                "joints_used", "kind", "legs_period_frames", "loops", "method", "metrics", "model", "n_periods",
                "not_looped", "part", "parts", "period_candidates", "period_frames", "period_reason",
                "period_source", "reason", "role", "root", "speed", "status", "time_axis", "travel_per_cycle",
                "turn_per_cycle_deg")),
    Spec("blend", "Blend the cycles of several takes into one new loop (paper 001 §4.5: a convex combination).",
         inputs=("*paths",), outputs=(_motion("loop", "The blended loop as a .bvh or .glb file.", loop=True),),
         facts=("cycle_frames", "cycles", "feet", "frames_out", "heading_offsets_deg", "input_periods_frames",
                "input_seams", "period_frames", "phase_offsets", "root", "seam", "start_phase", "travel_per_cycle",
                "turn_per_cycle_deg", "weights")),
    Spec("transition", "A motion that starts as the first take's cycle and ends as the second's (paper 001 §4.5, "
                       "a homotopy).",
         inputs=("first", "second"), command_module="blend",
         outputs=(_motion("transition", "The transition as a .bvh or .glb file."),),
         facts=("cycles", "feet", "frames", "input_periods_frames", "period_frames_end", "period_frames_start",
                "phase_offset", "root", "smoothness")),
    Spec("stretch", "Lengthen a take by time-frequency warping: its cycles are replicated, not slowed down.",
         outputs=(_motion("stretched", "The .bvh or .glb file to write."),),
         figures={"factor": lambda f: f["factor"], "frames_in": lambda f: f["frames_in"],
                  "frames_out": lambda f: f["frames_out"], "periodic_regions": lambda f: len(f["periodic_regions"])},
         imports=("mocycle.tasks.stretch", "mocycle.warp", "mocycle.phase", "pyRipser", "mocycle.cycle",
                  "mocycle.activities", "mocycle.cycle.parts", "mocycle.tasks.feet_option", "mocycle.contacts",
                  "scipy.ndimage"), batch=True,
         facts=("cycles", "factor", "feet", "forced", "fps", "frames_in", "frames_out", "joints_per_group",
                "periodic_regions", "periodic_regions_out", "trend_curves", "windows")),
    Spec("swings", "Segment a take into joint swings and holds; report playback error and compressed size.",
         outputs=(Output("result", "swings", (".mosw", ".json"), required=False,
                         help="Write the swings: .json (records) or .mosw (compact binary file)."),
                  _motion("playback", "Write the motion rebuilt from the swings as .bvh or .glb.", flag="--playback",
                          required=False)),
         figures={"frames": lambda f: f["frames"], "swings": lambda f: f["n_swings"],
                  "per_angle_error_deg": lambda f: f["per_angle_error_deg"],
                  "compressed_bytes": lambda f: f["compressed_bytes"], "ratio_bvh": lambda f: f["ratio_bvh"]},
         imports=("mocycle.tasks.swings", "mocycle.swings", "mocycle.io.mosw", "scipy.optimize", "scipy.ndimage"),
         batch=True,
         facts=("compressed_bytes", "fps", "frames", "geodesic_error_deg", "joints", "n_swings",
                "per_angle_error_deg", "per_joint", "ratio_bvh", "ratio_raw", "raw_float32_bytes",
                "segmentation_error", "threshold")),
    Spec("search", "Rank the takes of a folder by how alike their swings are to an example (query by example).",
         inputs=("query", "folder"), command_module="swings",
         facts=("indexed", "query", "results")),
    Spec("edit", "Scale the angle or the duration of one swing of one joint and write the edited motion.",
         outputs=(_motion("edited", "Edited motion (.bvh or .glb)."),), command_module="swings",
         facts=("angle_deg", "angle_scale", "duration_scale", "end", "joint", "start", "swing")),
    Spec("compress", "Compress a take to keyframes (and a 2-D trajectory for the spatial scheme); report error "
                     "and size.",
         outputs=(Output("result", "compressed", (".mck",), help="The .mck file to write."),),
         command_module="keyframes",
         figures={"frames": lambda f: f["frames"], "keyframes": lambda f: f["keyframes"],
                  "keys_per_period": lambda f: f["keys_per_period"],
                  "error_per_frame_per_joint": lambda f: f["error_per_frame_per_joint"],
                  "compressed_bytes": lambda f: f["compressed_bytes"], "real_ratio": lambda f: f["real_ratio"]},
         imports=("mocycle.tasks.compress", "mocycle.keyframes", "mocycle.phase", "pyRipser", "mocycle.io.mck",
                  "scipy.optimize"), batch=True,
         facts=("bvh_bytes", "compressed_bytes", "error_per_frame_per_joint", "formula_ratio", "frames",
                "keyframe_ratio", "keyframes", "keyframes_set_by", "keys_per_period", "period_frames", "ratio",
                "real_ratio")),
    Spec("decompress", "Rebuild a take from its keyframes; the keyframes come back exactly (unless --feet lock).",
         outputs=(_motion("motion", "The .bvh or .glb file to write."),), command_module="keyframes",
         facts=("feet", "frames", "keyframes", "keyframes_exact", "scheme")),
    Spec("project", "Project every pose to 2-D and pick keyframes: the spatial keyframing view of a take.",
         studio=("projection", "select", "ratio", "seed_projection", "optimize"), command_module="keyframes",
         facts=("frames", "keyframes", "points", "projection", "select", "stress"),
         optional_facts=("points_optimized", "stress_optimized")),
    Spec("author", "A new motion from a stroke drawn on a take's spatial-keyframe plane (thesis chapter 5).",
         inputs=(), studio=("plant", "feet"), cli=False),
)}
