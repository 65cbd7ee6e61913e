"""An FBX file looked at before any FBX loader reads it: regular files only, and no deflate bombs.

A binary FBX stores its arrays (vertices, key times, key values) as ``arrayLength``, ``encoding`` (0 raw, 1
zlib) and ``compressedLength``, then the bytes.  A zlib stream inflates up to about 1000 times: 300 million zero
doubles (2.4 GB) fit in a 2.3 MB file, and a loader that inflates what the file declares takes gigabytes.
:func:`declared_bytes` walks the node records and sums what every array would decode to, reading the record
and array headers only (nothing is decompressed; the file is memory-mapped, not read into memory), and
:func:`check_arrays` refuses a file whose arrays exceed :func:`array_budget` before the loader sees it.  An ASCII
FBX cannot hide a bomb: its numbers are text, at least two characters a value (a digit and a comma) for at most
8 bytes in memory, so its arrays hold at most :data:`ASCII_BYTES_PER_CHAR` bytes per byte of the file (and ufbx
does not allocate an ASCII array's declared ``*N`` ahead of its values).

:func:`opened` is what :mod:`.fbx` calls: it opens the file without blocking (a FIFO or device is refused, not
waited on), checks its arrays, and gives the loader a name for the very file checked (``/proc/self/fd/N`` where
there is one: any file name, also one that is not UTF-8, and no swap between the check and the load).
"""

from __future__ import annotations

import contextlib
import mmap
import os
import struct
from collections.abc import Iterator
from pathlib import Path

from ..errors import MotionFileError
from .regular import open_regular

__all__ = ["ASCII_BYTES_PER_CHAR", "array_budget", "check_arrays", "declared_bytes", "opened"]

MAGIC = b"Kaydara FBX Binary  \x00"
#: the arrays of any FBX file may decode to this many bytes ...
BUDGET_FLOOR = 256 << 20
#: ... or this many times the file's size, when that is more ...
BUDGET_RATIO = 32
#: ... but never more than this
BUDGET_CAP = 4 << 30
#: bytes an ASCII FBX's arrays may hold per byte of text, at most (a value: 8 bytes, two characters at least)
ASCII_BYTES_PER_CHAR = 4

_SCALARS = {ord("Y"): 2, ord("C"): 1, ord("B"): 1, ord("I"): 4, ord("F"): 4, ord("D"): 8, ord("L"): 8}
_ARRAYS = {ord("f"): 4, ord("d"): 8, ord("l"): 8, ord("i"): 4, ord("b"): 1, ord("c"): 1}
_SIZED = (ord("S"), ord("R"))


def array_budget(file_bytes: int) -> int:
    """The bytes the arrays of an FBX file of ``file_bytes`` bytes may decode to: 256 MiB, or 32 times the
    file when that is more, at most 4 GiB."""
    return min(max(BUDGET_FLOOR, BUDGET_RATIO * file_bytes), BUDGET_CAP)


class _Damaged(Exception):
    """The records do not fit together (a record past its parent's end, a property past its record)."""


def declared_bytes(data, budget: int | None = None) -> tuple[int, str]:
    """``(bytes, where)``: what the arrays of the binary FBX ``data`` (bytes-like) would decode to together, and
    the largest array (``"Vertices at byte 1234: 300,000,000 values"``).  Stops early once past ``budget``.
    An ASCII FBX: :data:`ASCII_BYTES_PER_CHAR` times its size (an upper bound; nothing is parsed).  Raises
    :class:`_Damaged` for records that do not fit together."""
    size = len(data)
    if bytes(data[:len(MAGIC)]) != MAGIC:
        return ASCII_BYTES_PER_CHAR * size, "the ASCII file's text"
    if size < 27:
        raise _Damaged("the header is cut short")
    version = struct.unpack_from("<I", data, 23)[0]
    wide = version >= 7500
    head = struct.Struct("<QQQB" if wide else "<IIIB")
    total, largest, where = 0, -1, "no array"
    pos = 27
    ends: list[int] = [size]  # the end of each record list being read (the file, then each open record)
    while True:
        if len(ends) > 1 and pos == ends[-1]:  # a record's children ran to its end without a closing record
            ends.pop()
            continue
        if pos + head.size > ends[-1]:
            if len(ends) == 1:
                break  # the top level ran to the end of the file without its closing record: the loader decides
            raise _Damaged(f"the record at byte {pos} runs past its parent's end (byte {ends[-1]})")
        end, n_props, props_len, name_len = head.unpack_from(data, pos)
        if end == 0 and n_props == 0 and props_len == 0 and name_len == 0:  # the record closing a list
            if len(ends) == 1:
                break  # the top level's: the footer follows
            if pos + head.size != ends[-1]:
                raise _Damaged(f"a closing record at byte {pos} is not at its parent's end (byte {ends[-1]})")
            pos = ends.pop()
            continue
        props_at = pos + head.size + name_len
        props_end = props_at + props_len
        if not pos < end <= ends[-1] or props_end > end:
            raise _Damaged(f"the record at byte {pos} claims to end at byte {end}")
        name = bytes(data[pos + head.size:props_at]).decode("latin-1")
        at = props_at
        for _ in range(min(n_props, props_len)):
            if at >= props_end:
                break
            code = data[at]
            at += 1
            if code in _SCALARS:
                at += _SCALARS[code]
            elif code in _SIZED:
                if at + 4 > props_end:
                    raise _Damaged(f"a property of {name} at byte {at} runs past its record")
                at += 4 + struct.unpack_from("<I", data, at)[0]
            elif code in _ARRAYS:
                if at + 12 > props_end:
                    raise _Damaged(f"an array of {name} at byte {at} runs past its record")
                count, encoding, stored = struct.unpack_from("<III", data, at)
                decoded = count * _ARRAYS[code]
                total += decoded if encoding else min(decoded, stored)
                if decoded > largest:
                    largest, where = decoded, f"{name} at byte {at - 1}: {count:,} values"
                at += 12 + stored
                if budget is not None and total > budget:
                    return total, where
            else:
                break  # a type this scan does not know: the rest of the list is skipped (the loader judges it)
        if at > props_end:
            raise _Damaged(f"a property of {name} runs past the end of its record (byte {props_end})")
        if props_end < end:  # children follow the properties
            ends.append(end)
            pos = props_end
        else:
            pos = end
    return total, where


def check_arrays(data, path, size: int | None = None) -> None:
    """Refuse (one :class:`MotionFileError`) an FBX file whose arrays would decode to more than
    :func:`array_budget` of its size, or whose records do not fit together (so no array can hide behind them)."""
    size = len(data) if size is None else size
    budget = array_budget(size)
    try:
        total, where = declared_bytes(data, budget)
    except _Damaged as exc:
        raise MotionFileError(f"not a readable FBX file ({exc})", path) from None
    if total > budget:
        raise MotionFileError(f"its arrays would decode to {total:,} bytes or more (the largest: {where}); an FBX "
                              f"file of {size:,} bytes is read only when they hold at most {budget:,} (a deflate "
                              f"bomb?)", path)


@contextlib.contextmanager
def opened(path: str | os.PathLike) -> Iterator[str]:
    """The FBX file ``path`` opened and checked (:func:`check_arrays`); yields the name a loader should open:
    ``/proc/self/fd/N`` of the file checked where the system has it, else ``path`` itself."""
    p = Path(path)
    fd, size = open_regular(p, "the file")
    try:
        if size:
            with mmap.mmap(fd, 0, access=mmap.ACCESS_READ) as view:
                check_arrays(view, p, size)
        by_fd = f"/proc/self/fd/{fd}"
        yield by_fd if os.path.exists(by_fd) else os.fspath(p)
    finally:
        os.close(fd)
