"""BVH channel values to a motion's arrays, a chunk of frame rows at a time.

:class:`ChannelConverter` takes the rows of a BVH motion block in order, in chunks of any size (the whole
take, or the pieces a streaming parser yields), checks each chunk (every value finite and within
``MAX_MAGNITUDE``: one per-column ``min`` and ``max``, which also say which position channels change) and
writes its frames into the motion's arrays: unit, sign-continuous quaternions ``(T, J, 4)``, constant
translations ``(J, 3)`` and a ``(T, 3)`` track per joint whose position channels change.  Within a chunk the
rotations are converted a block of frames at a time (:func:`block_frames`), so every temporary is small and
stays in cache; the sign flips carry over from block to block and chunk to chunk, so the arrays do not
depend on how the rows were cut: bit for bit what :class:`~mocycle.motion.Motion` makes of
:func:`~mocycle.rotations.euler_to_quats`' quaternions (``tests/io/test_bvh.py``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..limits import MAX_MAGNITUDE
from ..motion import POSITION_CHANNELS, ROTATION_CHANNELS, Skeleton
from ..rotations import euler_quat_components

#: joint-frames converted to quaternions at a time: blocks of about 32,768 joint-frames, 128 to 1024 frames,
#: keep the temporaries small and in cache (fastest on the 22-joint Bandai, 31-joint CMU and 101-joint
#: iClone rigs, read from row-major or column-major chunks alike; twice that is up to 1.4x slower)
BLOCK_ELEMENTS = 32768
#: frames per block, overriding BLOCK_ELEMENTS when set (the tests cut blocks of 1 and 7 frames)
BLOCK_FRAMES: int | None = None


def block_frames(n_joints: int) -> int:
    """Frames converted at a time for a group of ``n_joints`` joints of one Euler order."""
    if BLOCK_FRAMES:
        return BLOCK_FRAMES
    return max(128, min(1024, BLOCK_ELEMENTS // max(n_joints, 1)))


def channel_layout(skel: Skeleton):
    """Per joint: (rotation channel columns, order, position columns, axes)."""
    col = 0
    layout = []
    for j in range(skel.n_joints):
        rot_cols, pos_cols, pos_axes = [], [], []
        for c in skel.channels[j]:
            if c in ROTATION_CHANNELS:
                rot_cols.append(col)
            else:
                pos_cols.append(col)
                pos_axes.append(POSITION_CHANNELS.index(c))
            col += 1
        layout.append((rot_cols, skel.euler_order(j), pos_cols, pos_axes))
    return layout


class ChannelConverter:
    """The arrays of a motion of at most ``n_frames`` frames (the caller checked that count), filled from its
    channel rows ``(n, C)`` by :meth:`add`, in file order; :meth:`arrays` gives them."""

    def __init__(self, skel: Skeleton, n_frames: int):
        self.skel = skel
        self.n_frames = int(n_frames)
        self.rows = 0  # frames added so far
        self.quats = np.empty((self.n_frames, skel.n_joints, 4))
        self.static = np.array(skel.offsets, dtype=np.float64)
        self.tracks: dict[int, np.ndarray] = {}
        self.first: np.ndarray | None = None  # the first row
        by_order: dict[str, list[tuple[int, list[int]]]] = {}
        self.still = []
        self.positions = []  # (joint, position columns, axes)
        for j, (rot_cols, order, pos_cols, pos_axes) in enumerate(channel_layout(skel)):
            if rot_cols:
                by_order.setdefault(order, []).append((j, rot_cols))
            else:
                self.still.append(j)
            if pos_cols:
                self.positions.append((j, pos_cols, pos_axes))
        self.quats[:, self.still] = (0.0, 0.0, 0.0, 1.0)
        # a joint whose position values have so far all equalled the first row's bit for bit (its track, made
        # when a value first changes, starts as that row); False once a zero of the other sign came
        self.exact = {j: True for j, _, _ in self.positions}
        self.position_columns = np.array(sorted(c for _, cols, _ in self.positions for c in cols), dtype=np.intp)
        self.groups = []
        for order, items in by_order.items():
            joints = [j for j, _ in items]
            cols = [c for _, cs in items for c in cs]
            jsel: slice | list[int] = joints
            csel: slice | list[int] = cols
            if joints == list(range(joints[0], joints[-1] + 1)):  # a slice writes faster than a list of joints
                jsel = slice(joints[0], joints[-1] + 1)
            if cols == list(range(cols[0], cols[-1] + 1)):
                csel = slice(cols[0], cols[-1] + 1)
            self.groups.append((order, jsel, csel, len(items)))
        self.carry: list = [None] * len(self.groups)  # per group: the previous block's last frame and parity

    def add(self, values: np.ndarray) -> bool:
        """Convert the next rows ``(n, C)`` (any memory order); ``False`` (nothing added) when a value is not
        finite or beyond ``MAX_MAGNITUDE``, when the rows would pass ``n_frames``, or when a position
        channel's earlier rows cannot be rebuilt bit for bit (zeros of both signs before its first change:
        re-read the take in one chunk)."""
        converted = self.convert(self.rows, values)
        return converted is not None and self.commit(self.rows, values, converted)

    def convert(self, r0: int, values: np.ndarray) -> _Converted | None:
        """The rotations of rows ``(n, C)`` that are rows ``r0:r0 + n`` of the take, written into them as if
        they began the take (sign-continuous from their own first frame); ``None`` (nothing written) when a
        value is not finite or beyond ``MAX_MAGNITUDE`` or the rows would pass ``n_frames``.  Chunks of
        disjoint rows may be converted at once, in threads (numpy releases the GIL); :meth:`commit` then
        takes them in order."""
        n = values.shape[0]
        if n == 0:
            return _Converted(None, None, [], {})
        if r0 < 0 or r0 + n > self.n_frames or values.shape[1] != self.skel.n_channels:
            return None
        lo, hi = values.min(axis=0), values.max(axis=0)  # NaN propagates
        top = max(float(hi.max()), -float(lo.min())) if lo.size else 0.0
        if not (np.isfinite(lo).all() and np.isfinite(hi).all() and top <= MAX_MAGNITUDE):
            return None
        return _Converted(lo, hi, self._rotations(values, r0), self._zero_signs(values, lo, hi))

    def _zero_signs(self, values: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> dict[int, tuple[bool, bool]]:
        """Per position column whose rows are all zeros (of either sign): whether any of them, and whether all,
        are -0.0 (one gather of those columns, done in the converting thread)."""
        cols = self.position_columns
        if not cols.size:
            return {}
        zero = cols[(lo[cols] == 0.0) & (hi[cols] == 0.0)]
        if not zero.size:
            return {}
        negative = np.signbit(values[:, zero])
        flags = zip(negative.any(axis=0).tolist(), negative.all(axis=0).tolist(), strict=True)
        return dict(zip(zero.tolist(), flags, strict=True))

    def commit(self, r0: int, values: np.ndarray, converted: _Converted) -> bool:
        """Take converted rows ``r0:r0 + n`` after the rows before them: their signs made continuous with
        the frame before (a joint whose first frame flips against it is negated throughout the chunk, which
        is bit for bit the flip a whole-take conversion makes) and the position tracks written.  ``False``
        when ``r0`` is not the next row or a position channel's earlier rows cannot be rebuilt bit for bit."""
        n = values.shape[0]
        if r0 != self.rows:
            return False
        if n == 0:
            return True
        if self.first is None:
            self.first = values[0].copy()
            for j, pos_cols, pos_axes in self.positions:  # the channel values replace the offset
                self.static[j, pos_axes] = self.first[pos_cols]
        assert converted.lo is not None and converted.hi is not None  # rows were converted
        if not self._positions(values, converted, r0):
            return False
        for g, (_, joints, _, _) in enumerate(self.groups):
            first, (last, parity) = converted.seams[g]
            before = self.carry[g]
            if before is not None:
                prev, prev_parity = before
                dot = first[0] * prev[0] + first[1] * prev[1] + first[2] * prev[2] + first[3] * prev[3]
                shift = (dot < 0) ^ prev_parity  # the chunk's own flips, all shifted by one more
                if shift.any():
                    idx = np.arange(self.skel.n_joints)[joints][shift]
                    self.quats[r0:r0 + n, idx] = -self.quats[r0:r0 + n, idx]
                parity = parity ^ shift
            self.carry[g] = (last, parity)
        self.rows = r0 + n
        return True

    def _positions(self, values: np.ndarray, converted: _Converted, r0: int) -> bool:
        """The tracks of the joints whose position values change (a joint whose values never change, by
        ``==``, keeps its first row as its constant translation)."""
        first = self.first
        assert first is not None and converted.lo is not None and converted.hi is not None  # add() set them
        n = values.shape[0]
        unchanged = ((converted.lo == first) & (converted.hi == first)).tolist()  # per column, as Python bools
        first_values = first.tolist()
        for j, pos_cols, pos_axes in self.positions:
            track = self.tracks.get(j)
            if track is None:
                if all(unchanged[c] for c in pos_cols):
                    if self.exact[j]:
                        for c in pos_cols:
                            if first_values[c] == 0.0:  # +0.0 and -0.0 alike: exact when all have the first's sign
                                any_negative, all_negative = converted.zero_signs[c]
                                if (not all_negative) if np.signbit(first[c]) else any_negative:
                                    self.exact[j] = False
                    continue
                if not self.exact[j] and r0 > 0:
                    return False
                track = np.empty((self.n_frames, 3))
                track[...] = self.static[j]  # the earlier rows: the first row's values, bit for bit
                self.tracks[j] = track
            track[r0:r0 + n, pos_axes] = values[:, pos_cols]
        return True

    def _rotations(self, values: np.ndarray, r0: int) -> list:
        """Rows ``values`` converted into quaternion rows ``r0:`` as a take of their own; per group: the first
        frame's components (unflipped) and the carry (last frame's components, unflipped, and its flip
        parity)."""
        n_rows = values.shape[0]
        seams = []
        for order, joints, cols, n in self.groups:
            carry = first = None
            block = block_frames(n)
            for f0 in range(0, n_rows, block):
                f1 = min(n_rows, f0 + block)
                # angles (k, B, n), each axis contiguous, in one pass over the block's channels (a view of them
                # when cols is a slice)
                angles = values[f0:f1, cols].reshape(f1 - f0, n, len(order)).transpose(2, 0, 1)
                comp = euler_quat_components(np.ascontiguousarray(angles), order, degrees=True)
                parts = [np.zeros((f1 - f0, n)) if c is None else c for c in comp]
                if first is None:
                    first = [c[0].copy() for c in parts]
                norm = _norms(parts)
                sign, carry = _flip_signs(parts, carry)
                if sign is not None:
                    norm *= sign  # x / -n is exactly -(x / n): the flip costs no pass of its own
                a, b = r0 + f0, r0 + f1
                out = self.quats[a:b, joints] if isinstance(joints, slice) else np.empty((f1 - f0, n, 4))
                for m in range(4):
                    np.divide(parts[m], norm, out=out[..., m])
                if not isinstance(joints, slice):  # joints of this order interleaved with others'
                    self.quats[a:b, joints] = out
            seams.append((first, carry))
        return seams

    def arrays(self) -> tuple[np.ndarray, np.ndarray, dict[int, np.ndarray]]:
        """Quaternions ``(T, J, 4)``, constant translations ``(J, 3)`` and the tracks ``{joint: (T, 3)}``
        (sorted by joint) of the ``T`` rows added; copied down to ``T`` rows when fewer than ``n_frames``."""
        T = self.rows
        quats, tracks = self.quats, dict(sorted(self.tracks.items()))
        if T < self.n_frames:
            quats = quats[:T].copy()
            tracks = {j: t[:T].copy() for j, t in tracks.items()}
        return quats, self.static, tracks


class _Converted(NamedTuple):
    """What :meth:`ChannelConverter.convert` found of a chunk: per-column minima and maxima, and per group of
    joints the first frame's quaternion components and the carry of :func:`_flip_signs`, and per position
    column of only zeros whether any and whether all of them are -0.0."""

    lo: np.ndarray | None
    hi: np.ndarray | None
    seams: list
    zero_signs: dict[int, tuple[bool, bool]]


def _norms(comp: list[np.ndarray]) -> np.ndarray:
    """The quaternions' norms from their four component arrays, summed in ``np.linalg.norm``'s order (so
    the quotients are what :class:`Motion` makes of :func:`~mocycle.rotations.euler_to_quats`' quaternions,
    bit for bit)."""
    x, y, z, w = comp
    norm = np.multiply(x, x)
    sq = np.multiply(y, y)
    norm += sq
    np.multiply(z, z, out=sq)
    norm += sq
    np.multiply(w, w, out=sq)
    norm += sq
    return np.sqrt(norm, out=norm)


def _flip_signs(comp: list[np.ndarray], carry):
    """Signs ``(B, n)`` (or ``None``: none flips) that make a block of quaternions (components ``(B, n)``)
    sign-continuous, as :func:`~mocycle.rotations.continuous_quats` does over the whole take: a frame flips
    when its dot product with the frame before is negative, and so do all frames after it.  ``carry``: the
    previous block's last frame (its components, unflipped) and its flip parity, or ``None``.  Returns the
    signs and this block's carry."""
    dots = np.empty(comp[0].shape)
    np.multiply(comp[0][1:], comp[0][:-1], out=dots[1:])
    for c in comp[1:]:
        dots[1:] += c[1:] * c[:-1]
    if carry is None:
        dots[0] = 1.0  # the first frame keeps its sign
    else:
        last, parity = carry
        dots[0] = comp[0][0] * last[0] + comp[1][0] * last[1] + comp[2][0] * last[2] + comp[3][0] * last[3]
    flips = np.logical_xor.accumulate(dots < 0, axis=0)  # an odd number of sign changes so far
    if carry is not None:
        flips ^= parity
    carry = ([c[-1].copy() for c in comp], flips[-1].copy())
    if not flips.any():
        return None, carry
    return 1.0 - 2.0 * flips, carry
