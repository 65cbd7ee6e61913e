"""The degrees of freedom a cycle is regressed in, and back to a Motion.

A pose is split in two blocks (:class:`CycleSpace`):

* the **periodic block** ``P`` ``(T, 9J + 3m)``: every joint's local rotation
  as its 3×3 matrix (9 numbers) and the translations of the ``m`` other joints
  whose translation moves.  Matrix entries are continuous and periodic even
  for a joint that turns a full circle every cycle, so the regression has no
  Euler wrap and no ±π jump (the thesis' open problem, chapter 6); averages
  and fits are projected back onto rotations by SVD (the chordal mean).
  The travel joint (usually the root) contributes only its *tilt*: its
  rotation with the heading about the vertical axis taken out.
* the **drifting block** ``L`` ``(T, 4)``: the travel joint's translation
  (3, in its parent's frame, file units) and its heading about the vertical
  axis (1, radians, unwrapped).  These get the translation model with a
  linear term (KTH thesis eq. 3.27): walking moves on and turning keeps turning.

A walk along an arc has a path that is not "periodic plus a line", so the
cycle is fitted on the *straightened* path (:meth:`CycleSpace.straighten`,
paper 001 §4.1's differenced root: every horizontal step turned into the
heading frame and summed again), which is, and turned back along the cycle's
own heading afterwards (:meth:`CycleSpace.bend`).  For a walk whose heading
does not change the two are the same path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..axes import heading_angles, horizontal_basis, up_in_parent_frame, vertical_axis
from ..errors import MocycleError
from ..motion import Motion, Skeleton
from ..phase.period import moving_average
from ..rotations import axis_rotations, continuous_quats, matrix_quats, nearest_rotations

#: frames encoded at a time (the rotation matrices of a block, not of the take, are temporaries)
BLOCK_FRAMES = 8192
#: matrices projected at a time by :meth:`CycleSpace.project`
PROJECT_MATRICES = 8192


@dataclass(frozen=True, eq=False, kw_only=True)
class CycleSpace:
    """How a motion maps to ``(P, L)`` and back (see the module docstring).

    It keeps what decoding needs, not the input motion: ``skeleton``; ``frame_time`` (s);
    ``static_translations`` ``(J, 3)``: every joint's translation in the input's first
    frame (what the joints whose translation does not move keep);
    ``travel``: index of the travel joint; ``world_up``: the vertical axis of the
    take (:func:`~mocycle.axes.vertical_axis`); ``up``: the same in the
    travel joint's parent frame; ``e1``, ``e2``: a horizontal basis there;
    ``forward``: the vector in the travel joint's own frame whose horizontal
    direction defines the heading; ``moving``: the other joints whose translation moves.
    """

    skeleton: Skeleton
    frame_time: float
    static_translations: np.ndarray
    travel: int
    world_up: np.ndarray
    up: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    forward: np.ndarray
    moving: tuple[int, ...]

    @classmethod
    def fit(cls, motion: Motion, up=None) -> CycleSpace:
        """The space of ``motion``; ``up``: the vertical axis (``None``: detected; ``"y"``, ``"-z"`` or a
        3-vector: see :func:`~mocycle.axes.vertical_axis`)."""
        travel = motion.travel_joint
        up_world = vertical_axis(motion, up)
        up = up_in_parent_frame(motion, travel, up_world)
        e1, e2 = horizontal_basis(up)
        mean_rot = motion.rotation(travel).mean().as_matrix()
        forward = mean_rot.T @ e1
        moving = tuple(j for j in motion.moving_joints(1e-9) if j != travel)
        return cls(skeleton=motion.skeleton, frame_time=motion.frame_time,
                   static_translations=motion.translations_at(0), travel=travel, world_up=up_world, up=up,
                   e1=e1, e2=e2, forward=forward, moving=moving)

    # -- sizes ----------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return self.skeleton.n_joints

    @property
    def n_periodic(self) -> int:
        return 9 * self.n_joints + 3 * len(self.moving)

    @property
    def n_drifting(self) -> int:
        return 4

    def heading(self, rotations: np.ndarray) -> np.ndarray:
        """Unwrapped heading ``(T,)`` radians of the travel joint's rotation matrices ``(T, 3, 3)``."""
        return heading_angles(rotations @ self.forward, self.e1, self.e2)

    # -- motion -> (P, L) -----------------------------------------------
    def encode(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        """``P (T, n_periodic)`` and ``L (T, 4)`` of a motion with the space's skeleton."""
        rows, L = self.encode_rows(motion)
        # written block by block of frames straight into P: no (T, J, 3, 3) array or copy of it is held
        P = np.empty(rows.shape)
        for f0 in range(0, rows.shape[0], BLOCK_FRAMES):
            rows.write(f0, min(rows.shape[0], f0 + BLOCK_FRAMES), P[f0:f0 + BLOCK_FRAMES])
        return P, L

    def encode_rows(self, motion: Motion) -> tuple[EncodedRows, np.ndarray]:
        """:meth:`encode` with ``P`` left unmade: an :class:`EncodedRows` that makes the rows a caller reads
        (``rows[a:b]``, the same numbers as ``P[a:b]``), for a reader of a long take that goes over them a block
        at a time (the harmonic fit): its ``(T, 9J)`` array is never held."""
        if not motion.skeleton.same_as(self.skeleton):
            raise MocycleError("this motion's skeleton differs from the one the cycle space was made for")
        psi = self.heading(Rotation.from_quat(motion.rotations[:, self.travel]).as_matrix())
        L = np.concatenate([motion.joint_translations(self.travel), psi[:, None]], axis=1)
        return EncodedRows(self, motion, psi), L

    def path(self, motion: Motion) -> np.ndarray:
        """``L (T, 4)`` of :meth:`encode` alone (the travel joint's translation and heading), without ``P``."""
        if not motion.skeleton.same_as(self.skeleton):
            raise MocycleError("this motion's skeleton differs from the one the cycle space was made for")
        psi = self.heading(Rotation.from_quat(motion.rotations[:, self.travel]).as_matrix())
        return np.concatenate([motion.joint_translations(self.travel), psi[:, None]], axis=1)

    # -- straight and curved paths ---------------------------------------
    def _turned(self, V: np.ndarray, angles: np.ndarray) -> np.ndarray:
        """The vectors ``V (T, 3)`` each turned by ``angles (T,)`` about the vertical."""
        return np.einsum("tij,tj->ti", axis_rotations(self.up, angles), V)

    @staticmethod
    def heading_trend(psi: np.ndarray, period: float) -> np.ndarray:
        """The heading ``psi (T,)`` without its within-cycle sway: its mean over one period about each frame.

        The take's straight line through ``psi`` is taken out first and put back after, so the window's
        ends (shortened there) do not bend a steady turn.
        """
        t = np.arange(psi.size, dtype=np.float64)
        line = np.polyval(np.polyfit(t, psi, 1), t) if psi.size > 1 else psi.copy()
        width = int(max(1, min(round(period), psi.size)))
        return line + moving_average(psi - line, width)

    def straighten(self, L: np.ndarray, period: float, trend: np.ndarray | None = None) -> np.ndarray:
        """``L (T, 4)`` with its path straightened: step ``t`` turned back by the heading trend's change
        since the first frame (:meth:`heading_trend`, ``period`` in frames; ``trend``: ``heading_trend(L[:, 3],
        period)`` when the caller has it).

        The vertical component and the heading are kept; the first frame stays where it is.  A walk along
        a circle becomes a straight walk (periodic plus a line), which the cycle models can fit; a walk
        whose heading only sways about a fixed direction is left as it is.
        """
        L = np.asarray(L, dtype=np.float64)
        if L.shape[0] < 2:
            return L.copy()
        trend = self.heading_trend(L[:, 3], period) if trend is None else trend
        mid = 0.5 * (trend[1:] + trend[:-1])
        steps = self._turned(np.diff(L[:, :3], axis=0), trend[0] - mid)
        out = L.copy()
        out[1:, :3] = L[0, :3] + np.cumsum(steps, axis=0)
        return out

    def bend(self, Q: np.ndarray, drift: np.ndarray, reference: float) -> tuple[np.ndarray, np.ndarray]:
        """The inverse of :meth:`straighten` for one cycle: ``Q (N, 4)`` straightened with heading trend
        ``reference`` at the first frame of its take, ``drift (4,)`` its change over one cycle.

        The cycle's heading trend is its mean heading plus its turn spread evenly over the cycle.  Returns
        the cycle's path ``(N, 4)`` turned back along it and the drift ``(4,)`` (travel per cycle now in the
        file's frame, as the path ends one cycle later; turn unchanged).
        """
        N = Q.shape[0]
        full = np.vstack([Q, Q[:1] + drift])
        # the trend at frame k is the heading's mean over the cycle centred there: the mean over frames
        # 0..N-1 (centred at (N-1)/2) moved on by the turn; the steps turn at their middles k + 1/2
        mid = Q[:, 3].mean() + drift[3] * (np.arange(N) + 1 - 0.5 * N) / N - reference
        steps = self._turned(np.diff(full[:, :3], axis=0), mid)
        path = np.vstack([full[:1, :3], full[0, :3] + np.cumsum(steps, axis=0)])
        L = np.column_stack([path[:-1], Q[:, 3]])
        return L, np.append(path[-1] - path[0], drift[3])

    # -- (P, L) -> motion -----------------------------------------------
    def _check(self, P: np.ndarray, L: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        P, L = np.asarray(P, dtype=np.float64), np.asarray(L, dtype=np.float64)
        N = P.shape[0]
        if P.shape != (N, self.n_periodic) or L.shape != (N, self.n_drifting):
            raise MocycleError(f"expected P ({N}, {self.n_periodic}) and L ({N}, 4); got {P.shape}, {L.shape}")
        return P, L

    def project(self, P: np.ndarray) -> np.ndarray:
        """Each joint's block of ``P (N, n_periodic)`` projected onto the nearest rotation: ``(N, J, 3, 3)``
        local rotation matrices, the travel joint's without its heading.  A joint whose block is the same
        on every row (one that never moves) is projected once."""
        P = np.asarray(P, dtype=np.float64)
        N, J = P.shape[0], self.n_joints
        M = P[:, : 9 * J].reshape(N, J, 3, 3)
        still = np.all(P[:, : 9 * J] == P[:1, : 9 * J], axis=0).reshape(J, 9).all(axis=1) if N > 1 \
            else np.zeros(J, dtype=bool)
        R = np.empty(M.shape)
        if still.any():
            R[:, still] = nearest_rotations(M[0, still])
        moving = np.flatnonzero(~still)
        # a few thousand matrices at a time: the copies and results stay small (the whole trial cycle of a
        # 100-joint rig at once, 3.6 MB per array, spent a quarter of its time on fresh pages)
        rows = max(1, PROJECT_MATRICES // max(1, moving.size))
        for r in range(0, N, rows):
            if moving.size == J:
                nearest_rotations(M[r:r + rows], out=R[r:r + rows])  # rows of R: contiguous
            elif moving.size:  # take: a contiguous copy, unlike M[:, moving]
                R[r:r + rows, moving] = nearest_rotations(np.take(M[r:r + rows], moving, axis=1))
        return R

    def rotations(self, P: np.ndarray, L: np.ndarray, projected: np.ndarray | None = None) -> np.ndarray:
        """The local rotation matrices ``(N, J, 3, 3)`` that :meth:`decode` puts in its motion:
        :meth:`project` of ``P`` (or ``projected``, when the caller has it), the travel joint turned to the
        heading ``L[:, 3]``."""
        P, L = self._check(P, L)
        R = self.project(P) if projected is None else projected.copy()
        R[:, self.travel] = self.heading_rotations(L) @ R[:, self.travel]
        return R

    def heading_rotations(self, L: np.ndarray) -> np.ndarray:
        """``(N, 3, 3)`` the turns about the vertical by the headings ``L[:, 3]`` that :meth:`rotations` puts
        on the travel joint (in its parent's frame)."""
        return axis_rotations(self.up, L[:, 3])

    def tracks(self, P: np.ndarray, L: np.ndarray) -> dict[int, np.ndarray]:
        """The local translations ``{joint: (N, 3)}`` of the joints that move (the travel joint's from ``L``)
        that :meth:`decode` puts in its motion; every other joint keeps ``static_translations``."""
        P, L = self._check(P, L)
        c0 = 9 * self.n_joints
        tracks = {j: P[:, c0 + 3 * k:c0 + 3 * k + 3].copy() for k, j in enumerate(self.moving)}
        tracks[self.travel] = L[:, :3].copy()
        return dict(sorted(tracks.items()))

    def translations(self, P: np.ndarray, L: np.ndarray) -> np.ndarray:
        """The local translations ``(N, J, 3)`` that :meth:`decode` puts in its motion."""
        tracks = self.tracks(P, L)
        trans = np.broadcast_to(self.static_translations, (len(L),) + self.static_translations.shape).copy()
        for j, track in tracks.items():
            trans[:, j] = track
        return trans

    def travel_path(self, rotations: np.ndarray, translations: np.ndarray,
                    travel_rotation: np.ndarray | None = None) -> np.ndarray:
        """World positions ``(N, 3)`` of the travel joint from local ``rotations (N, J, 3, 3)`` and
        ``translations (N, J, 3)``: forward kinematics along its chain from the root only (the products of
        :meth:`Motion.world_positions <mocycle.motion.Motion.world_positions>` for that joint).
        ``travel_rotation`` ``(N, 3, 3)``: the travel joint's rotation, in place of ``rotations[:, travel]``."""
        chain = self.skeleton.chain_to(self.travel)

        def local(j):
            return travel_rotation if j == self.travel and travel_rotation is not None else rotations[:, j]

        world_r, world_p = local(chain[0]), translations[:, chain[0]]
        for j in chain[1:]:
            world_p = world_p + (world_r @ translations[:, j, :, None])[..., 0]
            world_r = world_r @ local(j)
        return world_p

    def decode_rows(self, P: np.ndarray, L: np.ndarray) -> tuple[np.ndarray, dict[int, np.ndarray]]:
        """The local quaternions ``(B, J, 4)`` (not yet made sign-continuous) and translation tracks
        (:meth:`tracks`) of rows ``P (B, n_periodic)``, ``L (B, 4)``: :meth:`decode` a block of frames at a
        time."""
        return matrix_quats(self.rotations(P, L)), self.tracks(P, L)

    def decode(self, P: np.ndarray, L: np.ndarray, projected: np.ndarray | None = None) -> Motion:
        """A Motion on the space's skeleton and frame time from ``P (N, n_periodic)``, ``L (N, 4)``;
        ``projected``: :meth:`project` of ``P`` when the caller has it."""
        quats = continuous_quats(matrix_quats(self.rotations(P, L, projected)))
        return Motion(self.skeleton, quats, self.static_translations, self.frame_time, tracks=self.tracks(P, L),
                      copy=False)

    def decode_repeated(self, P: np.ndarray, L: np.ndarray, projected: np.ndarray, quats: np.ndarray,
                        count: int) -> Motion:
        """:meth:`decode` of ``P (N, n_periodic)`` repeated ``count`` times on the path ``L (count * N, 4)``, the
        same Motion, from ``projected`` (:meth:`project` of ``P``, ``(N, J, 3, 3)``) and its quaternions ``quats``
        ``(N, J, 4)`` (:func:`~mocycle.rotations.matrix_quats` of it): every joint but the travel joint has the
        same rotations in every repeat, so only the travel joint's, turned to each frame's heading, are
        converted (each matrix's quaternion depends on that matrix alone)."""
        N, J, travel = P.shape[0], self.n_joints, self.travel
        if L.shape != (count * N, self.n_drifting) or projected.shape != (N, J, 3, 3) or quats.shape != (N, J, 4):
            raise MocycleError(f"expected L ({count * N}, 4), projected ({N}, {J}, 3, 3) and quats ({N}, {J}, 4); "
                               f"got {L.shape}, {projected.shape}, {quats.shape}")
        # the travel joint's matrices laid out as decode's (a view of the repeated (count N, J, 3, 3) array)
        tiled = projected if count == 1 else np.tile(projected, (count, 1, 1, 1))
        q = np.tile(quats, (count, 1, 1))
        q[:, travel] = matrix_quats(self.heading_rotations(L) @ tiled[:, travel])
        P = P if count == 1 else np.tile(P, (count, 1))
        return Motion(self.skeleton, continuous_quats(q, inplace=True), self.static_translations, self.frame_time,
                      tracks=self.tracks(P, L), copy=False)


class EncodedRows:
    """The rows of :meth:`CycleSpace.encode`'s ``P`` made when read: ``rows[a:b]`` (a slice of frames) is
    ``P[a:b]`` ``(b - a, n_periodic)``; ``shape`` is ``P``'s.  What the harmonic fit reads of a long take
    instead of ``P`` (158 MB for 100k frames of 22 joints), a few times over."""

    def __init__(self, space: CycleSpace, motion: Motion, psi: np.ndarray):
        self.space, self.motion, self.psi = space, motion, psi
        self.shape = (motion.n_frames, space.n_periodic)
        self.ndim = 2

    def __getitem__(self, key: slice) -> np.ndarray:
        if not isinstance(key, slice) or key.step not in (None, 1):
            raise TypeError("EncodedRows reads a slice of frames")
        f0, f1, _ = key.indices(self.shape[0])
        out = np.empty((max(0, f1 - f0), self.shape[1]))
        for a in range(f0, f1, BLOCK_FRAMES):
            self.write(a, min(f1, a + BLOCK_FRAMES), out[a - f0:a - f0 + BLOCK_FRAMES])
        return out

    def write(self, f0: int, f1: int, out: np.ndarray) -> None:
        """Rows ``f0:f1`` of ``P`` into ``out`` ``(f1 - f0, n_periodic)``."""
        space, motion, J, travel = self.space, self.motion, self.space.n_joints, self.space.travel
        n = f1 - f0
        rot = out[:, :9 * J].reshape(n, J, 3, 3)
        rot[:] = Rotation.from_quat(motion.rotations[f0:f1].reshape(-1, 4)).as_matrix().reshape(n, J, 3, 3)
        turn = np.swapaxes(axis_rotations(space.up, self.psi[f0:f1]), 1, 2)  # the heading taken out
        rot[:, travel] = turn @ rot[:, travel]
        if space.moving:
            for k, j in enumerate(space.moving):
                out[:, 9 * J + 3 * k:9 * J + 3 * k + 3] = motion.joint_translations(j)[f0:f1]
