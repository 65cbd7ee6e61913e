"""Which takes a batch runs: files, folders (searched recursively) and glob patterns, each take with the
path its outputs take under the output folder (the input tree, mirrored)."""

from __future__ import annotations

import errno
import glob
import os
import stat
from dataclasses import dataclass
from pathlib import Path

from ..errors import MocycleError
from ..suffixes import MOTION_READ_SUFFIXES

#: the suffixes of the files that hold a take (``.amc`` with its ``.asf`` beside it)

__all__ = ["Take", "find_takes"]


@dataclass(frozen=True)
class Take:
    """One input file of a batch.

    source : the motion file (absolute path).
    rel : its path relative to the common folder of the inputs; the outputs go to ``OUTDIR / rel`` with their
        own suffix, so the output tree mirrors the input tree.
    problem : why a path found in an input folder (or matched by a pattern) cannot be read as a take: a broken
        symbolic link, a link loop, a folder or file that cannot be read, not a regular file. ``None`` for a
        take to run. Such a path is not sent to the workers; it gets a row with status ``error`` and this
        message, so every path found is in the results.
    """

    source: Path
    rel: Path
    problem: str | None = None

    def output(self, outdir: Path, suffix: str) -> Path:
        """``OUTDIR/rel`` with ``suffix`` instead of the take's own (``a/walk.amc`` -> ``OUT/a/walk.bvh``)."""
        return outdir / self.rel.with_suffix(suffix)

    def inputs(self) -> list[Path]:
        """The files the take is read from: the motion file, and for an ``.amc`` every ``.asf`` beside it
        (any of them may be its skeleton), so that ``--resume`` sees a changed skeleton too."""
        if self.source.suffix.lower() == ".amc":
            return [self.source] + sorted(p for p in self.source.parent.iterdir() if p.suffix.lower() == ".asf")
        return [self.source]


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def problem_of(p: Path) -> str | None:
    """Why the path ``p`` (named like a take) cannot be read as one, or ``None`` when it can."""
    try:
        st = p.stat()
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return "a symbolic link loop"
        if p.is_symlink():
            try:
                return f"a broken symbolic link (to {os.readlink(p)})"
            except OSError:
                return "a broken symbolic link"
        return f"cannot read the file ({_why(exc)})"
    if stat.S_ISDIR(st.st_mode):
        return None  # a folder named like a take is searched like any folder
    if not stat.S_ISREG(st.st_mode):
        return "not a regular file (a device, pipe or socket)"
    if not os.access(p, os.R_OK):
        return "cannot read the file (Permission denied)"
    return None


def _walk(root: Path, skip: Path | None) -> tuple[list[Path], list[tuple[Path, str]]]:
    """The takes under the folder ``root`` (recursively, links to folders followed, hidden entries and
    ``skip`` left out) and the paths found there that cannot be read: (path, why).

    Every path is looked at once: a folder that cannot be listed, a folder link that leads back into its own
    ancestors (a loop), a broken or looping link named like a take, a take that is no regular file or cannot
    be read are returned with the reason, never dropped in silence. No recursion (a deep tree cannot exhaust
    the stack)."""
    files: list[Path] = []
    problems: list[tuple[Path, str]] = []
    stack: list[tuple[Path, tuple]] = [(root, ())]
    while stack:
        folder, ancestors = stack.pop()
        try:
            st = folder.stat()
            ident = (st.st_dev, st.st_ino)
            if ident in ancestors:
                problems.append((folder, "a symbolic link loop (it leads back to a folder above it)"))
                continue
            with os.scandir(folder) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError as exc:
            problems.append((folder, f"cannot read the folder ({_why(exc)})"))
            continue
        below = []
        for entry in entries:
            if entry.name.startswith("."):
                continue
            p = folder / entry.name
            if _inside(p, skip):
                continue
            try:
                is_dir = entry.is_dir()  # follows links
            except OSError:
                is_dir = False
            if is_dir:
                below.append(p)
            elif p.suffix.lower() in MOTION_READ_SUFFIXES:
                why = problem_of(p)
                if why is None:
                    files.append(p)
                else:
                    problems.append((p, why))
        stack += [(p, (*ancestors, ident)) for p in reversed(below)]
    return files, problems


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


def _below(outdir: Path | None, root: Path) -> Path | None:
    """The output folder to leave out when searching ``root``: only when it lies inside ``root`` (outputs
    written into the input tree); an input folder inside the output folder (``-o .``) is searched whole."""
    return outdir if outdir is not None and outdir != root and root in outdir.parents else None


def _inside(p: Path, folder: Path | None) -> bool:
    return folder is not None and (p == folder or folder in p.parents)


def find_takes(inputs: list[str | os.PathLike], outdir: str | os.PathLike | None = None) -> list[Take]:
    """The takes named by ``inputs`` (files, folders, glob patterns), sorted by their relative path.

    A folder is searched recursively for motion files (``.bvh``, ``.amc``, ``.fbx``, ``.glb``, ``.gltf``;
    hidden files and anything under ``outdir``, when it lies inside the folder, are left out, so outputs written
    into the input tree are never read back as inputs; an input folder inside ``outdir`` is searched whole). The
    relative path of a take is taken from the common folder of the inputs' roots (a folder is its own root,
    a file's root is its folder, a pattern's root is its folder before the first wildcard).

    Raises
    ------
    MocycleError
        An input that does not exist, matches nothing or holds no take; a file that is not a ``.bvh`` or
        ``.amc``; or two takes that would write the same output (``walk.bvh`` and ``walk.amc`` side by side).
    """
    if not inputs:
        raise MocycleError("no inputs: name files, folders or glob patterns")
    skip = _abs(outdir) if outdir is not None else None
    found: list[tuple[Path, Path, str | None]] = []  # (file, root, problem)
    for item in map(str, inputs):
        p = Path(item)
        if p.is_dir():
            root = _abs(p)
            files, problems = _walk(root, _below(skip, root))
            if not files and not problems:
                raise MocycleError(f"{item}: no {', '.join(MOTION_READ_SUFFIXES)} files in this folder")
        elif p.exists():
            if p.suffix.lower() not in MOTION_READ_SUFFIXES:
                raise MocycleError(f"{item}: not a take; batch reads {', '.join(MOTION_READ_SUFFIXES)} files")
            why = problem_of(_abs(p))
            if why is not None:
                raise MocycleError(f"{item}: {why}")
            root, files, problems = _abs(p).parent, [_abs(p)], []
        elif _magic(item):
            root = _abs(_root_of_pattern(item))
            matched = [_abs(f) for f in sorted(glob.glob(item, recursive=True))]
            matched = [f for f in matched if f.suffix.lower() in MOTION_READ_SUFFIXES and not f.name.startswith(".")
                       and not _inside(f, _below(skip, root)) and not f.is_dir()]
            files, problems = [], []
            for f in matched:
                why = problem_of(f)
                if why is None:
                    files.append(f)
                else:
                    problems.append((f, why))
            if not files and not problems:
                raise MocycleError(f"{item}: the pattern matches no {', '.join(MOTION_READ_SUFFIXES)} file")
        elif os.path.islink(item):
            raise MocycleError(f"{item}: {problem_of(Path(item))}")
        else:
            raise MocycleError(f"{item}: no such file or folder")
        found += [(f, root, None) for f in files] + [(f, root, why) for f, why in problems]
    base = Path(os.path.commonpath([str(root) for _, root, _ in found]))
    takes: dict[Path, Take] = {}
    for f, _, why in found:  # the same path named twice is one take; links of other names are takes of their own
        takes.setdefault(f, Take(source=f, rel=f.relative_to(base), problem=why))
    out = sorted(takes.values(), key=lambda t: str(t.rel))
    stems: dict[Path, Take] = {}
    for t in out:
        if t.problem is not None:
            continue
        stem = t.rel.with_suffix("")
        if stem in stems:
            raise MocycleError(f"{stems[stem].source} and {t.source} would write the same outputs "
                               f"({stem}.*); batch them separately")
        stems[stem] = t
    return out
