"""The result of a cycle extraction: :class:`Cycle`, one loop of ``N`` frames in the cycle space.

``P`` ``(N, n_periodic)``: rotation matrices and moving translations; ``L`` ``(N, 4)``: the travel joint's
translation (file units) and heading (rad), carrying ``drift`` ``(4,)`` per cycle.  It decodes to a Motion
with the root in place or moving on, and repeats seamlessly.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from dataclasses import InitVar, dataclass, field, replace
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate, defaults
from ..limits import check_frames
from ..motion import Motion
from ..phase.analysis import PeriodicMotion
from ..rotations import axis_rotations, continuous_quats, matrix_quats, vector_norms
from .harmonic import HarmonicRegression
from .representation import CycleSpace
from .timeaxis import TimeAxis

ROOT_MODES = defaults.ROOT_MODES


@dataclass(kw_only=True)
class Cycle:
    """One cycle of ``N`` frames (frame ``N`` would equal frame 0) and how it was made.

    ``P``: ``(N, n_periodic)`` and ``L``: ``(N, 4)`` in the cycle space, ``L`` with its drift;
    ``drift``: ``(4,)`` change of ``L`` over one cycle (horizontal travel per cycle, turn per cycle);
    ``positions``: ``(M,)`` where each frame of ``axis.frames()`` falls in the cycle, in cycle frames.

    The drift carries only what a loop may keep doing: travel across the floor and turn about the
    vertical.  A vertical component (a take whose root rises or sinks slowly: capture drift, a ramp)
    is taken out of ``drift`` and of ``L`` on construction, so the root's height is periodic and
    ``repeat(20, root="motion")`` neither floats nor sinks.

    The cycle keeps what it derives from its arrays (:meth:`cache`): every motion of it (:meth:`repeat`,
    :meth:`motion`) is decoded once per ``(count, root)`` and the same Motion returned after that, so the
    metrics, the feet and the output of one loop share them.  Its arrays are not to be changed in place;
    ``dataclasses.replace`` makes a cycle with caches of its own.
    """

    space: CycleSpace
    P: np.ndarray
    L: np.ndarray
    drift: np.ndarray
    method: str
    model: str | None
    harmonics: int | None
    axis: TimeAxis
    positions: np.ndarray
    periodic: PeriodicMotion | None  # None: a blend of cycles (no one take's phase)
    regression: HarmonicRegression | None = field(default=None, repr=False)
    seconds: float = 0.0
    #: ``space.project(P)`` ``(N, J, 3, 3)`` when the maker has it (rows of a finer sampling of the same fit):
    #: kept as :meth:`rotation_matrices`.  Not a field: ``dataclasses.replace`` does not pass it on.
    projected: InitVar[np.ndarray | None] = None
    #: the values of :meth:`cache` (a fresh dict for each cycle, ``dataclasses.replace``'s too)
    _kept: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self, projected: np.ndarray | None):
        up = self.space.up
        rise = float(self.drift[:3] @ up)
        if rise != 0.0:  # level the drift: only horizontal travel and the turn about the vertical remain
            ramp = np.arange(self.P.shape[0])[:, None] / self.P.shape[0]
            self.L = self.L.copy()
            self.L[:, :3] -= ramp * (rise * up)
            self.drift = self.drift.copy()
            self.drift[:3] -= rise * up
        if projected is not None:
            if projected.shape != (self.n_frames, self.space.n_joints, 3, 3):
                raise ValueError(f"projected has shape {projected.shape}; the cycle's rotation matrices are "
                                 f"{(self.n_frames, self.space.n_joints, 3, 3)}")
            self._kept["rotations"] = _read_only(projected)

    def __getstate__(self) -> dict:
        """Pickled without what :meth:`cache` keeps (made again from the arrays when asked for)."""
        return {**self.__dict__, "_kept": {}}

    def cache(self, key: Hashable, make: Callable[[Cycle], Any] | None = None) -> Any:
        """A value derived from this cycle, made by ``make(cycle)`` on the first call with ``key`` and kept with
        the cycle after that; with no ``make``, the kept value or ``None`` (as :meth:`Motion.cache`).

        Arrays are kept read-only and Motions are shared: copy where the caller changes them, and never hand
        a kept Motion over (:meth:`Motion.hand_over`).  The keys in use: ``"rotations"``
        (:meth:`rotation_matrices`), ``"quaternions"`` (:meth:`quaternions`), ``"inplace L"`` (:meth:`inplace_L`),
        ``("repeat", count, root)`` (:meth:`repeat`), ``"loop blocks"``
        (:func:`~mocycle.cycle.metric_rows.loop_blocks`).

        Examples
        --------
        >>> from mocycle.cycle import extract_cycle
        >>> from mocycle.datasets import synthetic_walk
        >>> cycle = extract_cycle(synthetic_walk(n_frames=300).motion)
        >>> cycle.repeat(2, root="motion") is cycle.repeat(2, root="motion"), cycle.cache(("repeat", 3, "motion"))
        (True, None)
        """
        kept = self._kept
        if key not in kept:
            if make is None:
                return None
            kept[key] = make(self)
        return kept[key]

    @property
    def n_frames(self) -> int:
        return self.P.shape[0]

    @property
    def n_harmonics(self) -> int | None:
        """The old name of :attr:`harmonics` (K, the number of harmonics): a DeprecationWarning, for one release."""
        import warnings

        warnings.warn("n_harmonics is now called harmonics; n_harmonics is accepted until the next release",
                      DeprecationWarning, stacklevel=2)
        return self.harmonics

    def rotation_matrices(self, count: int = 1) -> np.ndarray:
        """``space.project(P)`` ``(N, J, 3, 3)`` (read-only), made once, repeated ``count`` times (a new array):
        every motion of the cycle (in place, moving on, repeated, the seam's blocks) has these local rotations,
        only the travel joint's heading differs (here it has none)."""
        R = self.cache("rotations", lambda cycle: _read_only(cycle.space.project(cycle.P)))
        return R if count == 1 else np.tile(R, (count, 1, 1, 1))

    def quaternions(self) -> np.ndarray:
        """:func:`~mocycle.rotations.matrix_quats` of :meth:`rotation_matrices` ``(N, J, 4)`` (read-only, made once):
        the quaternions of every joint of every motion of the cycle, but the travel joint's (turned to the
        heading in each)."""
        return self.cache("quaternions", lambda cycle: _read_only(matrix_quats(cycle.rotation_matrices())))

    @property
    def period_frames(self) -> float:
        """The input's period in frames (the cycle has ``round`` of it, the cut its own length)."""
        return self.axis.period_frames

    @property
    def n_periods(self) -> float:
        return self.axis.n_periods

    def rolled(self, k: int) -> Cycle:
        """The same loop started at its frame ``k``: frames ``N..N+k-1`` are the first ones moved on by the
        drift.  Exact for a path in the straight form the cycles are fitted and blended in (periodic plus a
        line); :meth:`repeat` turns each repeat as a whole."""
        N, k = self.n_frames, int(k) % self.n_frames
        if k == 0:
            return self
        idx = (np.arange(N) + k) % N
        L = self.L[idx] + np.outer(np.arange(N) + k >= N, self.drift)
        return replace(self, P=self.P[idx], L=L, positions=np.mod(self.positions - k, N))

    def on_path(self, L: np.ndarray, drift: np.ndarray) -> Cycle:
        """The same poses on the path ``L`` ``(N, 4)`` moving on by ``drift`` ``(4,)``: a new cycle that keeps
        this one's rotation matrices (the path does not change them), none of its motions."""
        return replace(self, L=L, drift=drift, projected=self.cache("rotations"))

    def _next_repeat(self, L: np.ndarray, times: int = 1) -> np.ndarray:
        """Rows of ``L`` as they are ``times`` repeats later: the rigid motion of one cycle (the turn about the
        vertical through the first frame's position, then the travel) applied ``times`` times."""
        p0 = self.L[0, :3]
        out = L.copy()
        for _ in range(times):
            R = axis_rotations(self.space.up, np.array([self.drift[3]]))[0]
            out[:, :3] = (out[:, :3] - p0) @ R.T + p0 + self.drift[:3]
            out[:, 3] += self.drift[3]
        return out

    def inplace_L(self) -> np.ndarray:
        """``L (N, 4)`` walking on the spot (read-only, made once): the path straightened (each step turned back
        by the turn spread evenly over the cycle, so a turning walk's steps line up as a straight walk's) and
        its travel and turn taken out along a ramp.  Position and velocity both wrap seamlessly; a straight
        walk's path is only ramped.  :func:`drifting_L` is the inverse."""
        return self.cache("inplace L", lambda cycle: _read_only(cycle._make_inplace_L()))

    def _make_inplace_L(self) -> np.ndarray:
        N = self.n_frames
        ramp = np.arange(N) / N
        full = np.vstack([self.L, self._next_repeat(self.L[:1])])  # the next repeat's first frame closes it
        steps = np.einsum("tij,tj->ti", _step_turns(self.space.up, self.drift[3], N).swapaxes(1, 2),
                          np.diff(full[:, :3], axis=0))
        path = full[0, :3] + np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])  # (N + 1, 3)
        out = self.L.copy()
        out[:, :3] = path[:-1] - ramp[:, None] * (path[-1] - path[0])
        out[:, 3] -= ramp * self.drift[3]
        return out

    def motion(self, root: str = "inplace") -> Motion:
        """The cycle as a Motion; ``root="inplace"`` walks on the spot, ``"motion"`` moves on by ``drift``
        (``repeat(1, root)``: the same Motion)."""
        return self.repeat(1, root)

    def repeat(self, count: int, root: str = "inplace") -> Motion:
        """The cycle ``count`` times, seamlessly; with ``root="motion"`` each repeat starts where the last ends.

        Decoded on the first call with ``(count, root)`` and kept with the cycle (:meth:`cache`): later calls
        return the same Motion, and its ``count * N`` frames live as long as the cycle does."""
        _check_choice(root, ROOT_MODES, "root")
        count = _validate.integer("count", count, 1)
        return self.cache(("repeat", count, root), lambda cycle: cycle._decode(count, root))

    def _decode(self, count: int, root: str) -> Motion:
        check_frames(count * self.n_frames, self.space.skeleton.n_joints,
                     f"{count} cycles of {self.n_frames} frames")
        return self.space.decode_repeated(self.P, self._repeat_L(count, root), self.rotation_matrices(),
                                          self.quaternions(), count)

    def _repeat_L(self, count: int, root: str) -> np.ndarray:
        """``L (count * N, 4)`` of :meth:`repeat` (a new array)."""
        if root == "inplace":
            return np.tile(self.inplace_L(), (count, 1))
        Ls = [self.L]
        for _ in range(count - 1):  # each repeat is the last one moved rigidly: a turning walk walks a circle
            Ls.append(self._next_repeat(Ls[-1]))
        return np.concatenate(Ls)

    def repeat_path(self, count: int, root: str = "inplace") -> np.ndarray:
        """``space.path(repeat(count, root))`` ``(count * N, 4)``, the same numbers, from the travel joint alone:
        its rotation decoded as :meth:`repeat` and the Motion it makes do (quaternions, signs made continuous,
        normalised), no other joint's (a long view's ``(T, J, 3, 3)`` rotations and their quaternions are
        never made)."""
        _check_choice(root, ROOT_MODES, "root")
        count = _validate.integer("count", count, 1)
        space = self.space
        L = self._repeat_L(count, root)
        R = np.tile(self.rotation_matrices()[:, space.travel], (count, 1, 1))
        R = space.heading_rotations(L) @ R
        q = continuous_quats(matrix_quats(R[:, None]), inplace=True)  # decode
        q /= vector_norms(q, keepdims=True)  # Motion's own normalisation
        q = continuous_quats(q, inplace=True)[:, 0]
        psi = space.heading(Rotation.from_quat(q).as_matrix())
        return np.concatenate([L[:, :3], psi[:, None]], axis=1)

    def to_dict(self) -> dict:
        return {
            "period_frames": self.period_frames,
            "cycle_frames": self.n_frames,
            **{name: getattr(self, name) for name in ("n_periods", "method", "model", "harmonics")},
            "time_axis": self.axis.method,
            "travel_per_cycle": self.drift[:3].tolist(),
            "turn_per_cycle_deg": float(np.degrees(self.drift[3])),
            **(self.periodic.provenance() if self.periodic is not None else {}),  # a blend has no one phase
        }


def _step_turns(up: np.ndarray, turn: float, n: int) -> np.ndarray:
    """Rotations ``(n, 3, 3)`` about ``up`` by the turn ``turn`` (rad per cycle) spread over a cycle of ``n``
    frames, at the middle of each step ``k -> k + 1``."""
    return axis_rotations(up, turn * (np.arange(n) + 0.5) / n)


def drifting_L(up: np.ndarray, inplace: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """The cycle's ``L (N, 4)`` that moves on by ``drift (4,)`` (travel in the file's frame, turn in rad) and
    walks on the spot as ``inplace (N, 4)``: the inverse of :meth:`Cycle.inplace_L`.  The straight travel ``s``
    that, bent by the turn, ends at ``drift[:3]`` solves ``mean_k(R_k) s = drift - sum_k R_k (step_k)``."""
    N = inplace.shape[0]
    R = _step_turns(up, drift[3], N)
    d_in = np.diff(np.vstack([inplace[:, :3], inplace[:1, :3]]), axis=0)  # (N, 3), closing step included
    rhs = drift[:3] - np.einsum("tij,tj->i", R, d_in)
    s = np.linalg.lstsq(R.mean(axis=0), rhs, rcond=None)[0]
    steps = np.einsum("tij,tj->ti", R, d_in + s / N)
    out = inplace.copy()
    out[1:, :3] = inplace[0, :3] + np.cumsum(steps[:-1], axis=0)
    out[:, 3] += np.arange(N) / N * drift[3]
    return out


def _check_choice(value, choices, name):
    _validate.choice(name, value, choices)


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array
