"""``transition``: from the first take's cycle to the second's (paper 001 §4.5, a homotopy of loops)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import OptionError
from . import fields
from .fields import take_cycles
from .report import Recorder, Report, label_of, load_each


@dataclass(frozen=True)
class Options(fields.CycleOptions):
    """Options of ``transition`` (and how each take's cycle is found: :class:`~mocycle.tasks.fields.CycleOptions`)."""

    cycles: int = fields.cycles(3, "Cycles over which the weight moves from the first to the second.")
    root: str = fields.root("motion", "motion (travels on) or inplace (on the spot).")
    take: str | None = fields.takes()


def run(takes: Sequence, options: Options | None = None) -> Report:
    """A motion that starts as the first take's cycle and ends as the second's (``motions["transition"]``)."""
    from ..cycle.blend import transition, transition_smoothness
    from .feet_option import lock_motion

    o = options or Options()
    takes = list(takes)
    if len(takes) != 2:
        raise OptionError("takes", f"must be two takes (first, second); got {len(takes)}")
    with Recorder() as rec:
        labels = [label_of(t, k) for k, t in enumerate(takes)]
        with rec.part("cycle"):
            a, b = take_cycles(load_each(takes, o.amc_fps, o.take), labels, o)
        result = transition(a, b, o.cycles, root=o.root, labels=labels, force=o.force)
        facts = {**result.to_dict(), "root": o.root, "smoothness": transition_smoothness(result)}
        with rec.part("feet"):
            written, facts["feet"] = lock_motion(result.motion, o.feet, o.foot_joints, o.root == "motion")
    return rec.report("transition", facts, {"transition": written}, result)
