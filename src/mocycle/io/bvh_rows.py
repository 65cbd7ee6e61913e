"""The frame rows of a long BVH file parsed fast: polars' CSV reader, a chunk of lines at a time.

Text numbers are most of a BVH read. ``np.loadtxt`` parses about 45 MB/s; polars' CSV reader (the optional extra
``mocycle[fast]``) about 200 MB/s on one thread, to the same float64 values bit for bit (both round correctly;
``docs/performance.md`` has the figures and the other parsers measured). :func:`row_chunks` cuts the motion block at
line ends into pieces of :data:`CHUNK_BYTES`, counts their lines (so each piece knows the row it starts at; a piece
is the bytes as read, with no copy: polars is told how many lines to take and the file is sought back to the start
of the line the piece cut), and parses them and runs the caller's conversion on them in :func:`helpers` threads at
once (polars and numpy release the GIL); the caller takes them in order. Polars parses on its own pool, which the
command line sizes to one thread (``POLARS_MAX_THREADS=1``): the pieces' parses then run one after another on that
thread and the conversions beside them on the other core, so a long read takes about as long as the parses alone
(about 1.37 s for the 22-joint hour: 1.27-1.30 times polars' parse of the whole text on two threads; 1.7 times for
CMU's 31 joints, whose conversion costs more than its parse). The first pieces are small (the first parse starts
after a 1 MB read, not a 16 MB one) and so are the last (the last conversion ends a few ms after the last parse, not
one 16 MB conversion later): :func:`piece_bytes`. Polars' pool is global; letting it run two threads here measured
no faster (its threads and the conversions then share the two cores).

Only plain rows are taken: numbers separated by single spaces (a space at the end of every line allowed),
``\\n`` or ``\\r\\n`` line ends.  Anything else — tabs, runs of spaces, a value missing or extra, text polars
refuses, a byte-order mark — raises :class:`Unreadable` (a blank line within the rows becomes a row of NaN,
which the caller's finite check refuses), and the reader parses the whole file the usual way, which accepts
every layout and names the line of any error.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Callable, Generator
from typing import TypeVar

import numpy as np

#: bytes of text parsed at a time (about 12,000 rows of 132 channels)
CHUNK_BYTES = 16 << 20
#: the first and the last pieces are smaller (:func:`piece_bytes`): the first parse starts sooner, and the last
#: pieces' conversions end soon after their parses; down to this share of :data:`CHUNK_BYTES`
SMALL_SHARE = 1 / 16
#: near the end a piece is this share of the rows left: each piece's conversion (about 0.6 of its parse) then
#: ends within the next, smaller piece's parse
TAIL_SHARE = 0.4
#: below this much text ``np.loadtxt`` is as fast as importing polars (0.2 s) and parsing with it
MIN_BYTES = 8 << 20
#: the same once polars is imported (a batch of takes, a second read): a second read of 0.36 MB of rows took 4.4 ms
#: through polars against 3.7 ms by ``np.loadtxt``, of 1.2 MB 7.6 against 10.1 ms (22 joints, one polars thread)
MIN_BYTES_IMPORTED = 1 << 20

T = TypeVar("T")

_BOM = b"\xef\xbb\xbf"
#: bytes compared at a time by :func:`count_lines` (its boolean temporary stays in the cache)
COUNT_BYTES = 1 << 18
_SPACE = frozenset(b" \t\r\n")


class Unreadable(Exception):
    """The rows are not plain single-space-separated numbers polars takes: parse them another way."""


def wanted(n_bytes: int) -> bool:
    """Whether :func:`row_chunks` is worth it for ``n_bytes`` of rows: polars is installed and the text long."""
    if "polars" in sys.modules:
        return n_bytes >= MIN_BYTES_IMPORTED
    return n_bytes >= MIN_BYTES and _installed()


def _installed() -> bool:
    try:
        return importlib.util.find_spec("polars") is not None
    except (ImportError, ValueError):
        return False


def count_lines(block: bytes, stop: int) -> int:
    """The ``\\n`` in ``block[:stop]``: numpy compares a piece at a time, twice as fast as ``bytes.count`` and
    without the GIL, which the helper threads' conversions need meanwhile."""
    codes = np.frombuffer(block, dtype=np.uint8, count=stop)
    hits = np.empty(min(stop, COUNT_BYTES), dtype=bool)
    lines = 0
    for i in range(0, stop, COUNT_BYTES):
        part = codes[i:i + COUNT_BYTES]
        np.equal(part, 10, out=hits[:part.size])
        lines += int(np.count_nonzero(hits[:part.size]))
    return lines


def helpers() -> int:
    """Threads that parse and convert pieces at once: the cores this process may use, 2 to 4."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return min(4, max(2, cores))


def piece_bytes(k: int, left: int) -> int:
    """Bytes to read for the ``k``-th piece (from 0) when ``left`` bytes of rows remain: :data:`CHUNK_BYTES`,
    but doubling up to it from ``SMALL_SHARE`` of it at the start and shrinking by ``1 - TAIL_SHARE`` a piece
    near the end (the rest in one piece once it is small)."""
    small = max(1, int(CHUNK_BYTES * SMALL_SHARE))
    size = min(CHUNK_BYTES, small << min(k, 62), max(small, int(left * TAIL_SHARE)))
    return left if left - size < small else size


def row_chunks(path: str | os.PathLike, offset: int, n_channels: int,
               then: Callable[[int, np.ndarray], T] | None = None) -> Generator[tuple[int, np.ndarray, T | None]]:
    """The rows from byte ``offset`` of ``path`` on, in file order: ``(r0, values, then(r0, values))`` per
    piece, ``values`` its rows ``(n, n_channels)`` (float64) and ``r0`` the row of the take it starts at.

    Pieces are parsed, and ``then`` run on them, in :func:`helpers` threads at once (polars and numpy release
    the GIL); ``then`` must only touch the rows it is given.  Raises :class:`Unreadable` (possibly after
    some pieces) when the rows are not plain; a null (an empty field) comes out as NaN, which the caller's
    finite check refuses.
    """
    from concurrent.futures import ThreadPoolExecutor

    try:
        import polars as pl
    except ImportError:
        raise Unreadable("polars is not installed") from None
    with open(path, "rb") as fh:
        fh.seek(offset)
        names = [f"c{i}" for i in range(n_channels + 1)]
        # polars takes a piece's columns from its first line: a space closing it (iClone, Bandai: a space closes
        # every row, perhaps but the last) is one column more, which must be empty
        schemas = {trailing: {name: pl.Float64 for name in names[:n_channels + trailing]} for trailing in (0, 1)}
        size_of_file = os.fstat(fh.fileno()).st_size
        r0 = 0
        k = 0

        def next_piece() -> tuple[bytes, int] | None:
            """The next piece as read (no copy: polars reads its first ``rows`` lines and no further) and its
            count of whole lines, about :func:`piece_bytes` of them (``None`` at the end).  The file is left at
            the start of the next line."""
            nonlocal k
            at = fh.tell()
            size = piece_bytes(k, size_of_file - at)
            k += 1
            block = fh.read(size)
            if block.startswith(_BOM):  # polars would skip it; the usual parse refuses it with its line
                raise Unreadable("a byte-order mark")
            if at + len(block) < size_of_file:  # more follows: the piece ends at its last line end
                cut = block.rfind(b"\n") + 1
                if not cut and size < CHUNK_BYTES:  # a small piece within one line: read on to a whole piece
                    block += fh.read(CHUNK_BYTES - size)
                    cut = block.rfind(b"\n") + 1
                if not cut:  # a line of 16 MB is no frame row (nor a CR-only file's rows)
                    raise Unreadable("no line end within a piece")
                last = cut - 1
                while last >= 0 and block[last] in _SPACE:
                    last -= 1
                if last >= 0:  # blank lines at the piece's end go to the next piece: they may end the file
                    cut = block.find(b"\n", last) + 1
                if cut < len(block):
                    fh.seek(at + cut)
                return block, count_lines(block, cut)  # a blank line within: a row of nulls (NaN)
            # the last piece: its blank lines at the end go (np.loadtxt skips them; polars would make rows of
            # nulls); its last row may lack a line end
            end = len(block)
            while end and block[end - 1] in _SPACE:
                end -= 1
            if not end:
                return None
            return block, count_lines(block, end) + 1

        def parse(piece: bytes, rows: int, r0: int):
            try:
                line_end = piece.find(b"\n")
                first = (piece if line_end < 0 else piece[:line_end]).rstrip(b"\r")
                trailing = int(first.endswith(b" "))
                frame = pl.read_csv(piece, has_header=False, separator=" ", schema=schemas[trailing],
                                    quote_char=None, n_rows=rows)
                if trailing:
                    if frame[names[-1]].null_count() != frame.height:
                        raise Unreadable("a value after the last channel")
                    frame = frame.drop(names[-1])
                values = frame.to_numpy()
            except Unreadable:
                raise
            except Exception as exc:  # a polars error, or an API this polars lacks: the usual parse decides
                raise Unreadable(str(exc).splitlines()[0] if str(exc) else type(exc).__name__) from None
            if values.shape[0] != rows:  # a line polars read as two
                raise Unreadable(f"{values.shape[0]} rows parsed of {rows} lines")
            return r0, values, None if then is None else then(r0, values)

        def submit(pool):
            nonlocal r0
            got = next_piece()
            if got is None:
                return None
            piece, rows = got
            try:
                future = pool.submit(parse, piece, rows, r0)
            except RuntimeError as exc:  # the interpreter is shutting down (Ctrl-C, SIGTERM): no helper thread
                raise Unreadable(str(exc)) from None
            r0 += rows
            return future

        n_threads = helpers()
        with ThreadPoolExecutor(max_workers=n_threads, thread_name_prefix="mocycle-bvh-rows") as pool:
            pending = []
            try:
                # one piece more than threads: a thread is never idle while the caller takes a piece
                for _ in range(n_threads + 1):
                    future = submit(pool)
                    if future is None:
                        break
                    pending.append(future)
                while pending:
                    done = pending.pop(0).result()
                    future = submit(pool)
                    if future is not None:
                        pending.append(future)
                    yield done
            finally:
                for future in pending:
                    future.cancel()
