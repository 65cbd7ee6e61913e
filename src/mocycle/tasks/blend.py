"""``blend``: one new loop from the cycles of several takes (paper 001 §4.5, a convex combination)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import OptionError
from . import fields
from .fields import take_cycles
from .options import Constraint, Flag, option
from .report import Recorder, Report, label_of, load_each


@dataclass(frozen=True)
class Weights(Constraint):
    """None, or a tuple of numbers >= 0 (a text such as ``"0.7,0.3"`` is split at the commas)."""

    def __call__(self, name: str, value):
        if value is None:
            return None
        items = value.split(",") if isinstance(value, str) else value
        try:
            w = tuple(float(v) for v in items)
        except (TypeError, ValueError):
            w = ()
        if not w or not all(math.isfinite(x) and x >= 0 for x in w):
            raise OptionError(name, f"must be comma-separated numbers >= 0, one per take (e.g. 0.7,0.3); got "
                                    f"{value!r}")
        return w


@dataclass(frozen=True)
class Options(fields.CycleOptions):
    """Options of ``blend`` (and how each take's cycle is found: :class:`~mocycle.tasks.fields.CycleOptions`)."""

    weights: tuple[float, ...] | None = option(
        None, "One weight >= 0 per take, comma-separated (normalised to sum 1); default equal.", Weights())
    root: str = fields.root("inplace", "inplace (on the spot) or motion (moves on by the blended stride).")
    cycles: int = fields.cycles(1, "Repeat the loop this many times in the output.")
    align: bool = option(True, "Search each take's phase offset against the first.", Flag())
    take: str | None = fields.takes()


def run(takes: Sequence, options: Options | None = None) -> Report:
    """Blend the cycles of two or more takes (Motions or files on one skeleton) into one loop;
    ``motions["loop"]`` is it repeated ``cycles`` times. Raises NoPeriodicMotion when a take has no cycle and
    LoopRefused when a take's cycle fails a loop check (``force``: a warning instead)."""
    from ..cycle.blend import blend_cycles, check_weights, cycle_seam
    from .feet_option import clean_feet

    o = options or Options()
    takes = list(takes)
    if len(takes) < 2:
        raise OptionError("takes", f"must be at least two takes to blend; got {len(takes)}")
    if o.weights is not None:
        if len(o.weights) != len(takes):
            raise OptionError("weights", f"needs {len(takes)} numbers, one per take; got {len(o.weights)}")
        check_weights(o.weights, len(takes))  # refuse bad weights before the (slower) extraction
    with Recorder() as rec:
        motions = load_each(takes, o.amc_fps, o.take)
        labels = [label_of(t, k) for k, t in enumerate(takes)]
        with rec.part("cycle"):
            cycles = take_cycles(motions, labels, o)
        result = blend_cycles(cycles, o.weights, align=o.align, labels=labels, force=o.force)
        with rec.part("feet"):
            cleaned, feet_facts, _ = clean_feet(result.cycle, o.feet, o.root, o.foot_joints, reference=motions)
        result = dataclasses.replace(result, cycle=cleaned)
        loop = result.repeat(o.cycles, root=o.root)
        facts = {
            **result.to_dict(),
            "frames_out": result.n_frames * o.cycles,
            "root": o.root,
            "cycles": o.cycles,
            "seam": result.seam(),
            "input_seams": [cycle_seam(c) for c in result.inputs],
            "feet": feet_facts,
        }
    return rec.report("blend", facts, {"loop": loop}, result)
