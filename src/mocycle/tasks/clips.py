"""What the tasks' output motions are as animation clips (:class:`~mocycle.clip.Clip`), for the writers of
formats that name clips and keep loop facts (glTF), and the loops' closing frame.

A loop of ``N`` frames per cycle is written without its closing frame (frame ``N`` would equal frame 0, the
BVH way); players that loop over a clip's key range (glTF engines, three.js) need the closing frame to play
whole periods: :func:`closed_loop` adds it, moved on by a cycle's travel and turn with root motion.
:func:`for_output` is what every front end writes: the motion (with the closing frame for .glb loops) and
its clip.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from ..clip import Clip
from ..motion import Motion, concatenate

__all__ = ["LOOP_TASKS", "clip_of", "closed_loop", "closing_frame", "cycle_of", "for_output"]

#: the tasks whose output motion is a seamless loop (clip ``<name>_loop``)
LOOP_TASKS = ("loop", "blend")


def closing_frame(cycle, cycles: int, root: str) -> Motion:
    """The pose after the last frame of ``cycles`` repeats (one frame): the loop's first pose, moved on by
    ``cycles`` cycles' travel and turn with ``root="motion"``."""
    n = cycle.n_frames * cycles
    return cycle.repeat(cycles + 1, root=root)[n:n + 1]


def closed_loop(cycle, cycles: int, root: str, repeated: Motion | None = None) -> Motion:
    """``cycle.repeat(cycles, root)`` plus its :func:`closing_frame` (``cycles * N + 1`` frames).
    ``repeated``: the repeat already made."""
    repeated = cycle.repeat(cycles, root=root) if repeated is None else repeated
    return concatenate([repeated, closing_frame(cycle, cycles, root)])


def cycle_of(report, role: str):
    """The cycle behind a loop task's output motion ``role`` (``report.result``, or, when it holds one cycle
    per loop (``loop.part<k>``, ``loop.class<k>`` roles), the one of that role): what :func:`closed_loop`
    repeats."""
    if report.task not in LOOP_TASKS:
        raise ValueError(f"a {report.task} report holds no cycle")
    if isinstance(report.result, list):
        return report.result[[f.get("role") for f in report.facts["loops"]].index(role)]
    return report.result


def clip_of(report, role: str, name: str, closing_frame: bool = False) -> Clip:
    """The clip of ``report.motions[role]`` called ``name`` (loops: ``<name>_loop``) with the loop's facts.

    Parameters
    ----------
    report : a task's :class:`~mocycle.tasks.report.Report`.
    role : the motion's role (``"loop"``, ``"loop.class1"``, ``"stretched"``, ...).
    name : the clip's base name (the CLI: the output file's stem).
    closing_frame : the written motion ends with the closing frame (:func:`closed_loop`).

    Examples
    --------
    >>> from mocycle import tasks
    >>> from mocycle.datasets import synthetic_walk
    >>> report = tasks.loop.run(synthetic_walk(n_frames=300).motion, tasks.loop.Options(root="motion"))
    >>> clip = clip_of(report, "loop", "walk")
    >>> clip.name, clip.loopable, clip.root, clip.cycle_frames
    ('walk_loop', True, 'motion', 60)
    """
    motion = report.motions[role]
    if report.task not in LOOP_TASKS:
        return Clip(name=name, facts={"task": report.task, "frames": motion.n_frames})
    facts = _loop_facts(report.facts, role)
    contacts = (facts.get("feet") or {}).get("contacts")
    return Clip(name=name if name.endswith("_loop") else f"{name}_loop", loopable=True, root=facts["root"],
                cycles=facts["cycles"], cycle_frames=facts["cycle_frames"], period_frames=facts["period_frames"],
                closing_frame=closing_frame, travel_per_cycle=tuple(facts["travel_per_cycle"]),
                turn_per_cycle_deg=facts["turn_per_cycle_deg"],
                contacts=None if contacts is None else {side: c["contacts"] for side, c in contacts.items()},
                travel_joint=motion.skeleton.names[motion.travel_joint],
                facts={"task": report.task, "seam": _seam(facts)})


def _loop_facts(facts: Mapping, role: str) -> Mapping:
    """The figures of the loop written as ``role`` (``loop``, ``loop.part<k>``, ``loop.class<k>``)."""
    loops = facts.get("loops")
    if not loops:
        return facts
    return next((f for f in loops if f.get("role") == role), loops[0])


def _seam(facts: Mapping) -> dict:
    """The seam figures (pose and velocity jumps, × median step) of a loop's or a blend's facts."""
    seam = facts.get("seam") or facts.get("metrics") or {}
    return {k: seam[k] for k in ("seam_pose", "seam_velocity") if k in seam}


def for_output(report, role: str, path: str | os.PathLike, closing_frame: bool | None = None):
    """What to write for ``report.motions[role]`` at ``path``: ``(motion, clip)``.

    A ``.glb`` gets the clip of :func:`clip_of` named after the file's stem (``None`` for other formats);
    a loop gets its closing frame when ``closing_frame`` is true, or, when it is ``None``, for ``.glb``
    outputs only (glTF players wrap at the last key; BVH loops keep the mocycle convention, frame N not
    written).  Write them with ``mocycle.write(motion, path, clip=clip)``.
    """
    p = Path(path)
    glb = p.suffix.lower() == ".glb"
    closing = report.task in LOOP_TASKS and (glb if closing_frame is None else bool(closing_frame))
    motion = report.motions[role]
    if closing:
        facts = clip_of(report, role, p.stem)
        assert facts.cycles is not None and facts.root is not None  # a loop's clip has its options' cycles, root
        motion = closed_loop(cycle_of(report, role), facts.cycles, facts.root, motion)
    return motion, (clip_of(report, role, p.stem, closing) if glb else None)
