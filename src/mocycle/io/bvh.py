"""BVH read and write, faithful and tolerant.

Reading accepts what real exporters write: tabs or spaces, CRLF or CR-only
line ends, ``End Site`` / ``End site`` with or without a name, joint names
with spaces, 0-, 3- and 6-channel joints, position channels on any joint,
per-joint Euler orders, and a ``Frames:`` count that disagrees with the rows
(a :class:`~mocycle.errors.MocycleWarning`, the rows win).  Anything else
raises :class:`~mocycle.errors.MotionFileError` naming the file, the line and
what was expected.

Writing keeps each joint's channel order and the End Sites, writes the exact
frame time and Euler angles that are continuous in time, and replaces the
target file in one step (never a half-written file).

:func:`read_bvh` reads the hierarchy line by line, then the frame rows: a long file's by polars' CSV reader
a chunk at a time when the extra ``mocycle[fast]`` is installed (:mod:`.bvh_rows`: the chunks parsed and
converted to quaternions in helper threads at once, one per core), others by numpy's C ``loadtxt``; the rows
become quaternions as they come (:mod:`.bvh_channels`), so a long read takes about polars' parse with its
threads, and 1.1-1.2 times ``loadtxt`` without polars (``docs/performance.md``).  When
anything is off (a warning, an error, a line the parser cannot take), the whole file is parsed again the
careful way (:func:`parse_bvh`), which says what is wrong where.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import re
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import NoReturn

import numpy as np

from ..errors import MocycleError, MocycleWarning, MotionFileError
from ..limits import MAX_MAGNITUDE, check_frames, frame_time_problem
from ..motion import POSITION_CHANNELS, ROTATION_CHANNELS, EndSite, Motion, Skeleton
from ..rotations import continuous_euler_blocks
from . import bvh_rows
from .atomic import atomic_write
from .bvh_channels import ChannelConverter
from .bvh_channels import channel_layout as _channel_layout

_CHANNEL_NAMES = {c.lower(): c for c in ROTATION_CHANNELS + POSITION_CHANNELS}


def read_bvh(path: str | os.PathLike) -> Motion:
    """Read a BVH file into a :class:`Motion` (see module notes for what is accepted)."""
    p = Path(path)
    try:
        fast = _read_plain(p)
        if fast is None:  # something to warn about or refuse: the careful parse says what and where
            return parse_bvh(p.read_bytes(), path=p)
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", p) from None
    skel, frame_time, (quats, static, tracks) = fast
    return _motion(skel, quats, static, tracks, frame_time, p)


def _read_plain(p: Path):
    """A well-formed file read fast: the hierarchy from its lines, the frame rows by polars a chunk at a time
    (:mod:`.bvh_rows`, for long files when polars is installed) or by ``np.loadtxt(path)``, converted as they
    come (:class:`~.bvh_channels.ChannelConverter`).

    Returns (skeleton, frame time, (quaternions, constant translations, tracks)), or ``None`` when the file
    needs the careful parse: a header error or warning, no channels, a row ``loadtxt`` refuses, or a value
    that is not finite or beyond ``MAX_MAGNITUDE``.  When the rows' count differs from ``Frames:`` the rows
    win, with a warning.
    """
    head = []
    with open(p, "rb") as fh:
        for raw in fh:
            head.append(raw)
            if raw.strip().lower().replace(b" ", b"").replace(b"\t", b"").startswith(b"frametime"):
                break
        else:
            return None
    lines = _decode(b"".join(head)).split("\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            skel, frames, frame_time, data_start = _parse_header(lines, p)
        except MotionFileError:
            return None
    if caught or skel.n_channels == 0:
        return None
    converter = None
    if frames and data_start == len(head):  # the data's first byte is where the header's lines end
        converter = _read_chunks(p, sum(map(len, head)), skel, frames)
    if converter is None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")  # "input contained no data" and the like: the careful parse
                values = np.loadtxt(p, dtype=np.float64, ndmin=2, comments=None, skiprows=data_start,
                                    encoding="latin-1")
        except (ValueError, UserWarning):
            return None
        if values.shape[0] == 0 or values.shape[1] != skel.n_channels:
            return None
        converter = ChannelConverter(skel, values.shape[0])
        if not converter.add(values):
            return None
        del values  # the channel array goes before the motion is made: lower peak memory
    rows = converter.rows
    if frames is not None and frames != rows:
        warnings.warn(f"{p}: 'Frames: {frames}' but {rows} frame rows follow; using the {rows} rows",
                      MocycleWarning, stacklevel=3)
    return skel, frame_time, converter.arrays()


def _read_chunks(p: Path, offset: int, skel: Skeleton, frames: int) -> ChannelConverter | None:
    """The rows from byte ``offset`` on parsed by polars and converted a chunk at a time into arrays of the
    ``Frames:`` count (allocated only when that count fits the bytes present and ``MOCYCLE_MAX_FRAMES``), or
    ``None``: a short file, no polars, rows it does not take or more rows than ``Frames:`` says (the caller
    reads the file the other way)."""
    size = p.stat().st_size - offset
    if not bvh_rows.wanted(size) or frames > size // (2 * skel.n_channels):  # a value is 2 bytes at least
        return None
    try:
        check_frames(frames, skel.n_joints)
    except MocycleError:
        return None
    converter = ChannelConverter(skel, frames)
    try:
        # pieces parsed and their rotations converted in threads at once, taken here in order
        with contextlib.closing(bvh_rows.row_chunks(p, offset, skel.n_channels, then=converter.convert)) as chunks:
            for r0, values, converted in chunks:
                if converted is None or not converter.commit(r0, values, converted):
                    return None
    except bvh_rows.Unreadable:
        return None
    return converter if converter.rows else None


def _plain_numbers(values: np.ndarray) -> bool:
    """All finite and within ±MAX_MAGNITUDE (two reductions, no temporary array: NaN propagates)."""
    if values.size == 0:
        return True
    high, low = values.max(), values.min()
    return bool(np.isfinite(high) and np.isfinite(low) and max(high, -low) <= MAX_MAGNITUDE)


def _decode(data: str | bytes) -> str:
    if isinstance(data, str):
        text = data
    else:
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError:
            text = data.decode("latin-1")
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    return text


class _Header:
    """Line-by-line parser of the HIERARCHY section."""

    def __init__(self, path) -> None:
        self.path = path
        self.names: list[str] = []
        self.known: set[str] = set()
        self.parents: list[int] = []
        self.offsets: list[tuple[float, float, float] | None] = []
        self.channels: list[tuple[str, ...]] = []
        self.end_sites: list[EndSite] = []
        self.stack: list[tuple[str, int]] = []  # ("joint", index) or ("end", parent index)
        self.pending: tuple[str, int, str | None] | None = None  # node waiting for "{"
        self.end_offset: tuple[float, float, float] | None = None

    def error(self, lineno: int, message: str) -> MotionFileError:
        return MotionFileError(message, self.path, lineno)

    def numbers(self, lineno: int, words: list[str], n: int, what: str) -> tuple[float, ...]:
        if len(words) != n:
            raise self.error(lineno, f"expected {n} numbers after {what}, found {len(words)}")
        try:
            vals = tuple(float(w) for w in words)
        except ValueError:
            raise self.error(lineno, f"expected {n} numbers after {what}, found {' '.join(words)!r}") from None
        if not all(map(math.isfinite, vals)) or max(map(abs, vals)) > MAX_MAGNITUDE:
            raise self.error(lineno, f"{what} values must be finite numbers within ±{MAX_MAGNITUDE:g}, "
                                     f"found {' '.join(words)!r}")
        return vals

    def open_node(self, lineno: int):
        if self.pending is None:
            raise self.error(lineno, "found '{' without a ROOT, JOINT or End Site before it")
        kind, parent, name = self.pending
        self.pending = None
        if kind == "end":
            self.stack.append(("end", parent))
            self.end_offset = None
            self._end_name = name
            return
        if len(self.names) != 0 and not self.stack:
            raise self.error(lineno, "found a second ROOT; only one skeleton per file is supported")
        assert name is not None  # a ROOT or JOINT line always names its joint
        self.names.append(name)
        self.parents.append(parent)
        self.offsets.append(None)
        self.channels.append(())
        self.stack.append(("joint", len(self.names) - 1))

    def close_node(self, lineno: int):
        if not self.stack:
            raise self.error(lineno, "found '}' with no open ROOT, JOINT or End Site")
        kind, idx = self.stack.pop()
        if kind == "end":
            if self.end_offset is None:
                raise self.error(lineno, "End Site has no OFFSET")
            self.end_sites.append(EndSite(idx, self.end_offset, self._end_name))
        elif self.offsets[idx] is None:
            raise self.error(lineno, f"joint {self.names[idx]!r} has no OFFSET")

    def line(self, lineno: int, raw: str):
        s = raw.strip()
        if not s:
            return
        opens = closes = 0
        while s.endswith("{") and len(s) > 1:
            opens += 1
            s = s[:-1].rstrip()
        words = s.split()
        key = words[0].upper()
        if self.pending is not None and s != "{":
            raise self.error(lineno, f"expected '{{' after {self.pending[0].upper()}, found {s!r}")
        if s == "{":
            opens += 1
        elif s == "}":
            closes += 1
        elif key in ("ROOT", "JOINT"):
            name = s[len(words[0]):].strip()
            if not name:
                raise self.error(lineno, f"expected a joint name after {words[0]}")
            if key == "ROOT" and (self.names or self.stack):
                raise self.error(lineno, "found a second ROOT; only one skeleton per file is supported")
            if key == "JOINT" and not (self.stack and self.stack[-1][0] == "joint"):
                raise self.error(lineno, "JOINT outside of a ROOT or JOINT block")
            if name in self.known:
                raise self.error(lineno, f"joint name {name!r} is used twice")
            self.known.add(name)
            parent = self.stack[-1][1] if self.stack else -1
            self.pending = ("joint", parent, name)
        elif key == "END" and len(words) >= 2 and words[1].upper() == "SITE":
            if not (self.stack and self.stack[-1][0] == "joint"):
                raise self.error(lineno, "End Site outside of a JOINT block")
            site_name = s.split(None, 2)[2].strip() if len(words) > 2 else None
            self.pending = ("end", self.stack[-1][1], site_name)
        elif key == "OFFSET":
            if not self.stack:
                raise self.error(lineno, "OFFSET outside of a ROOT, JOINT or End Site block")
            x, y, z = self.numbers(lineno, words[1:], 3, "OFFSET")
            vals = (x, y, z)
            kind, idx = self.stack[-1]
            if kind == "end":
                self.end_offset = vals
            else:
                self.offsets[idx] = vals
        elif key == "CHANNELS":
            if not self.stack or self.stack[-1][0] != "joint":
                raise self.error(lineno, "CHANNELS outside of a ROOT or JOINT block")
            try:
                n = int(words[1]) if len(words) > 1 and words[1].isascii() else -1
            except ValueError:
                n = -1
            if n < 0:
                raise self.error(lineno, "expected the channel count after CHANNELS")
            names = words[2:]
            if len(names) != n:
                raise self.error(lineno, f"CHANNELS says {n} channels but lists {len(names)}")
            try:
                chans = tuple(_CHANNEL_NAMES[c.lower()] for c in names)
            except KeyError as exc:
                raise self.error(
                    lineno, f"unknown channel {exc.args[0]!r}; expected X/Y/Z position or rotation"
                ) from None
            if len(set(chans)) != n:
                raise self.error(lineno, f"a channel is listed twice: {' '.join(names)}")
            self.channels[self.stack[-1][1]] = chans
        else:
            raise self.error(lineno, f"expected ROOT, JOINT, End Site, OFFSET, CHANNELS, '{{' or '}}', found {s!r}")
        for _ in range(opens):
            self.open_node(lineno)
        for _ in range(closes):
            self.close_node(lineno)

    def skeleton(self, lineno: int) -> Skeleton:
        if self.pending is not None or self.stack:
            raise self.error(lineno, "hierarchy ends before every '{' is closed; expected '}'")
        if not self.names:
            raise self.error(lineno, "no ROOT joint in HIERARCHY")
        try:
            # every joint has its OFFSET by now (close_node refuses one without)
            return Skeleton(tuple(self.names), np.asarray(self.parents), np.asarray(self.offsets, dtype=np.float64),
                            tuple(self.channels),
                            tuple(self.end_sites))
        except MocycleError as exc:
            raise self.error(lineno, str(exc)) from None


def _motion_header(lines: list[str], first: int, path) -> tuple[int | None, float, int]:
    """Parse ``Frames:`` and ``Frame Time:``; return (frames, frame time, index of first data line)."""
    frames: int | None = None
    i = first
    n = len(lines)
    while i < n and not lines[i].strip():
        i += 1
    if i < n and lines[i].strip().lower().startswith("frames"):
        key, _, val = lines[i].partition(":")
        try:
            frames = int(val.strip())
        except ValueError:
            raise MotionFileError(f"expected 'Frames: <count>', found {lines[i].strip()!r}", path, i + 1) from None
        i += 1
        while i < n and not lines[i].strip():
            i += 1
    else:
        warnings.warn(f"{path or 'BVH'}:{i + 1}: no 'Frames:' line; counting the rows", MocycleWarning, stacklevel=3)
    if i >= n or not lines[i].strip().lower().replace(" ", "").startswith("frametime"):
        raise MotionFileError("expected 'Frame Time: <seconds>' after MOTION", path, min(i, n - 1) + 1)
    key, _, val = lines[i].partition(":")
    try:
        frame_time = float(val.strip())
    except ValueError:
        raise MotionFileError(f"expected 'Frame Time: <seconds>', found {lines[i].strip()!r}", path, i + 1) from None
    if not np.isfinite(frame_time) or frame_time <= 0:
        raise MotionFileError(f"Frame Time must be a positive number of seconds, found {val.strip()!r}", path, i + 1)
    problem = frame_time_problem(frame_time)
    if problem:
        raise MotionFileError(f"{problem} (Frame Time: {val.strip()})", path, i + 1)
    return frames, frame_time, i + 1


def _parse_rows(lines: list[str], start: int, n_channels: int, path) -> np.ndarray:
    """The data rows as a ``(T, C)`` float array; errors name the first bad line.

    numpy's C ``loadtxt`` does the work (blank lines are skipped); only when it
    fails are the lines scanned one by one to say which line is wrong and why.
    """
    body = lines[start:]
    values = None
    if n_channels:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "input contained no data": handled below
                values = np.loadtxt(body, dtype=np.float64, ndmin=2, comments=None)
        except ValueError:
            values = None
    if values is None or values.shape[1] != n_channels or not _plain_numbers(values):
        _find_bad_row(body, start, n_channels, path)
    if values.shape[0] == 0:
        raise MotionFileError("no frame rows after 'Frame Time:'; expected at least one", path, len(lines))
    return values


def _find_bad_row(body: list[str], start: int, n_channels: int, path) -> NoReturn:
    """Raise the error for the first malformed frame row."""
    for k, line in enumerate(body):
        words = line.split()
        if not words:
            continue
        if len(words) != n_channels:
            raise MotionFileError(
                f"expected {n_channels} values in this frame row (one per channel), found {len(words)}",
                path, start + k + 1,
            )
        for word in words:
            try:  # the same numbers loadtxt takes: ASCII, no digit separators
                v = float(word) if word.isascii() and "_" not in word else np.nan
            except ValueError:
                v = np.nan
            if not np.isfinite(v) or abs(v) > MAX_MAGNITUDE:
                raise MotionFileError(f"expected a finite number within ±{MAX_MAGNITUDE:g}, found {word!r}",
                                      path, start + k + 1)
    if n_channels == 0:
        raise MotionFileError("the hierarchy declares no channels; nothing to read", path, start)
    raise MotionFileError("no frame rows after 'Frame Time:'; expected at least one", path, start)


def parse_bvh(data: str | bytes, path: str | os.PathLike | None = None) -> Motion:
    """Parse BVH text (``str`` or ``bytes``) into a :class:`Motion`; ``path`` only names errors."""
    text = _decode(data)
    lines = text.split("\n")
    skel, frames, frame_time, data_start = _parse_header(lines, path)
    if skel.n_channels == 0:  # nothing moves: the Frames: count is all there is
        if not frames or frames < 1:
            raise MotionFileError("the hierarchy declares no channels and 'Frames:' gives no count", path,
                                  data_start)
        # no row holds data, so the count is only a claim: bound it like a size asked for by an option
        check_frames(frames, skel.n_joints, f"'Frames: {frames}' with no channels", path, data_start - 1)
        return _motion_from_channels(skel, np.zeros((frames, 0)), frame_time, path)
    values = _parse_rows(lines, data_start, skel.n_channels, path)
    T = values.shape[0]
    if frames is not None and frames != T:
        warnings.warn(
            f"{path or 'BVH'}: 'Frames: {frames}' but {T} frame rows follow; using the {T} rows",
            MocycleWarning, stacklevel=2,
        )
    return _motion_from_channels(skel, values, frame_time, path)


def _parse_header(lines: list[str], path) -> tuple[Skeleton, int | None, float, int]:
    """The hierarchy and the MOTION header: (skeleton, Frames: count or None, frame time, first data line)."""
    first = next((i for i, ln in enumerate(lines) if ln.strip()), None)
    if first is None:
        raise MotionFileError("file is empty; expected 'HIERARCHY'", path, 1)
    if lines[first].strip().upper() != "HIERARCHY":
        raise MotionFileError(f"expected 'HIERARCHY', found {lines[first].strip()[:40]!r}", path, first + 1)
    header = _Header(path)
    motion_line = None
    for i in range(first + 1, len(lines)):
        if lines[i].strip().upper() == "MOTION":
            motion_line = i
            break
        header.line(i + 1, lines[i])
    if motion_line is None:
        header.skeleton(len(lines))
        raise MotionFileError("no MOTION section; expected 'MOTION' after the hierarchy", path, len(lines))
    skel = header.skeleton(motion_line + 1)
    frames, frame_time, data_start = _motion_header(lines, motion_line + 1, path)
    return skel, frames, frame_time, data_start


def _motion_from_channels(skel: Skeleton, values: np.ndarray, frame_time: float, path=None) -> Motion:
    return _motion(skel, *_arrays_from_channels(skel, values), frame_time, path)


def _arrays_from_channels(skel: Skeleton, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
    """Local unit, sign-continuous quaternions ``(T, J, 4)``, constant translations ``(J, 3)`` and the
    ``{joint: (T, 3)}`` tracks of the joints whose position channels change, from the checked channel values
    ``(T, C)`` (finite, within ``MAX_MAGNITUDE``): :class:`~.bvh_channels.ChannelConverter` in one chunk."""
    converter = ChannelConverter(skel, values.shape[0])
    if not converter.add(values):
        raise MocycleError(f"channel values must be finite numbers within ±{MAX_MAGNITUDE:g}")
    return converter.arrays()


def _motion(skel: Skeleton, quats: np.ndarray, static: np.ndarray, tracks: dict, frame_time: float, path) -> Motion:
    """The motion, owning the arrays :func:`_arrays_from_channels` made (frozen, not copied or checked again:
    the values were checked when read)."""
    try:
        return Motion._adopt(skel, quats, static, tracks, frame_time)
    except MocycleError as exc:
        raise MotionFileError(f"cannot build a motion from this file: {exc}", path) from None


def channel_blocks(motion: Motion, block: int = 8192) -> Iterator[tuple[slice, np.ndarray]]:
    """The BVH channel values of ``motion`` in file order (degrees, continuous over the take) a block of
    ``block`` frames at a time: yields ``(rows, values (n, C))``, holding no ``(T, C)`` or ``(T, N, 3)`` array
    (each Euler order's angles come from :func:`~mocycle.rotations.continuous_euler_blocks`)."""
    skel = motion.skeleton
    positions: list[tuple[list[int], int, list[int]]] = []
    by_order: dict[str, list[tuple[int, list[int]]]] = {}
    for j, (rot_cols, order, pos_cols, pos_axes) in enumerate(_channel_layout(skel)):
        if rot_cols:
            by_order.setdefault(order, []).append((j, rot_cols))
        if pos_cols:
            positions.append((pos_cols, j, pos_axes))
    angles = [([c for _, cs in items for c in cs],
               continuous_euler_blocks(motion.rotations, order, [j for j, _ in items], block))
              for order, items in by_order.items()]
    for f0 in range(0, motion.n_frames, block):
        rows = slice(f0, min(motion.n_frames, f0 + block))
        out = np.empty((rows.stop - f0, skel.n_channels))
        for cols, j, axes in positions:
            out[:, cols] = motion.joint_translations(j)[rows][:, axes]
        for cols, blocks in angles:
            _, a = next(blocks)
            out[:, cols] = np.degrees(a, out=a).reshape(len(out), -1)
        yield rows, out


def motion_channels(motion: Motion) -> np.ndarray:
    """The BVH channel values ``(T, C)`` of ``motion`` in file order (degrees, continuous)."""
    out = np.empty((motion.n_frames, motion.skeleton.n_channels))
    for rows, values in channel_blocks(motion):
        out[rows] = values
    return out


def _fmt(x: float) -> str:
    return f"{x:.9g}"


def _rows_text(block: np.ndarray) -> str:
    """The lines of the channel values ``block`` ``(n, C)``, ``%.9g`` each, space-separated (the text of
    ``np.savetxt(fmt="%.9g", delimiter=" ")``), with one ``%`` over the whole block; a column that holds one
    value throughout (a joint's constant position channels) is formatted once, into the line's format."""
    same = (block == block[0]).all(axis=0)
    line = " ".join(_fmt(v) if constant else "%.9g"
                    for v, constant in zip(block[0].tolist(), same.tolist(), strict=True))
    return ((line + "\n") * block.shape[0]) % tuple(block[:, ~same].ravel().tolist())


def format_bvh(motion: Motion) -> str:
    """The BVH text of ``motion`` (written without recursion: any depth of hierarchy)."""
    return "".join(bvh_chunks(motion))


def bvh_size(motion: Motion) -> int:
    """Bytes of the BVH file of ``motion`` (counted piece by piece, without holding the text)."""
    with warnings.catch_warnings():  # a size: the writer says what it changes
        warnings.simplefilter("ignore")
        return sum(len(piece.encode("utf-8")) for piece in bvh_chunks(motion))


#: Tabs of indentation at most (readers go by the braces; past this depth every level is indented alike).
MAX_INDENT = 32
#: Frames per piece of text :func:`bvh_chunks` yields.
_ROWS_PER_CHUNK = 1024  # the text of 1024 rows of 69 channels: about 1 MB (a StringIO holds 4 bytes a character)


#: what a BVH joint or End Site name cannot hold: braces (read as the hierarchy's), control characters (a line
#: break ends the name), text that is no Unicode (a lone surrogate: the file is UTF-8)
_NOT_IN_A_NAME = re.compile("[{}\x00-\x1f\x7f\ud800-\udfff]")
_IN_PLACE = {"{": "(", "}": ")"}


def _bvh_name(name: str, one_word: bool = True) -> str:
    def one(match: re.Match) -> str:
        c = match.group()
        return _IN_PLACE.get(c, "\ufffd" if "\ud800" <= c <= "\udfff" else "_")

    held = _NOT_IN_A_NAME.sub(one, name)
    return ("_".join(held.split()) if one_word else held.strip()) or "_"  # one word: white space inside to "_"


def bvh_skeleton(skeleton: Skeleton, one_word: bool = True) -> Skeleton:
    """``skeleton`` with joint and End Site names a BVH file holds and reads back as they are: ``{``/``}`` as
    ``(``/``)``, control characters as ``_``, lone surrogates as U+FFFD, no space at either end, and with
    ``one_word`` white space inside as ``_`` (most BVH readers split a line at spaces); one warning saying
    which (:func:`mocycle.text.renamed`); the same skeleton when every name is fine."""
    from ..text import renamed

    sites = [s.name for s in skeleton.end_sites if s.name is not None]
    if not any(_NOT_IN_A_NAME.search(n) or (one_word and len(n.split()) != 1) or n != n.strip() or not n
               for n in (*skeleton.names, *sites)):
        return skeleton
    names = renamed(list(skeleton.names) + sites, lambda n: _bvh_name(n, one_word),
                    "BVH (one word each)" if one_word else "BVH")
    joints, site_names = names[:skeleton.n_joints], iter(names[skeleton.n_joints:])
    end_sites = tuple(EndSite(s.parent, s.offset, next(site_names) if s.name is not None else None)
                      for s in skeleton.end_sites)
    return Skeleton(tuple(joints), skeleton.parents, skeleton.offsets, skeleton.channels, end_sites)


def one_word_names(skeleton: Skeleton) -> tuple[list[str], list[str | None], list[tuple[str, str]]]:
    """Joint and End Site names as one word each, which every BVH reader takes (most split a line at white
    space): white space inside a name becomes ``_`` (``bras droit`` -> ``bras_droit``), an empty name
    ``joint<j>``, and a joint name that then repeats another gets ``_2``, ``_3``.  Returns (joint names, End
    Site names, the ``(name, written)`` pairs that changed)."""
    taken: set[str] = set()
    joints, changed = [], []
    for j, name in enumerate(skeleton.names):
        word = "_".join(name.split()) or f"joint{j}"
        if word != name or word in taken:
            base, k = word, 2
            while word in taken or (word != name and word in skeleton.names):
                word, k = f"{base}_{k}", k + 1
        taken.add(word)
        joints.append(word)
        if word != name:
            changed.append((name, word))
    sites: list[str | None] = []
    for site in skeleton.end_sites:
        site_word = "_".join(site.name.split()) if site.name else site.name
        sites.append(site_word or None)
        if site.name and site_word != site.name:
            changed.append((site.name, str(site_word)))
    return joints, sites, changed


def bvh_chunks(motion: Motion, names: tuple[list[str], list[str | None]] | None = None) -> Iterator[str]:
    """The BVH text of ``motion`` in pieces (the header, then blocks of frames), so that a long take is
    written without holding its whole text.  ``names``: the joint and End Site names to write (default the
    skeleton's as BVH holds them: :func:`bvh_skeleton`, then :func:`one_word_names`)."""
    skel = motion.skeleton
    if names is None:
        joint_words, site_words, _ = one_word_names(bvh_skeleton(skel))
        names = (joint_words, site_words)
    joint_names, site_names = names
    out = io.StringIO()
    out.write("HIERARCHY\n")
    children: list[list[int]] = [[] for _ in range(skel.n_joints)]
    for j, p in enumerate(skel.parents.tolist()):
        if p >= 0:
            children[p].append(j)
    sites: list[list[tuple[EndSite, str | None]]] = [[] for _ in range(skel.n_joints)]
    for site, site_name in zip(skel.end_sites, site_names, strict=True):
        sites[site.parent].append((site, site_name))
    # A stack of ("open", joint, depth) and ("close", joint, depth): depth-first, children in order.
    stack = [("close", 0, 0), ("open", 0, 0)]
    while stack:
        what, j, depth = stack.pop()
        tab = "\t" * min(depth, MAX_INDENT)  # deeper levels alike: a 10,000-deep chain's tabs would be quadratic
        if what == "close":
            for s, site_name in sites[j]:
                label = "End Site" + (f" {site_name}" if site_name else "")
                out.write(f"{tab}\t{label}\n{tab}\t{{\n")
                out.write(f"{tab}\t\tOFFSET {' '.join(_fmt(v) for v in s.offset)}\n{tab}\t}}\n")
            out.write(f"{tab}}}\n")
            continue
        out.write(f"{tab}{'ROOT' if j == 0 else 'JOINT'} {joint_names[j]}\n{tab}{{\n")
        out.write(f"{tab}\tOFFSET {' '.join(_fmt(v) for v in skel.offsets[j])}\n")
        chans = skel.channels[j]
        out.write(f"{tab}\tCHANNELS {len(chans)}{''.join(' ' + c for c in chans)}\n")
        for c in reversed(children[j]):
            stack += [("close", c, depth + 1), ("open", c, depth + 1)]

    out.write(f"MOTION\nFrames: {motion.n_frames}\nFrame Time: {motion.frame_time!r}\n")
    yield out.getvalue()
    if not motion.skeleton.n_channels:
        yield "\n" * motion.n_frames
        return
    for _, block in channel_blocks(motion, _ROWS_PER_CHUNK):  # a block of rows at a time, none held whole
        # Write tiny values as 0 so files stay readable; keep 9 significant digits.
        yield _rows_text(np.where(np.abs(block) < 1e-9, 0.0, block))


def write_bvh(motion: Motion, path: str | os.PathLike) -> Path:
    """Write ``motion`` as a BVH file at ``path`` (atomically).  Returns the path.

    Names are written as BVH holds them (:func:`bvh_skeleton`: no braces, control characters or lone
    surrogates) and one word each (:func:`one_word_names`), a :class:`~mocycle.errors.MocycleWarning` listing
    what changed, so that every BVH reader reads one joint per name; mocycle reads back the names written."""
    joints, sites, changed = one_word_names(bvh_skeleton(motion.skeleton))  # what BVH holds, then one word
    if changed:
        shown = ", ".join(f"{a!r} as {b!r}" for a, b in changed[:5]) + (" ..." if len(changed) > 5 else "")
        warnings.warn(f"{path}: BVH names are one word each (most readers split a line at spaces): {len(changed)} "
                      f"written with underscores: {shown}", MocycleWarning, stacklevel=2)
    try:
        return atomic_write(path, bvh_chunks(motion, (joints, sites)))
    except OSError as exc:
        raise MotionFileError(f"cannot write file ({exc.strerror or exc})", path) from None


def skeleton_text(skeleton: Skeleton) -> str:
    """The BVH text of the skeleton's rest pose (one frame), which :func:`parse_bvh` reads back (the swings
    files keep their skeleton so): names as BVH holds them but with their spaces (:func:`bvh_skeleton` with
    ``one_word=False``: mocycle's reader takes a name with spaces)."""
    skeleton = bvh_skeleton(skeleton, one_word=False)
    names = (list(skeleton.names), [s.name for s in skeleton.end_sites])
    return "".join(bvh_chunks(Motion.rest(skeleton, 1), names))
