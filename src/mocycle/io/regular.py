"""Opening a file that a file names, or that a folder holds, as a reader may: regular files only, never
blocking, never more bytes than a bound.

A path can name a FIFO (``open`` waits for a writer for ever), a device (``/dev/zero`` never ends), a socket
or a file far larger than anything a reader should hold.  :func:`open_regular` opens without blocking
(``O_NONBLOCK``: a FIFO opens at once) and looks at what it opened (``fstat``, so a file swapped for a FIFO
after a first look is still caught); :func:`read_regular` then reads at most ``limit`` bytes, after checking
the file's size against it.  Errors are :class:`~mocycle.errors.MotionFileError` naming ``path``.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ..errors import MotionFileError

__all__ = ["open_regular", "read_regular"]

_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0) \
    | getattr(os, "O_BINARY", 0)


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device"


def open_regular(path: str | os.PathLike, what: str = "the file", report=None) -> tuple[int, int]:
    """``(fd, size)`` of the regular file ``path``, opened read-only without blocking; the caller closes ``fd``.

    what : how messages name it (``"buffers[0]'s file"``); report : the path messages name (default ``path``).
    """
    report = path if report is None else report
    try:
        before = os.stat(path)  # a look first: a device is not even opened
        if not stat.S_ISREG(before.st_mode):
            raise MotionFileError(f"{what} is {_kind(before.st_mode)}, not a regular file", report)
        fd = os.open(path, _FLAGS)
    except OSError as exc:
        raise MotionFileError(f"cannot read {what} ({exc.strerror or exc})", report) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):  # swapped since the first look
            raise MotionFileError(f"{what} is {_kind(st.st_mode)}, not a regular file", report)
        os.set_blocking(fd, True)
    except BaseException:
        os.close(fd)
        raise
    return fd, st.st_size


def read_regular(path: str | os.PathLike, limit: int, what: str = "the file", report=None, *,
                 exact: int | None = None) -> bytearray:
    """The bytes of the regular file ``path`` (a ``bytearray``: no second copy): all of them (at most ``limit``,
    else an error before reading), or its first ``exact`` bytes (an error when it holds fewer)."""
    report = Path(path) if report is None else report
    fd, size = open_regular(path, what, report)
    with os.fdopen(fd, "rb", buffering=0) as fh:
        if exact is not None:
            if exact > limit:
                raise MotionFileError(f"{what}: {exact:,} bytes asked for; at most {limit:,} are read", report)
            if size < exact:
                raise MotionFileError(f"{what} holds {size:,} bytes; {exact:,} expected (truncated?)", report)
            want = exact
        else:
            if size > limit:
                raise MotionFileError(f"{what} holds {size:,} bytes; at most {limit:,} are read", report)
            want = size
        try:
            data = _read_exactly(fh, want)
        except OSError as exc:
            raise MotionFileError(f"cannot read {what} ({exc.strerror or exc})", report) from None
    if len(data) < want:
        raise MotionFileError(f"{what} changed while it was read (it holds {len(data):,} bytes now)", report)
    return data


def _read_exactly(fh, n: int) -> bytearray:
    """Up to ``n`` bytes (fewer only at the end of the file), never more."""
    out = bytearray(n)
    view = memoryview(out)
    got = 0
    while got < n:
        k = fh.readinto(view[got:])
        if not k:
            break
        got += k
    del view
    if got < n:
        del out[got:]
    return out
