"""The space the loop metrics and checks measure in: every rotation joint's matrix over √2, ``(T, 9J)``
(:func:`metric_features`), made a block at a time for a long take (:class:`MetricRows`), and a cycle's own
rows and travel path (:func:`loop_blocks`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import MocycleError
from ..features import pose_matrix
from ..motion import ROTATION_CHANNELS, Motion

if TYPE_CHECKING:
    from .result import Cycle


def metric_features(motion: Motion, *, rows: slice = slice(None)) -> np.ndarray:
    """``(T, 9J)`` the space the loop metrics are measured in: every joint's rotation matrix (its 9 entries,
    :func:`~mocycle.features.pose_matrix` ``rotmat``) divided by √2.

    The distance between two poses is then, per joint, ``||R1 - R2||_F / √2 = 2 sin(θ/2)`` for a relative
    rotation of ``θ``: about ``θ`` in radians for small angles (0.5 % short at 20°, 4 % at 60°), and, unlike
    a rotation vector, continuous for a joint that turns a full circle every cycle (no wrap at ±π); it is
    the same wrap-free space the cycle is regressed in (:class:`~mocycle.cycle.representation.CycleSpace`),
    and no reference pose moves a distance in it.  ``rows``: only these frames (a slice), without copying
    the motion.  Computed block by block of frames: the same numbers as
    ``pose_matrix(motion, rep="rotmat", root_features="drop")[0] / √2``.
    """
    joints = _rotation_joints(motion.skeleton)
    if not joints:
        return pose_matrix(motion, rep="rotmat", root_features="drop")[0]  # raises: no features
    quats = motion.rotations[rows]
    T = quats.shape[0]
    out = np.empty((T, 9 * len(joints)))
    for f0 in range(0, T, 8192):
        block = np.take(quats[f0:f0 + 8192], joints, axis=1)  # contiguous, unlike [:, joints]
        out[f0:f0 + 8192] = Rotation.from_quat(block.reshape(-1, 4)).as_matrix().reshape(block.shape[0], -1)
    out /= np.sqrt(2.0)
    return out


def _rotation_joints(skeleton) -> list[int]:
    """The joints :func:`metric_features` measures: those with rotation channels."""
    return [j for j, channels in enumerate(skeleton.channels) if any(c in ROTATION_CHANNELS for c in channels)]


#: A motion's whole ``(T, 9J)`` metric rows are made once and kept with it (:meth:`Motion.cache` ``"metric rows"``)
#: when they take at most this many bytes (about 20,000 frames of a 22-joint rig): the metrics and the checks of
#: one loop read them about eight times over.  A longer motion's are made block by block as they are read.
KEPT_ROWS_BYTES = 32 * 2**20


def _kept_rows(motion: Motion, joints: np.ndarray) -> np.ndarray | None:
    """``metric_features(motion)`` (read-only), kept with the motion, or ``None`` above :data:`KEPT_ROWS_BYTES`."""
    if not joints.size or motion.n_frames * 9 * joints.size * 8 > KEPT_ROWS_BYTES:
        return None

    def make(m: Motion) -> np.ndarray:
        rows = metric_features(m)
        rows.setflags(write=False)
        return rows

    return motion.cache("metric rows", make)


class MetricRows:
    """``metric_features(motion, rows=region)[:, columns]`` made a block of rows (or of columns) at a time when
    read, never held whole: a long take's ``(T, 9J)`` array (158 MB for 100k frames of 22 joints) was the
    largest thing the loop metrics and checks held.

    ``rows[a:b]`` and ``rows[index array]`` are those rows of the array ``(n, len(columns))``, the same numbers
    (each block made as :func:`metric_features` makes its blocks, columns picked as ``array[:, columns]``
    picks them); :meth:`region` is a block of frames, :meth:`select` and :meth:`moving` pick columns;
    :meth:`column_blocks` feeds :func:`~mocycle.phase.period.autocorrelation_period_of_blocks`;
    :meth:`lag_differences` gives the squared row distances ``lag`` rows apart from the quaternions
    (``||R1 - R2||²/2 = 4 sin²(θ/2) = 4 (1 - (q1·q2)²)`` per moving joint, within 1e-15 of the largest of the
    rows' own); :meth:`spread` the RMS distance of the rows from their mean row.

    A motion of up to :data:`KEPT_ROWS_BYTES` has its rows made once and kept (``kept``: the rows of every
    rotation joint, ``metric_features``' numbers, which are each block's); the others' are made as read."""

    BLOCK = 8192

    def __init__(self, motion: Motion, region: slice = slice(None), columns: np.ndarray | None = None):
        self.quats = motion.rotations[region]
        self.joints = np.asarray(_rotation_joints(motion.skeleton), dtype=np.intp)
        if self.joints.size == 0:
            metric_features(motion, rows=region)  # raises: no features
        self.every = columns is None
        self.columns = np.arange(9 * self.joints.size) if columns is None else np.asarray(columns, dtype=np.intp)
        self.shape = (self.quats.shape[0], int(self.columns.size))
        self.ndim = 2
        kept = _kept_rows(motion, self.joints)
        self.kept = None if kept is None else kept[region]

    def _like(self, quats: np.ndarray, columns: np.ndarray | None, kept: np.ndarray | None) -> MetricRows:
        out = object.__new__(MetricRows)
        out.quats, out.joints, out.every, out.kept = quats, self.joints, columns is None, kept
        out.columns = self.columns if columns is None else columns
        out.shape, out.ndim = (quats.shape[0], int(out.columns.size)), 2
        return out

    def region(self, start: int, stop: int) -> MetricRows:
        """Rows ``start:stop`` as another :class:`MetricRows` (nothing is made)."""
        return self._like(self.quats[start:stop], None if self.every else self.columns,
                          None if self.kept is None else self.kept[start:stop])

    def select(self, keep: np.ndarray) -> MetricRows:
        """The columns where the boolean ``keep`` ``(n_columns,)`` is true."""
        return self._like(self.quats, self.columns[np.asarray(keep, dtype=bool)], self.kept)

    def still(self) -> np.ndarray:
        """``(n_columns,)`` True where a column holds one value on every row (``np.ptp(rows, axis=0) == 0``)."""
        lo = hi = None
        for r0 in range(0, self.shape[0], self.BLOCK):
            raw = self._rows(r0, r0 + self.BLOCK)
            lo = raw.min(axis=0) if lo is None else np.minimum(lo, raw.min(axis=0))
            hi = raw.max(axis=0) if hi is None else np.maximum(hi, raw.max(axis=0))
        if lo is None:
            return np.zeros(self.shape[1], dtype=bool)
        return (hi - lo == 0)[self.columns]

    def moving(self) -> MetricRows:
        """Without the still columns (:func:`~mocycle.cycle.checks.moving_columns`); itself when all move."""
        still = self.still()
        return self if not still.any() else self.select(~still)

    def _rows(self, r0: int, r1: int) -> np.ndarray:
        """All 9 entries per rotation joint of rows ``r0:r1``: the kept rows (a read-only view) or made now."""
        return self.kept[r0:r1] if self.kept is not None else self._raw(self.quats[r0:r1])

    def _raw(self, quats: np.ndarray, joints: np.ndarray | None = None) -> np.ndarray:
        """All 9 entries per joint (of ``joints``, default every rotation joint) of the frames ``quats``."""
        block = np.take(quats, self.joints if joints is None else joints, axis=1)
        out = Rotation.from_quat(block.reshape(-1, 4)).as_matrix().reshape(block.shape[0], -1)
        out /= np.sqrt(2.0)
        return out

    def _pick(self, raw: np.ndarray) -> np.ndarray:
        return raw if self.every else raw[:, self.columns]  # laid out as array[:, columns]: the same rounding

    def __getitem__(self, key) -> np.ndarray:
        if isinstance(key, slice):
            if key.step not in (None, 1):
                raise TypeError("MetricRows reads a slice of rows with step 1")
            r0, r1, _ = key.indices(self.shape[0])
            if r1 <= r0:
                return np.empty((0, self.shape[1]))
            if self.kept is not None:  # a new array, as when made
                return self.kept[r0:r1].copy() if self.every else self.kept[r0:r1, self.columns]
            blocks = [self._raw(self.quats[a:min(r1, a + self.BLOCK)]) for a in range(r0, r1, self.BLOCK)]
            return self._pick(blocks[0] if len(blocks) == 1 else np.concatenate(blocks, axis=0))
        index = np.asarray(key)
        if index.ndim != 1 or index.dtype.kind not in "iu":
            raise TypeError("MetricRows reads a slice of rows or a 1-D array of row indices")
        if self.kept is not None:
            return self._pick(np.take(self.kept, index, axis=0))
        blocks = [self._raw(np.take(self.quats, index[a:a + self.BLOCK], axis=0))
                  for a in range(0, index.size, self.BLOCK)] or [np.empty((0, 9 * self.joints.size))]
        return self._pick(blocks[0] if len(blocks) == 1 else np.concatenate(blocks, axis=0))

    def column_blocks(self):
        """The columns, :func:`~mocycle.phase.period.column_block_width` at a time, all rows each ``(n, d)``."""
        from ..phase.period import column_block_width

        M, width = self.shape[0], column_block_width(self.shape[0])
        for c0 in range(0, self.shape[1], width):
            cols = self.columns[c0:c0 + width]
            if self.kept is not None:
                yield self.kept[:, cols]
                continue
            ks = np.unique(cols // 9)  # the joints (positions in self.joints) these columns belong to
            local = np.searchsorted(ks, cols // 9) * 9 + cols % 9
            out = np.empty((M, cols.size))
            for r0 in range(0, M, self.BLOCK):
                out[r0:r0 + self.BLOCK] = self._raw(self.quats[r0:r0 + self.BLOCK], self.joints[ks])[:, local]
            yield out

    def lag_differences(self, lag: int) -> np.ndarray:
        """``(n - lag,)`` squared distances between rows ``lag`` apart (see the class docstring)."""
        return self.lag_differences_of([lag])[int(lag)]

    def lag_differences_of(self, lags) -> dict[int, np.ndarray]:
        """:meth:`lag_differences` of each of ``lags`` (ints >= 1), ``{lag: (n - lag,)}``, the same numbers: a run
        of consecutive lags is made together, rows ``r .. r + lag`` of every lag of the run in one product
        (a plain cut searches some 30 lags near a period; one product per lag cost more in calls than in
        arithmetic).  A block of rows at a time: the ``(lags, rows, joints)`` temporaries stay small."""
        joints = self.joints[np.unique(self.columns // 9)]  # those with a column here: the others add nothing
        q = self.quats
        if not np.array_equal(joints, np.arange(q.shape[1])):
            q = np.take(q, joints, axis=1)
        M, out = q.shape[0], {}
        for run in _runs(sorted({int(lag) for lag in lags})):
            first, last = run[0], run[-1]
            n = max(0, M - first)
            d = np.empty((len(run), n))
            rows = max(1, self.BLOCK // len(run))
            for r0 in range(0, n, rows):
                r1 = min(r0 + rows, n)
                d[:, r0:r1] = 4.0 * (joints.size - _lag_sums(q[r0:r1], _later_rows(q, r0 + first, r1 + last)))
            out.update({lag: d[k, :max(0, M - lag)] for k, lag in enumerate(run)})
        return out

    def spread(self) -> float:
        """RMS distance of the rows from their mean row."""
        M = self.shape[0]
        mean = sum(self[r:r + self.BLOCK].sum(axis=0) for r in range(0, M, self.BLOCK)) / M
        return float(np.sqrt(sum(float(((self[r:r + self.BLOCK] - mean) ** 2).sum())
                                 for r in range(0, M, self.BLOCK)) / M))


def _runs(values: list[int]) -> list[list[int]]:
    """Sorted ints cut into runs of consecutive ones."""
    runs: list[list[int]] = []
    for v in values:
        if runs and v == runs[-1][-1] + 1:
            runs[-1].append(v)
        else:
            runs.append([v])
    return runs


def _later_rows(q: np.ndarray, start: int, stop: int) -> np.ndarray:
    """Rows ``start:stop`` of the quaternions ``q (M, J, 4)``, rows past ``M`` zeros (their distances are not kept)."""
    later = q[start:stop]
    if later.shape[0] < stop - start:
        later = np.concatenate([later, np.zeros((stop - start - later.shape[0],) + q.shape[1:])])
    return later


def _lag_sums(a: np.ndarray, later: np.ndarray) -> np.ndarray:
    """``(lags, rows)`` sums over the joints of ``cos²(θ/2)`` between rows ``a (rows, J, 4)`` and the rows ``lag``
    on, for the consecutive lags of ``later`` (rows ``r0 + first .. r1 + last`` of the same quaternions): for
    lag ``first + k`` the rows ``later[k:k + rows]``, a strided view (no copy per lag)."""
    n_lags = later.shape[0] - a.shape[0] + 1
    shifted = np.lib.stride_tricks.as_strided(later, shape=(n_lags,) + a.shape,
                                              strides=(later.strides[0],) + later.strides, writeable=False)
    cos = np.einsum("tjk,ltjk->ltj", a, shifted)  # cos(θ/2) per joint, up to sign
    return np.einsum("ltj,ltj->lt", cos, cos)


def loop_blocks(cycle: Cycle) -> tuple[np.ndarray, np.ndarray]:
    """What the seam of a cycle is judged on: its in-place rotations as :func:`metric_features` ``(N, 9J)``
    and the world path of its travel joint ``(N, 3)`` (both read-only).

    Made from the decoded rotation matrices directly (the numbers of ``metric_features`` and
    ``world_positions`` of ``cycle.motion("inplace")`` within rounding, without building the motion or
    running forward kinematics of every joint), and kept with the cycle (:meth:`Cycle.cache`): the
    metrics and the checks ask for the same blocks."""
    return cycle.cache("loop blocks", _loop_blocks)


def _loop_blocks(cycle: Cycle) -> tuple[np.ndarray, np.ndarray]:
    C, path = _blocks(cycle, cycle.rotation_matrices(), cycle.inplace_L(), cycle.P)
    C.setflags(write=False)
    path.setflags(write=False)
    return C, path


def loop_blocks_at(cycle: Cycle, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`loop_blocks` at the cycle's ``rows`` only (indices ``(n,)``): the same numbers within rounding
    (the projection's last step is shared by the rows projected together), with only those rows projected onto
    rotations (each row's blocks depend on that row alone, once the in-place path, which depends on them all,
    is made).  Not kept."""
    P = cycle.P[rows]
    return _blocks(cycle, cycle.space.project(P), cycle.inplace_L()[rows], P)


def _blocks(cycle: Cycle, R: np.ndarray, L: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The blocks of :func:`loop_blocks` from rows of the cycle's projected rotations ``R (n, J, 3, 3)``,
    in-place path ``L (n, 4)`` and periodic curves ``P (n, n_periodic)``."""
    space = cycle.space
    joints = _rotation_joints(space.skeleton)
    if not joints:
        raise MocycleError("no features: the selected joints have no rotation channels and the root is dropped")
    # local rotations: the travel joint's without its heading, put in below
    travel = space.heading_rotations(L) @ R[:, space.travel]
    every = len(joints) == space.n_joints
    C = (R if every else np.take(R, joints, axis=1)).reshape(R.shape[0], -1) / np.sqrt(2.0)
    if space.travel in joints:
        at = space.travel if every else joints.index(space.travel)
        C[:, 9 * at:9 * at + 9] = travel.reshape(-1, 9) / np.sqrt(2.0)
    path = space.travel_path(R, space.translations(P, L), travel)
    return C, path
