"""The takes the studio shows: found in files and folders, read on demand, looped in the background."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import MocycleError
from ..motion import Motion

#: the motion files the library lists (``.amc`` needs its ``.asf`` beside it)
SUFFIXES = (".bvh", ".amc", ".fbx", ".glb", ".gltf")


def find_takes(paths) -> list[Path]:
    """The motion files named by ``paths`` (files, or folders searched recursively), sorted, no repeats."""
    found: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(f for f in p.rglob("*") if f.suffix.lower() in SUFFIXES and f.is_file())
        elif p.is_file():
            if p.suffix.lower() not in SUFFIXES:
                raise MocycleError(f"{p}: not a motion file the studio reads ({', '.join(SUFFIXES)})")
            found.append(p)
        else:
            raise MocycleError(f"{p}: no such file or folder")
    seen, out = set(), []
    for f in found:
        key = f.resolve()
        if key not in seen:
            seen.add(key)
            out.append(f)
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
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    @property
    def name(self) -> str:
        return self.path.name

    def motion(self, amc_fps: float) -> Motion:
        """The take, read once."""
        with self._lock:
            if self._motion is None:
                from .. import tasks

                self._motion = tasks.info.run(self.path, tasks.info.Options(amc_fps=amc_fps)).motions["motion"]
            return self._motion

    def to_dict(self) -> dict:
        return {"id": self.id, "name": self.name, "path": str(self.path), "status": self.status,
                "facts": self.facts, "loops": self.loops, "reason": self.reason, "error": self.error}


def loop_summary(loop: dict) -> dict:
    """The figures the library shows for one loop (from ``tasks.loop`` facts).  ``refused``: the loop failed
    checks (``failed_checks``, the ones ``tasks.loop`` refuses it for without ``force``); ``refusal``: why."""
    m = loop.get("metrics", {})
    failed = loop.get("failed_checks", [])
    return {"class": loop["class"], "period_frames": loop["period_frames"],
            "period_s": loop["period_frames"] / loop["fps"], "cycle_frames": loop["cycle_frames"],
            "seam_pose": m.get("seam_pose"), "seam_velocity": m.get("seam_velocity"),
            "skate": m.get("skate"), "input_skate": m.get("input_skate"),
            "failed_checks": [c.get("check", c.get("name", "")) for c in failed],
            "refused": bool(failed), "refusal": "; ".join(f"{c['check']}: {c['reason']}" for c in failed) or None,
            "excitation": loop.get("excitation")}
