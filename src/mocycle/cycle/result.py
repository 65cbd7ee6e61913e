"""The result of a cycle extraction: :class:`Cycle`, one loop of ``N`` frames in the cycle space.

``P`` ``(N, n_periodic)``: rotation matrices and moving translations; ``L`` ``(N, 4)``: the travel joint's
translation (file units) and heading (rad), carrying ``drift`` ``(4,)`` per cycle.  It decodes to a Motion
with the root in place or moving on, and repeats seamlessly.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..limits import check_frames
from ..motion import Motion
from ..phase.analysis import PeriodicMotion
from ..rotations import axis_rotations, continuous_quats, matrix_quats, vector_norms
from .harmonic import HarmonicRegression
from .representation import CycleSpace
from .timeaxis import TimeAxis

ROOT_MODES = ("inplace", "motion")


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
    """

    space: CycleSpace
    P: np.ndarray
    L: np.ndarray
    drift: np.ndarray
    method: str
    model: str | None
    n_harmonics: int | None
    axis: TimeAxis
    positions: np.ndarray
    periodic: PeriodicMotion
    regression: HarmonicRegression | None = field(default=None, repr=False)
    seconds: float = 0.0
    #: :func:`loop_blocks` of this cycle and ``space.project(P)``, once made (not copied by ``dataclasses.replace``)
    _blocks: tuple | None = field(default=None, init=False, repr=False, compare=False)
    _projected: np.ndarray | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self):
        up = self.space.up
        rise = float(self.drift[:3] @ up)
        if rise != 0.0:  # level the drift: only horizontal travel and the turn about the vertical remain
            ramp = np.arange(self.P.shape[0])[:, None] / self.P.shape[0]
            self.L = self.L.copy()
            self.L[:, :3] -= ramp * (rise * up)
            self.drift = self.drift.copy()
            self.drift[:3] -= rise * up

    def __getstate__(self) -> dict:
        """Pickled without the caches ``_blocks`` and ``_projected`` (made again from ``P`` when asked for)."""
        return {**self.__dict__, "_blocks": None, "_projected": None}

    @property
    def n_frames(self) -> int:
        return self.P.shape[0]

    def _rotations(self, count: int = 1) -> np.ndarray:
        """``space.project(P)`` ``(N, J, 3, 3)``, made once, repeated ``count`` times: every motion of the
        cycle (in place, moving on, repeated, the seam's blocks) has these rotations, only the travel joint's
        heading differs."""
        if self._projected is None:
            self._projected = self.space.project(self.P)
        return self._projected if count == 1 else np.tile(self._projected, (count, 1, 1, 1))

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

    def _inplace_L(self) -> np.ndarray:
        """``L (N, 4)`` walking on the spot: the path straightened (each step turned back by the turn spread
        evenly over the cycle, so a turning walk's steps line up as a straight walk's) and its travel and turn
        taken out along a ramp.  Position and velocity both wrap seamlessly; a straight walk's path is only
        ramped.  :func:`drifting_L` is the inverse."""
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
        """The cycle as a Motion; ``root="inplace"`` walks on the spot, ``"motion"`` moves on by ``drift``."""
        _check_choice(root, ROOT_MODES, "root")
        return self.space.decode(self.P, self._inplace_L() if root == "inplace" else self.L, self._rotations())

    def repeat(self, count: int, root: str = "inplace") -> Motion:
        """The cycle ``count`` times, seamlessly; with ``root="motion"`` each repeat starts where the last ends."""
        _check_choice(root, ROOT_MODES, "root")
        count = _validate.integer("count", count, 1)
        check_frames(count * self.n_frames, self.space.skeleton.n_joints,
                     f"{count} cycles of {self.n_frames} frames")
        return self.space.decode(np.tile(self.P, (count, 1)), self._repeat_L(count, root), self._rotations(count))

    def _repeat_L(self, count: int, root: str) -> np.ndarray:
        """``L (count * N, 4)`` of :meth:`repeat`."""
        if root == "inplace":
            return np.tile(self._inplace_L(), (count, 1))
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
        R = np.tile(self._rotations()[:, space.travel], (count, 1, 1))
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
            "n_periods": self.n_periods,
            "method": self.method,
            "model": self.model,
            "harmonics": self.n_harmonics,
            "time_axis": self.axis.method,
            "travel_per_cycle": self.drift[:3].tolist(),
            "turn_per_cycle_deg": float(np.degrees(self.drift[3])),
            **self.periodic.provenance(),
        }


def _step_turns(up: np.ndarray, turn: float, n: int) -> np.ndarray:
    """Rotations ``(n, 3, 3)`` about ``up`` by the turn ``turn`` (rad per cycle) spread over a cycle of ``n``
    frames, at the middle of each step ``k -> k + 1``."""
    return axis_rotations(up, turn * (np.arange(n) + 0.5) / n)


def drifting_L(up: np.ndarray, inplace: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """The cycle's ``L (N, 4)`` that moves on by ``drift (4,)`` (travel in the file's frame, turn in rad) and
    walks on the spot as ``inplace (N, 4)``: the inverse of ``Cycle._inplace_L``.  The straight travel ``s``
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
