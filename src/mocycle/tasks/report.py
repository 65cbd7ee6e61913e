"""What a task returns: a :class:`Report` (figures, warnings, labelled times, output motions) and the
:class:`Recorder` that times a task and collects its warnings."""

from __future__ import annotations

import os
import sys
import time
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal, NamedTuple

from ..defaults import AMC_FPS
from ..threads import limited

if TYPE_CHECKING:
    from ..motion import Motion

__all__ = ["Labelled", "Recorder", "Report", "is_motion", "label_of", "load"]


@dataclass(frozen=True)
class Report:
    """The outcome of one task run.

    task : the task's name (``"loop"``, ...).
    facts : the figures a user asks for, JSON-ready (what ``mocycle <task> --json`` prints, timing aside).
    warnings : the warnings raised while the task ran, as text.
    timings_s : wall-clock seconds, labelled: ``"total"`` always, parts such as ``"metrics"`` when measured.
    motions : the output motion(s) by role (``{"loop": Motion}``); not part of :meth:`to_dict` (write them
        with ``mocycle.write``).
    result : the library's own result object (e.g. a ``Cycle``), for plots; not part of :meth:`to_dict`.
    extras : other library objects a front end may draw (e.g. the fitted cycle and the foot contacts of a
        loop whose feet were locked, by the role of its motion); not part of :meth:`to_dict`.
    """

    task: str
    facts: Mapping
    warnings: tuple[str, ...] = ()
    timings_s: Mapping[str, float] = field(default_factory=dict)
    motions: Mapping[str, Motion] = field(default_factory=dict, compare=False, repr=False)
    result: object = field(default=None, compare=False, repr=False)
    extras: Mapping[str, object] = field(default_factory=dict, compare=False, repr=False)

    @property
    def seconds(self) -> float:
        """Total wall-clock time of the run, seconds."""
        return float(self.timings_s.get("total", 0.0))

    def to_dict(self) -> dict:
        """JSON-ready: ``task``, ``facts``, ``warnings``, ``timings_s`` (motions and result excluded)."""
        return {"task": self.task, "facts": dict(self.facts), "warnings": list(self.warnings),
                "timings_s": dict(self.timings_s)}

    @classmethod
    def from_dict(cls, data: Mapping) -> Report:
        """The inverse of :meth:`to_dict` (the report comes back without motions and result)."""
        return cls(task=data["task"], facts=dict(data["facts"]), warnings=tuple(data.get("warnings", ())),
                   timings_s=dict(data.get("timings_s", {})))


class Recorder:
    """``with Recorder() as rec: ...`` times the block and records its warnings; ``rec.part("metrics")``
    times a part. On an exception the recorded warnings are issued again so the caller still sees them."""

    def __enter__(self) -> Recorder:
        self._threads = limited()  # BLAS/OpenMP on MOCYCLE_THREADS threads (one by default)
        self._threads.__enter__()
        self._catcher = warnings.catch_warnings(record=True)
        self._caught = self._catcher.__enter__()
        warnings.simplefilter("always")
        self.timings_s: dict[str, float] = {}
        self._t0 = time.perf_counter()
        return self

    def __exit__(self, kind, value, traceback) -> Literal[False]:
        self.timings_s["total"] = time.perf_counter() - self._t0
        self._catcher.__exit__(kind, value, traceback)
        kept = [w for w in self._caught if not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning))]
        self.warnings = tuple(str(w.message) for w in kept)
        if kind is not None:
            for w in kept:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        self._threads.__exit__(kind, value, traceback)
        return False

    def part(self, label: str) -> _Part:
        return _Part(self.timings_s, label)

    def report(self, task: str, facts: Mapping, motions: Mapping[str, Motion] | None = None,
               result: object = None, extras: Mapping[str, object] | None = None) -> Report:
        return Report(task=task, facts=facts, warnings=self.warnings, timings_s=dict(self.timings_s),
                      motions=dict(motions or {}), result=result, extras=dict(extras or {}))


class _Part:
    def __init__(self, timings: dict, label: str):
        self.timings, self.label = timings, label

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        self.timings[self.label] = self.timings.get(self.label, 0.0) + time.perf_counter() - self.t0
        return False


class Labelled(NamedTuple):
    """A motion in memory and how messages name it (a front end's name for the take, e.g. its file name):
    a task input like the motion itself, whose errors and warnings begin ``<label>:`` instead of ``take 0:``."""

    motion: Motion
    label: str


def is_motion(item) -> bool:
    """True for a :class:`~mocycle.motion.Motion` (or a :class:`Labelled` one), without importing
    :mod:`mocycle.motion` (and numpy): when that module is not loaded yet, no object can be a Motion."""
    if isinstance(item, Labelled):
        return True
    motion = sys.modules.get("mocycle.motion")
    return motion is not None and isinstance(item, motion.Motion)


def load(item: Motion | Labelled | str | os.PathLike, amc_fps: float = AMC_FPS, take: str | None = None) -> Motion:
    """A task input: a :class:`Motion` as is, or a motion file read (``amc_fps``: AMC files only; ``take``: the
    animation of a glTF or FBX file)."""
    if isinstance(item, Labelled):
        return item.motion
    from ..motion import Motion  # what is_motion tests; mocycle.io, read next otherwise, imports it too

    if isinstance(item, Motion):
        return item
    from ..io import read_motion

    return read_motion(item, fps=amc_fps, take=take)


def load_each(items, amc_fps: float = AMC_FPS, take: str | None = None) -> list[Motion]:
    """Each input of a task that takes several (:func:`load`), each with its own take: ``take`` for every one,
    or one per input separated by commas (:func:`~mocycle.tasks.fields.take_for_each`)."""
    from .fields import take_for_each

    return [load(item, amc_fps, k) for item, k in zip(items, take_for_each(take, len(items)), strict=True)]


def label_of(item, k: int = 0) -> str:
    """How messages name an input: its path, its label (:class:`Labelled`), or ``take k`` for a motion in
    memory."""
    if isinstance(item, Labelled):
        return item.label
    return f"take {k}" if is_motion(item) else str(Path(item)) if not isinstance(item, str) else item
