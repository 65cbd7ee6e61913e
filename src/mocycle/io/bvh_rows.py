"""The frame rows of a long BVH file parsed fast: polars' CSV reader, a chunk of lines at a time.

Text numbers are most of a BVH read.  ``np.loadtxt`` parses about 45 MB/s; polars' CSV reader (the optional
extra ``mocycle[fast]``) about 200 MB/s on one thread, to the same float64 values bit for bit (both round
correctly; ``docs/performance.md`` has the figures and the other parsers measured).  :func:`row_chunks` cuts
the motion block at line ends into pieces of :data:`CHUNK_BYTES`, and parses the next piece in a helper thread
(polars releases the GIL) while the caller converts the one before, so reading takes about the parse alone.

Only plain rows are taken: numbers separated by single spaces (a space at the end of every line allowed),
``\\n`` or ``\\r\\n`` line ends.  Anything else — tabs, runs of spaces, blank lines, a value missing or extra,
text polars refuses, a byte-order mark — raises :class:`Unreadable`, and the reader parses the whole file
the usual way, which accepts every layout and names the line of any error.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Generator

import numpy as np

#: bytes of text parsed at a time (about 12,000 rows of 132 channels)
CHUNK_BYTES = 16 << 20
#: below this much text ``np.loadtxt`` is as fast as importing polars (0.2 s) and parsing with it
MIN_BYTES = 8 << 20
#: the same once polars is imported (a batch of takes, a second read)
MIN_BYTES_IMPORTED = 256 << 10

_BOM = b"\xef\xbb\xbf"


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


def row_chunks(path: str | os.PathLike, offset: int, n_channels: int) -> Generator[np.ndarray, None, None]:
    """The rows from byte ``offset`` of ``path`` on as ``(n, n_channels)`` float64 arrays, in file order.

    Raises :class:`Unreadable` (possibly after some chunks) when the rows are not plain; a null (an empty
    field) comes out as NaN, which the caller's finite check refuses.
    """
    from concurrent.futures import ThreadPoolExecutor

    try:
        import polars as pl
    except ImportError:
        raise Unreadable("polars is not installed") from None
    with open(path, "rb") as fh:
        fh.seek(offset)
        first = fh.readline()
        fh.seek(offset)
        trailing = first.rstrip(b"\r\n").endswith(b" ")  # iClone, Bandai: a space closes every row
        names = [f"c{i}" for i in range(n_channels + trailing)]
        schema = {name: pl.Float64 for name in names}
        rest = [b""]

        def next_piece() -> bytes:
            """The next whole lines, about CHUNK_BYTES of them (``b""`` at the end)."""
            data = rest[0]
            while True:
                block = fh.read(CHUNK_BYTES)
                if not block:
                    rest[0] = b""
                    return data
                data += block
                cut = data.rfind(b"\n") + 1
                if cut:
                    rest[0] = data[cut:]
                    return data[:cut]

        def parse(piece: bytes) -> np.ndarray | None:
            # blank lines closing a piece go (np.loadtxt skips blank lines; polars would make a row of nulls);
            # a row that lost its closing space gets it back (polars counts the fields of the first line)
            piece = piece.rstrip(b" \t\r\n")
            if not piece:
                return None
            if trailing:
                piece += b" "
            if piece.startswith(_BOM):  # polars would skip it; the usual parse refuses it with its line
                raise Unreadable("a byte-order mark")
            try:
                frame = pl.read_csv(piece, has_header=False, separator=" ", schema=schema, quote_char=None)
                if trailing:
                    if frame[names[-1]].null_count() != frame.height:
                        raise Unreadable("a value after the last channel")
                    frame = frame.drop(names[-1])
                return frame.to_numpy()
            except Unreadable:
                raise
            except Exception as exc:  # a polars error, or an API this polars lacks: the usual parse decides
                raise Unreadable(str(exc).splitlines()[0] if str(exc) else type(exc).__name__) from None

        def read_parse() -> np.ndarray | None:
            while True:
                piece = next_piece()
                if not piece:
                    return None
                values = parse(piece)
                if values is not None:
                    return values

        def submit(pool):
            try:
                return pool.submit(read_parse)
            except RuntimeError as exc:  # the interpreter is shutting down (Ctrl-C, SIGTERM): no helper thread
                raise Unreadable(str(exc)) from None

        with ThreadPoolExecutor(max_workers=1, thread_name_prefix="mocycle-bvh-rows") as pool:
            pending = submit(pool)
            while True:
                values = pending.result()
                if values is None:
                    return
                pending = submit(pool)  # the next piece is parsed while the caller converts this one
                yield values
