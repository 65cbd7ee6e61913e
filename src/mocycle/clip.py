"""What a written motion is as an animation clip: its name and, for loops, the facts game tools ask for.

The task layer says what it made (:func:`mocycle.tasks.clips.clip_of`); the writers of formats that can
hold it (glTF) write it, converting lengths and directions into their own units and axes.  Nothing here
knows a file format.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Clip", "jsonable"]


@dataclass(frozen=True, kw_only=True)
class Clip:
    """One animation clip.

    name : the clip's name (loops: ``<name>_loop``, which Godot loops by itself).
    loopable : the clip is a seamless cycle (its last frame runs into its first).
    root : ``"inplace"`` (walks on the spot) or ``"motion"`` (root motion: it moves on each cycle); ``None``
        when not a loop.
    cycles : how many cycles the clip holds.
    cycle_frames : frames of one cycle in the clip (without the closing frame).
    period_frames : the take's period, input frames (may be fractional).
    closing_frame : the clip ends with a copy of its first pose (moved on by one cycle's travel and turn
        with root motion), so that players that loop over the clip's key range play whole periods.
    travel_per_cycle : ``(3,)`` the travel joint's displacement per cycle, motion units and axes.
    turn_per_cycle_deg : the turn about the vertical per cycle, degrees (right hand about up).
    contacts : per foot (``"left"``, ``"right"``, ...), the ``[start, stop)`` clip frames of its ground
        contacts in one cycle (``stop > cycle_frames`` when a contact runs over the seam into the next cycle);
        ``None`` when the feet were not analysed.
    travel_joint : the name of the joint whose translation carries the travel (root motion).
    facts : other JSON-ready figures, copied as they are.
    """

    name: str
    loopable: bool = False
    root: str | None = None
    cycles: int | None = None
    cycle_frames: int | None = None
    period_frames: float | None = None
    closing_frame: bool = False
    travel_per_cycle: tuple[float, float, float] | None = None
    turn_per_cycle_deg: float | None = None
    contacts: Mapping[str, list] | None = None
    travel_joint: str | None = None
    facts: Mapping = field(default_factory=dict)

    def metadata(self, frame_time: float, length: Callable[[np.ndarray], np.ndarray] = lambda v: v) -> dict:
        """JSON-ready facts of the clip; ``length`` turns a vector in motion units and axes into the file's
        (the travel).  Times in seconds beside frames (``frame_time`` s per frame).  Each foot's contacts are
        ``{"count": n, "frames": [[start, stop], ...], "seconds": [[start, stop], ...]}`` (stop exclusive)."""
        out = {"name": self.name, "loopable": self.loopable}
        if self.loopable:
            out["root_motion"] = self.root == "motion"
            out["in_place"] = self.root == "inplace"
            out["cycles"] = self.cycles
            out["cycle_frames"] = self.cycle_frames
            out["cycle_seconds"] = None if self.cycle_frames is None else self.cycle_frames * frame_time
            out["period_frames"] = self.period_frames
            out["closing_frame"] = self.closing_frame
            if self.travel_per_cycle is not None:
                out["travel_per_cycle"] = length(np.asarray(self.travel_per_cycle, dtype=float))
            out["turn_per_cycle_deg"] = self.turn_per_cycle_deg
            out["travel_joint"] = self.travel_joint
            if self.contacts is not None:
                out["foot_contacts"] = {foot: {"count": len(spans), "frames": [[int(a), int(b)] for a, b in spans],
                                               "seconds": [[a * frame_time, b * frame_time] for a, b in spans]}
                                        for foot, spans in self.contacts.items()}
        out["frame_time"] = frame_time
        if self.facts:
            out["facts"] = dict(self.facts)
        return jsonable(out)


def jsonable(x):
    """``x`` with numpy numbers and arrays as Python ones and non-finite floats as ``None`` (strict JSON)."""
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if np.isfinite(x) else None
    return x
