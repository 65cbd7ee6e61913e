"""Write files all at once: to a temporary file beside the target, then rename.

The temporary file is ``.<name>.<pid>.<random>.tmp`` beside the target (for a name too long for that, its
first 150 bytes and a hash of the whole stand for ``<name>``); it is removed on every exit
the process lives to see (an exception, Ctrl-C, SIGTERM handled by the CLI).  A run killed outright
(SIGKILL, power loss) leaves it behind: the next write to the same target removes such leftovers of
processes that no longer run (:func:`clean_stale`).  Readers never take them for takes (they end in
``.tmp``).

A process lists a folder's leftovers once, at its first write there, not at every write: writing ``n``
outputs into one folder costs one listing, not ``n`` listings of a folder that grows to ``n`` files.  The
leftovers of a run killed while this process runs are the next process's to remove.
"""

from __future__ import annotations

import os
import tempfile
import threading
import time
from collections.abc import Iterable
from pathlib import Path
from typing import IO

#: A leftover temporary file without a process id in its name counts as stale after this many seconds.
STALE_AFTER_S = 3600.0

_leftovers: dict[str, list[str]] = {}  # per folder (absolute) listed by this process: the names of its leftovers
_lock = threading.Lock()  # batch's threaded workers write side by side


#: the longest name a file may have (bytes; most file systems)
NAME_MAX = 255


def _temporary_prefix(name: str) -> str:
    """``.<name>.``, the start of a temporary file's name for the target ``name``; for a long name (whose
    temporary name would pass :data:`NAME_MAX` bytes) its first 150 bytes and a hash of the whole instead."""
    if len(os.fsencode(name)) <= NAME_MAX - 50:  # room for ".", ".<pid>.<random>.tmp"
        return f".{name}."
    import hashlib

    raw = os.fsencode(name)
    head = os.fsdecode(raw[:150])  # bytes of a cut character stay bytes (surrogate escapes)
    return f".{head}~{hashlib.sha256(raw).hexdigest()[:12]}."


def _file_mode(path: Path) -> int:
    """The mode a plain ``open(path, "w")`` would give: the old file's, else 0o666 minus the umask."""
    try:
        return path.stat().st_mode & 0o777
    except OSError:
        mask = os.umask(0)
        os.umask(mask)
        return 0o666 & ~mask


def atomic_write(path: str | os.PathLike, data: str | bytes | Iterable[str] | Iterable[bytes],
                 binary: bool = False) -> Path:
    """Write ``data`` to ``path`` so that ``path`` is either the old file or the whole new one.

    ``data`` may also be an iterable of text pieces (a long file written without holding it whole), or of
    bytes-like pieces with ``binary``.

    A failure part-way (disk full, an exception while writing) leaves no
    half-written file and no temporary file behind.
    """
    path = Path(path)
    mode = "wb" if binary or isinstance(data, bytes) else "w"
    clean_stale(path)
    fd, tmp = tempfile.mkstemp(prefix=f"{_temporary_prefix(path.name)}{os.getpid()}.", suffix=".tmp",
                               dir=path.parent or ".")
    try:
        fh: IO = os.fdopen(fd, "wb") if mode == "wb" else os.fdopen(fd, "w", encoding="utf-8", newline="")
        with fh:
            if isinstance(data, str | bytes):
                fh.write(data)
            else:
                for piece in data:
                    fh.write(piece)
        os.chmod(tmp, _file_mode(path))  # mkstemp makes 0o600 files; others could not read the output
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # someone else's process (or an odd number): leave its file alone
    return True


def _folder_leftovers(folder: Path) -> list[str]:
    """The names in ``folder`` that look like leftovers (``.<name>...tmp``), listed once per process."""
    key = os.path.abspath(folder)
    names = _leftovers.get(key)
    if names is None:
        try:
            with os.scandir(folder) as entries:
                names = [e.name for e in entries if e.name.startswith(".") and e.name.endswith(".tmp")]
        except OSError:
            names = []
        _leftovers[key] = names
    return names


def clean_stale(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files a killed write to ``path`` left behind; returns the ones removed.

    ``.<name>.<pid>.<random>.tmp`` goes when process ``pid`` no longer runs; an older
    ``.<name>.<random>.tmp`` (no process id) when it is older than :data:`STALE_AFTER_S`.  The folder is
    listed at this process's first write there (:func:`_folder_leftovers`); later calls look only at what
    that listing found.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    prefix = _temporary_prefix(path.name)
    removed: list[Path] = []
    with _lock:
        names = _folder_leftovers(folder)
        mine = [n for n in names if n.startswith(prefix)]
        if not mine:
            return removed
        now = time.time()
        for name in mine:
            p = folder / name
            middle = name[len(prefix):-len(".tmp")]
            pid_text = middle.split(".", 1)[0] if "." in middle else ""
            try:
                if pid_text.isdigit():
                    stale = not _alive(int(pid_text))
                else:
                    stale = now - p.stat().st_mtime > STALE_AFTER_S
                if stale:
                    p.unlink()
                    removed.append(p)
                    names.remove(name)
            except FileNotFoundError:
                names.remove(name)
            except OSError:
                continue
    return removed
