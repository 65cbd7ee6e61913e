"""The takes the studio shows: found in files and folders, read on demand, looped in the background.

A file in a served folder that is a link to a file outside it is listed as ``refused`` and never read (the
studio shows a folder, not what its links reach).  A file name that is not UTF-8 is kept as the operating
system gave it (Python's surrogate escapes) and shown with its odd bytes written ``\xff``.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import MocycleError
from ..motion import Motion
from ..tasks import words

#: the motion files the library lists (``.amc`` needs its ``.asf`` beside it)
SUFFIXES = (".bvh", ".amc", ".fbx", ".glb", ".gltf")
#: seconds a request waits for another request's (or the analysis's) read of the same take before a 503
READ_WAIT_S = 20.0


def display(text: str) -> str:
    """``text`` as valid UTF-8 for a page or a message: the bytes of a non-UTF-8 file name (which Python keeps
    as surrogate escapes) written ``\xff``."""
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
        return True
    except (ValueError, OSError, RuntimeError):
        return False


def find_takes(paths) -> list[Take]:
    """The motion files named by ``paths`` (files, or folders searched recursively), sorted, no repeats; a
    file of a folder that links outside that folder is a take with status ``refused`` (never read).  Ids are
    given by the caller."""
    found: list[tuple[Path, str | None]] = []
    for p in map(Path, paths):
        if p.is_dir():
            for f in sorted(f for f in p.rglob("*") if f.suffix.lower() in SUFFIXES and f.is_file()):
                found.append((f, None if _inside(f, p) else
                              "refused: a link to a file outside the served folder (not read)"))
        elif p.is_file():
            if p.suffix.lower() not in SUFFIXES:
                raise MocycleError(f"{display(str(p))}: not a motion file the studio reads ({', '.join(SUFFIXES)})")
            found.append((p, None))
        else:
            raise MocycleError(f"{display(str(p))}: no such file or folder")
    seen, out = set(), []
    for f, refusal in found:
        try:
            key = f.resolve()
        except (OSError, RuntimeError):
            key = f.absolute()
        if key not in seen:
            seen.add(key)
            take = Take(id="", path=f)
            if refusal:
                take.status, take.error = "refused", refusal
            out.append(take)
    return out


@dataclass
class Take:
    """One take of the library and what the background analysis found."""

    id: str
    path: Path
    status: str = "queued"  # queued, running, done, failed
    facts: dict = field(default_factory=dict)  # frames, fps, duration_s, joints
    loops: list = field(default_factory=list)  # one summary per periodic motion
    reason: str | None = None  # why there is no loop
    error: str | None = None
    _motion: Motion | None = field(default=None, repr=False)
    _failed: str | None = field(default=None, repr=False)  # why it could not be read
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    @property
    def name(self) -> str:
        """The file's name as the page shows it (valid UTF-8)."""
        return display(self.path.name)

    def motion(self, amc_fps: float) -> Motion:
        """The take, read once (a refused take: an error, never read); a request that waits :data:`READ_WAIT_S`
        for another one's read of it gets a 503 (no request thread waits on one take for long); a take that
        failed to read fails again at once, with the same message."""
        if self.status == "refused":
            raise MocycleError(f"{self.name}: {self.error}")
        if not self._lock.acquire(timeout=READ_WAIT_S):
            from http import HTTPStatus

            from .validate import HTTPProblem

            raise HTTPProblem(f"{self.name} is still being read; try again in a moment",
                              HTTPStatus.SERVICE_UNAVAILABLE)
        try:
            if self._motion is None:
                if self._failed is not None:
                    raise MocycleError(self._failed)
                from .. import tasks

                try:
                    self._motion = tasks.info.run(self.path, tasks.info.Options(amc_fps=amc_fps)).motions["motion"]
                except MocycleError as exc:
                    self._failed = str(exc)
                    raise
            return self._motion
        finally:
            self._lock.release()

    def to_dict(self) -> dict:
        """What the page lists; ``reason`` and ``error`` whole (the detail), ``reason_line`` and ``error_line``
        the line the page shows of them (:func:`~mocycle.tasks.words.brief`)."""
        return {"id": self.id, "name": self.name, "path": display(str(self.path)), "status": self.status,
                "facts": self.facts, "loops": self.loops, "reason": self.reason, "error": self.error,
                "reason_line": self.reason and words.brief(self.reason),
                "error_line": self.error and words.brief(self.error)}


def loop_summary(loop: dict) -> dict:
    """The figures the library shows for one loop (from ``tasks.loop`` facts).  ``refused``: the loop failed
    checks (``failed_checks``, the ones ``tasks.loop`` refuses it for without ``force``); ``refusal``: why, each
    check's reason with its numbers; ``refusal_line``: the same in a few plain words
    (:func:`~mocycle.tasks.words.refusal`).  A figure that could not be measured (the foot skate of a rig
    whose feet are not found by name) is None."""
    m = loop.get("metrics", {})
    failed = loop.get("failed_checks", [])
    return {"part": loop["part"], "kind": loop.get("kind"), "frames": loop.get("frames"),
            "period_frames": loop["period_frames"],
            "period_s": loop["period_frames"] / loop["fps"], "cycle_frames": loop["cycle_frames"],
            "seam_pose": m.get("seam_pose"), "seam_velocity": m.get("seam_velocity"),
            "skate": m.get("skate"), "input_skate": m.get("input_skate"),
            "failed_checks": [c.get("check", c.get("name", "")) for c in failed],
            "refused": bool(failed), "refusal": "; ".join(f"{c['check']}: {c['reason']}" for c in failed) or None,
            "refusal_line": words.refusal(failed) if failed else None,
            "excitation": loop.get("excitation")}
