"""Which takes a batch runs: files, folders (searched recursively) and glob patterns, each take with the
path its outputs take under the output folder (the input tree, mirrored)."""

from __future__ import annotations

import glob
import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import MocycleError

#: the suffixes of the files that hold a take (``.amc`` with its ``.asf`` beside it)
TAKE_SUFFIXES = (".bvh", ".amc", ".fbx", ".glb", ".gltf")

__all__ = ["TAKE_SUFFIXES", "Take", "find_takes"]


@dataclass(frozen=True)
class Take:
    """One input file of a batch.

    source : the motion file (absolute path).
    rel : its path relative to the common folder of the inputs; the outputs go to ``OUTDIR / rel`` with their
        own suffix, so the output tree mirrors the input tree.
    """

    source: Path
    rel: Path

    def output(self, outdir: Path, suffix: str) -> Path:
        """``OUTDIR/rel`` with ``suffix`` instead of the take's own (``a/walk.amc`` -> ``OUT/a/walk.bvh``)."""
        return outdir / self.rel.with_suffix(suffix)

    def inputs(self) -> list[Path]:
        """The files the take is read from: the motion file, and for an ``.amc`` every ``.asf`` beside it
        (any of them may be its skeleton), so that ``--resume`` sees a changed skeleton too."""
        if self.source.suffix.lower() == ".amc":
            return [self.source] + sorted(p for p in self.source.parent.iterdir() if p.suffix.lower() == ".asf")
        return [self.source]


def _is_take(p: Path) -> bool:
    return p.is_file() and p.suffix.lower() in TAKE_SUFFIXES and not p.name.startswith(".")


def _magic(text: str) -> bool:
    return glob.has_magic(text)


def _root_of_pattern(pattern: str) -> Path:
    """The folder of a glob pattern before its first wildcard (``data/*/walk*.bvh`` -> ``data``)."""
    parts = Path(pattern).parts
    head = []
    for part in parts:
        if _magic(part):
            break
        head.append(part)
    return Path(*head) if head else Path(".")


def _abs(p) -> Path:
    """The absolute, normalised path, symbolic links kept (a linked take keeps the name the user gave it)."""
    return Path(os.path.abspath(p))


def _inside(p: Path, folder: Path | None) -> bool:
    return folder is not None and (p == folder or folder in p.parents)


def find_takes(inputs: list[str | os.PathLike], outdir: str | os.PathLike | None = None) -> list[Take]:
    """The takes named by ``inputs`` (files, folders, glob patterns), sorted by their relative path.

    A folder is searched recursively for motion files (``.bvh``, ``.amc``, ``.fbx``, ``.glb``, ``.gltf``;
    hidden files and anything under ``outdir`` are left out, so outputs written into the input tree are never
    read back as inputs). The relative path of a take is taken from the common folder of the inputs' roots (a
    folder is its own root, a file's root is its folder, a pattern's root is its folder before the first wildcard).

    Raises
    ------
    MocycleError
        An input that does not exist, matches nothing or holds no take; a file that is not a ``.bvh`` or
        ``.amc``; or two takes that would write the same output (``walk.bvh`` and ``walk.amc`` side by side).
    """
    if not inputs:
        raise MocycleError("no inputs: name files, folders or glob patterns")
    skip = _abs(outdir) if outdir is not None else None
    found: list[tuple[Path, Path]] = []  # (file, root)
    for item in map(str, inputs):
        p = Path(item)
        if p.is_dir():
            root = _abs(p)
            files = [f for f in sorted(root.rglob("*")) if _is_take(f) and not _inside(f, skip)
                     and not any(part.startswith(".") for part in f.relative_to(root).parts)]
            if not files:
                raise MocycleError(f"{item}: no {', '.join(TAKE_SUFFIXES)} files in this folder")
        elif p.exists():
            if p.suffix.lower() not in TAKE_SUFFIXES:
                raise MocycleError(f"{item}: not a take; batch reads {', '.join(TAKE_SUFFIXES)} files")
            root, files = _abs(p).parent, [_abs(p)]
        elif _magic(item):
            root = _abs(_root_of_pattern(item))
            files = [_abs(f) for f in sorted(glob.glob(item, recursive=True))]
            files = [f for f in files if _is_take(f) and not _inside(f, skip)]
            if not files:
                raise MocycleError(f"{item}: the pattern matches no {', '.join(TAKE_SUFFIXES)} file")
        else:
            raise MocycleError(f"{item}: no such file or folder")
        found += [(f, root) for f in files]
    base = Path(os.path.commonpath([str(root) for _, root in found]))
    takes = {}
    for f, _ in found:  # the same path named twice is one take; links of other names are takes of their own
        takes.setdefault(f, Take(source=f, rel=f.relative_to(base)))
    out = sorted(takes.values(), key=lambda t: str(t.rel))
    stems: dict[Path, Take] = {}
    for t in out:
        stem = t.rel.with_suffix("")
        if stem in stems:
            raise MocycleError(f"{stems[stem].source} and {t.source} would write the same outputs "
                               f"({stem}.*); batch them separately")
        stems[stem] = t
    return out
