"""Bounded reading of a zlib stream: never more bytes than the reader asks for.

The binary formats (``.mck``, ``.mosw``) are one zlib stream.  ``zlib.decompress``
would expand a small bomb to gigabytes before any check; :class:`Inflater`
decompresses only the bytes the reader takes, each count checked first by the
reader against what the header allows, and :meth:`Inflater.finish` checks that
the stream ends there.
"""

from __future__ import annotations

import struct
import zlib

from ..errors import MotionFileError


class Inflater:
    """Take decompressed bytes from ``data`` (a zlib stream) a piece at a time.

    ``what`` names the file kind in errors (e.g. ``"keyframe file"``); ``path`` names the file.
    """

    def __init__(self, data: bytes, path=None, what: str = "file"):
        self._z = zlib.decompressobj()
        self._tail = bytes(data)
        self.path, self.what = path, what
        self.taken = 0  # decompressed bytes handed out so far

    def error(self, reason: str) -> MotionFileError:
        return MotionFileError(f"{self.what} is damaged: {reason}", self.path)

    def take(self, n: int, purpose: str = "data") -> bytes:
        """Exactly ``n`` decompressed bytes, or an error naming ``purpose`` when the stream has fewer."""
        n = int(n)
        if n < 0:
            raise self.error(f"negative size for {purpose}")
        parts, need = [], n
        while need:
            try:
                piece = self._z.decompress(self._tail, min(need, 1 << 24))
            except zlib.error as exc:
                raise self.error(f"its compressed data does not decode ({exc})") from None
            self._tail = self._z.unconsumed_tail
            if not piece:
                raise self.error(f"it ends {need} bytes short in {purpose} (truncated?)")
            parts.append(piece)
            need -= len(piece)
        self.taken += n
        return b"".join(parts)

    def unpack(self, fmt: str, purpose: str = "header"):
        return struct.unpack(fmt, self.take(struct.calcsize(fmt), purpose))

    def finish(self) -> None:
        """Check that the stream ends here: nothing more to decompress, no bytes after it."""
        try:
            extra = self._z.decompress(self._tail, 1)
        except zlib.error as exc:
            raise self.error(f"its compressed data does not decode ({exc})") from None
        if extra or self._z.unconsumed_tail:
            raise self.error("it holds more data than its header describes")
        if not self._z.eof:
            raise self.error("its compressed stream does not end (truncated?)")
        if self._z.unused_data:
            raise self.error(f"{len(self._z.unused_data)} stray bytes follow the compressed stream")
