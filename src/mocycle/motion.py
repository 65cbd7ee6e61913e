"""The one data model: :class:`Skeleton` and :class:`Motion`.

Conventions
-----------
* Joints are ordered parents before children (the order of a BVH file).
* Rotations are local (relative to the parent), stored as unit quaternions in
  scipy's scalar-last order ``(x, y, z, w)``, shape ``(T, J, 4)``, and kept
  sign-continuous in time (``q[t] . q[t-1] >= 0``).
* Translations are local too, ``(T, J, 3)`` as :attr:`Motion.translations` shows them: for a joint with
  position channels they are the channel values (they *replace* the rest offset, as BVH exporters write
  them); for every other joint they equal the rest offset.  A motion stores them as one ``(J, 3)`` row of
  constant translations and a ``(T, 3)`` *track* per joint whose translation changes (usually the root
  alone): a long take costs its rotations, not three more floats per joint and frame.
  ``root_positions`` is ``translations[:, 0]``.
* Lengths are in the file's units; angles inside mocycle are radians.
* Objects are immutable in practice: every operation returns a new object.
"""

from __future__ import annotations

import fnmatch
import functools
import re
import sys
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from . import _validate
from .errors import MocycleError
from .limits import MAX_MAGNITUDE, check_frames, frame_time_problem
from .rotations import continuous_quats, vector_norms

ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")
POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")


@dataclass(frozen=True)
class EndSite:
    """A BVH ``End Site``: a leaf point below joint ``parent`` at ``offset``."""

    parent: int
    offset: tuple[float, float, float]
    name: str | None = None


@dataclass(frozen=True, eq=False)
class Skeleton:
    """Joint hierarchy with rest offsets and per-joint channel layout.

    Parameters
    ----------
    names : joint names, ``J`` strings (may contain spaces).
    parents : parent index per joint, ``-1`` for the root; parents come first.
    offsets : rest offsets from the parent, ``(J, 3)`` in file length units.
    channels : per joint, the channel names in file order, e.g.
        ``("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")``.
    end_sites : the End Sites, each with its parent joint and offset.
    up : the world vertical the file declares, a unit 3-vector in the skeleton's axes (glTF: +Y; FBX: its
        ``GlobalSettings``), or ``None`` when the file says nothing (BVH, ASF/AMC): then
        :func:`mocycle.axes.vertical_axis` finds it from the body.
    metres_per_unit : the length unit the file declares (glTF: 1; FBX: its ``UnitScaleFactor``), or ``None``;
        the glTF writer's ``scale="auto"`` uses it.
    """

    names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    channels: tuple[tuple[str, ...], ...]
    end_sites: tuple[EndSite, ...] = field(default=())
    up: tuple[float, float, float] | None = None
    metres_per_unit: float | None = None

    def __post_init__(self):
        names = tuple(str(n) for n in self.names)
        parents = np.asarray(self.parents, dtype=np.int64).reshape(-1)
        offsets = np.asarray(self.offsets, dtype=np.float64)
        channels = tuple(tuple(c) for c in self.channels)
        J = len(names)
        if J == 0:
            raise MocycleError("a skeleton needs at least one joint")
        if parents.shape != (J,) or offsets.shape != (J, 3) or len(channels) != J:
            raise MocycleError(
                f"skeleton arrays disagree: {J} names, parents {parents.shape}, "
                f"offsets {offsets.shape} (expected ({J}, 3)), {len(channels)} channel lists"
            )
        if parents[0] != -1 or np.any(parents[1:] < 0) or np.any(parents[1:] >= np.arange(1, J)):
            raise MocycleError("skeleton parents must list the root first (-1) and parents before children")
        if len(set(names)) != J:
            dup = sorted({n for n in names if names.count(n) > 1})
            raise MocycleError(f"joint names must be unique; repeated: {', '.join(dup)}")
        for name, ch in zip(names, channels, strict=True):
            bad = [c for c in ch if c not in ROTATION_CHANNELS + POSITION_CHANNELS]
            if bad or len(set(ch)) != len(ch):
                raise MocycleError(f"joint {name!r}: bad channel list {list(ch)}")
        if self.up is not None:
            up = np.asarray(self.up, dtype=np.float64).reshape(-1)
            norm = float(np.linalg.norm(up)) if up.shape == (3,) and np.isfinite(up).all() else 0.0
            if not norm > 0:
                raise MocycleError(f"the skeleton's up must be a non-zero 3-vector; got {self.up!r}")
            object.__setattr__(self, "up", tuple(float(v) for v in up / norm))
        if self.metres_per_unit is not None:
            unit = float(self.metres_per_unit)
            if not (np.isfinite(unit) and unit > 0):
                raise MocycleError(f"the skeleton's metres_per_unit must be positive; got {self.metres_per_unit!r}")
            object.__setattr__(self, "metres_per_unit", unit)
        parents.setflags(write=False)
        offsets.setflags(write=False)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "parents", parents)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "channels", channels)
        object.__setattr__(self, "end_sites", tuple(self.end_sites))

    # -- structure -------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return len(self.names)

    @property
    def n_channels(self) -> int:
        return sum(len(c) for c in self.channels)

    def index(self, name: str) -> int:
        """Index of the joint called ``name`` (exact match)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise MocycleError(f"no joint named {name!r}; joints are: {', '.join(self.names)}") from None

    def children(self, j: int) -> list[int]:
        return [int(c) for c in np.flatnonzero(self.parents == j)]

    def body_root(self) -> int:
        """The joint where the body branches: down from the root while a joint has exactly one child joint (a
        static ``joint_Root`` above ``Hips``), to the first with two or more (legs and spine); the root itself
        when it branches or when no joint does (a single chain)."""
        j = 0
        while True:
            kids = self.children(j)
            if len(kids) != 1:
                return j if len(kids) > 1 else 0
            j = kids[0]

    def chain_to(self, joint: int) -> list[int]:
        """The joints from the root down to ``joint`` (root first, ``joint`` last)."""
        chain = [int(joint)]
        while self.parents[chain[-1]] >= 0:
            chain.append(int(self.parents[chain[-1]]))
        return chain[::-1]

    def euler_order(self, j: int) -> str:
        """Rotation axes of joint ``j`` in channel order, e.g. ``"ZYX"`` ('' for none)."""
        return "".join(c[0] for c in self.channels[j] if c in ROTATION_CHANNELS)

    def position_axes(self, j: int) -> list[int]:
        """Axes (0=x, 1=y, 2=z) that joint ``j`` has position channels for, in channel order."""
        return [POSITION_CHANNELS.index(c) for c in self.channels[j] if c in POSITION_CHANNELS]

    def bone_lengths(self) -> np.ndarray:
        """Length of the bone each joint turns, ``(J,)``: its longest child offset.

        Children include End Sites; a joint with no child gets 0.
        """
        lengths = np.zeros(self.n_joints)
        norms = np.linalg.norm(self.offsets, axis=1)
        np.maximum.at(lengths, np.asarray(self.parents[1:], dtype=np.intp), norms[1:])
        for site in self.end_sites:
            lengths[site.parent] = max(lengths[site.parent], float(np.linalg.norm(site.offset)))
        return lengths

    def select(self, patterns: str | Iterable[str] | None) -> list[int]:
        """Joint indices matching names, glob patterns (case-insensitive) or group names.

        ``None`` selects every joint.  Group names are the keys of
        :data:`JOINT_GROUPS` (``"legs"``, ``"arms"``, ``"spine"``).  Unknown
        names raise with the list of joints.
        """
        if patterns is None:
            return list(range(self.n_joints))
        if isinstance(patterns, str):
            patterns = [p for p in patterns.split(",") if p.strip()]
        chosen: set[int] = set()
        for pat in patterns:
            pat = pat.strip()
            if pat in self.names:
                chosen.add(self.names.index(pat))
                continue
            globs = JOINT_GROUPS.get(pat.lower(), [pat])
            match = _glob_matcher(tuple(globs))
            hits = [j for j, n in enumerate(self.names) if match(n.lower())]
            if not hits:
                raise MocycleError(
                    f"no joint matches {pat!r}; joints are: {', '.join(self.names)}"
                )
            chosen.update(hits)
        return sorted(chosen)

    def same_as(self, other: Skeleton) -> bool:
        return (
            self.names == other.names
            and np.array_equal(self.parents, other.parents)
            and np.allclose(self.offsets, other.offsets)
        )


@functools.lru_cache(maxsize=256)
def _glob_matcher(globs: tuple[str, ...]):
    """One compiled regex for case-insensitive glob patterns (lower-cased names match), made once per
    pattern set: ``fnmatch.translate`` of a group's 30 patterns took longer than the selection itself."""
    return re.compile("|".join(fnmatch.translate(g.lower()) for g in globs)).match


#: Name patterns for common joint groups (CMU, Character Creator, Bandai and
#: the synthetic humanoid naming).
JOINT_GROUPS: dict[str, list[str]] = {
    "legs": ["*hipjoint*", "*leg*", "*thigh*", "*femur*", "*knee*", "*calf*", "*tibia*", "*shin*",
             "*foot*", "*ankle*", "*toe*"],
    "arms": ["*shoulder*", "*clavicle*", "*arm*", "*humerus*", "*elbow*", "*radius*", "*wrist*",
             "*hand*"],
    "spine": ["*spine*", "*back*", "*chest*", "*thorax*", "*waist*", "*neck*", "*head*", "*pelvis*"],
}


#: Frames per block of :meth:`Motion.world_positions` (its matrices take 168 bytes per joint and frame).
_FK_BLOCK = 4096


def _turned(R: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """``R @ offset`` ``(n, 3)``: rotations ``R`` ``(n, 3, 3)`` applied to one vector ``offset`` ``(3,)``, as one
    matrix-vector product over the ``3n`` rows (one BLAS call instead of one per frame; the same dot products
    of three, the same numbers)."""
    return (np.ascontiguousarray(R).reshape(-1, 3) @ offset).reshape(-1, 3)


def _forward_kinematics(quats: np.ndarray, translations: np.ndarray, parents,
                        tracked: Iterable[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """World rotations ``(T, J, 3, 3)`` and positions ``(T, J, 3)`` of local ``quats`` (T, J, 4) and
    ``translations`` (T, J, 3) (parents before children).  ``tracked``: the joints whose translation may
    change from frame to frame (default all); every other joint's is ``translations[0, j]`` throughout."""
    T, J = quats.shape[:2]
    moving = set(range(J)) if tracked is None else set(tracked)
    local = Rotation.from_quat(quats.reshape(-1, 4)).as_matrix().reshape(T, J, 3, 3)
    world_r = np.empty_like(local)
    world_p = np.empty((T, J, 3))
    world_r[:, 0] = local[:, 0]
    world_p[:, 0] = translations[:, 0]
    for j in range(1, J):
        p = parents[j]
        world_r[:, j] = world_r[:, p] @ local[:, j]
        if j in moving:
            world_p[:, j] = world_p[:, p] + (world_r[:, p] @ translations[:, j, :, None])[..., 0]
        else:
            world_p[:, j] = world_p[:, p] + _turned(world_r[:, p], translations[0, j])
    return world_r, world_p


def chain_forward_kinematics(motion: Motion, chain: list[int], rows: slice, Rw: np.ndarray, W: np.ndarray) -> None:
    """Forward kinematics of ``chain`` (joints with all their ancestors, parents first) over the frames
    ``rows``, into ``Rw`` ``(n, len(chain), 3, 3)`` and ``W`` ``(n, len(chain), 3)`` (columns in chain order).  The
    chain's local rotation matrices are made at once (one more array of ``Rw``'s size, while it is filled: one
    scipy ``Rotation`` instead of one per joint).  The same numbers as :func:`_forward_kinematics`."""
    parents = motion.skeleton.parents
    column = {int(j): i for i, j in enumerate(chain)}
    n = Rw.shape[0]
    local = Rotation.from_quat(motion.rotations[rows][:, chain].reshape(-1, 4)).as_matrix().reshape(n, len(chain), 3, 3)
    tracked = motion.tracked_joints
    for i, j in enumerate(chain):
        p = int(parents[j])
        if p < 0:
            Rw[:, i] = local[:, i]
            W[:, i] = motion.joint_translations(j)[rows]
        else:
            Rp = Rw[:, column[p]]
            np.matmul(Rp, local[:, i], out=Rw[:, i])
            if j in tracked:
                t = np.ascontiguousarray(motion.joint_translations(j)[rows])
                W[:, i] = W[:, column[p]] + (Rp @ t[..., None])[..., 0]
            else:  # the same offset on every frame
                W[:, i] = W[:, column[p]] + _turned(Rp, motion._static[j])


def chain_kinematics_blocks(motion: Motion, chain: list[int], block: int):
    """:func:`chain_forward_kinematics` a block of ``block`` frames at a time: yields ``(rows, Rw, W)``, the
    frames (a slice) and their world rotations ``(n, len(chain), 3, 3)`` and positions ``(n, len(chain), 3)``
    (one pair of buffers, reused: read a block before asking for the next)."""
    T = motion.n_frames
    Rw = np.empty((min(T, block), len(chain), 3, 3))
    W = np.empty((min(T, block), len(chain), 3))
    for start in range(0, T, block):
        rows = slice(start, min(T, start + block))
        n = rows.stop - start
        chain_forward_kinematics(motion, chain, rows, Rw[:n], W[:n])
        yield rows, Rw[:n], W[:n]


def _check_translations(trans: np.ndarray) -> None:
    """Refuse translations with NaN or infinite values or beyond ±MAX_MAGNITUDE (two reductions: NaN propagates)."""
    if not trans.size:
        return
    high, low = trans.max(), trans.min()
    if not (np.isfinite(high) and np.isfinite(low)):
        raise MocycleError("translations contain NaN or infinite values")
    reach = max(high, -low)
    if reach > MAX_MAGNITUDE:
        raise MocycleError(f"translations reach {reach:.3g}, beyond ±{MAX_MAGNITUDE:g}")


def _float_array(values, copy: bool) -> np.ndarray:
    """``values`` as float64: a copy, or (``copy=False``) the caller's array itself when it is one already."""
    return np.array(values, dtype=np.float64, copy=True) if copy else np.asarray(values, dtype=np.float64)


def _split_translations(trans: np.ndarray) -> tuple[np.ndarray, dict[int, np.ndarray]]:
    """A ``(T, J, 3)`` array of local translations as a motion stores them: the first frame's ``(J, 3)`` and
    a ``(T, 3)`` track (a copy) for each joint whose translation changes at all (compared exactly)."""
    static = np.array(trans[0], dtype=np.float64)
    tracks = {}
    for j in range(trans.shape[1]):
        column = trans[:, j]
        if not np.array_equal(column, np.broadcast_to(column[0], column.shape)):
            tracks[j] = np.array(column, dtype=np.float64)
    return static, tracks


def _translation_parts(T: int, J: int, static, translations, root_positions, tracks, copy: bool):
    """The checked ``(J, 3)`` constant translations and ``{joint: (T, 3)}`` tracks of a new motion: from
    ``translations`` (``(T, J, 3)``, or ``(J, 3)`` for every frame, or ``None`` for ``static``), then
    ``root_positions`` (the root's track) and ``tracks`` on top."""
    track_of: dict[int, np.ndarray] = {}
    if translations is not None:
        trans = np.asarray(translations, dtype=np.float64)  # the tracks are copied from it: no copy first
        if trans.shape == (T, J, 3):
            static, track_of = _split_translations(trans)
        elif trans.shape != (J, 3):
            raise MocycleError(f"translations must have shape ({T}, {J}, 3) or ({J}, 3); got {trans.shape}")
        else:
            static = trans
    static = np.array(static, dtype=np.float64)  # small: never a caller's array, frozen
    if static.shape != (J, 3):
        raise MocycleError(f"constant translations must have shape ({J}, 3); got {static.shape}")
    if root_positions is not None:
        tracks = {**(tracks or {}), 0: root_positions}
    for j, track in (tracks or {}).items():
        if isinstance(j, bool) or not isinstance(j, (int, np.integer)) or not 0 <= j < J:
            raise MocycleError(f"a translation track for joint {j!r}, but the skeleton's joints are 0 to {J - 1}")
        track = _float_array(track, copy)
        if track.shape != (T, 3):
            name = "root_positions" if root_positions is not None and j == 0 else f"the track of joint {j}"
            raise MocycleError(f"{name} must have shape ({T}, 3); got {track.shape}")
        track_of[int(j)] = track
    _check_translations(static)
    for track in track_of.values():
        _check_translations(track)
        track.setflags(write=False)
    static.setflags(write=False)
    return static, dict(sorted(track_of.items()))


class Motion:
    """A take: skeleton, local rotations, local translations and the exact frame time.

    Parameters
    ----------
    skeleton : :class:`Skeleton` with ``J`` joints.
    rotations : ``(T, J, 4)`` unit quaternions ``(x, y, z, w)`` (normalised and
        made sign-continuous here), or a ``(T, J, 3, 3)`` array of matrices.
    translations : ``(T, J, 3)`` local translations, ``(J, 3)`` the same at every frame, or ``None`` for the
        rest offsets at every frame.  Stored as constant translations and a track per joint that moves.
    frame_time : seconds per frame (> 0).
    root_positions : ``(T, 3)``; a shortcut that sets ``translations[:, 0]``.
    tracks : ``{joint: (T, 3)}`` translations of the joints that move (over ``translations``).
    copy : ``False`` hands the float64 ``rotations`` and track arrays over to the motion, which then
        normalises and freezes them in place instead of copying them (what the readers do: half the memory).
    """

    __slots__ = ("skeleton", "rotations", "_static", "_tracks", "frame_time", "_travel", "_cache")
    _cache: dict[str, Any]  # Motion.cache's values

    def __init__(
        self,
        skeleton: Skeleton,
        rotations: np.ndarray,
        translations: np.ndarray | None = None,
        frame_time: float = 1 / 30,
        root_positions: np.ndarray | None = None,
        *,
        tracks: dict[int, np.ndarray] | None = None,
        copy: bool = True,
    ):
        J = skeleton.n_joints
        rot = np.asarray(rotations, dtype=np.float64)
        if rot.ndim == 4 and rot.shape[-2:] == (3, 3):
            T = rot.shape[0]
            rot = Rotation.from_matrix(rot.reshape(-1, 3, 3)).as_quat().reshape(T, J, 4)
        if rot.ndim != 3 or rot.shape[1:] != (J, 4):
            raise MocycleError(f"rotations must have shape (T, {J}, 4); got {rot.shape}")
        T = rot.shape[0]
        if T < 1:
            raise MocycleError("a motion needs at least one frame")
        # the caller hands its float64 array over (readers): normalised in place, no copy
        out = np.empty(rot.shape) if copy or rot is not rotations or not rot.flags.writeable else rot
        for f0 in range(0, T, 4096):  # in blocks of frames: the norms and numpy's temporaries stay small
            norms = vector_norms(rot[f0:f0 + 4096], keepdims=True)
            # a NaN or infinite component makes the norm NaN or infinite: a (T, J) check instead of (T, J, 4)
            if not np.all(np.isfinite(norms)) or np.any(norms < 1e-12):
                raise MocycleError("rotations contain NaN, infinite or zero quaternions")
            np.divide(rot[f0:f0 + 4096], norms, out=out[f0:f0 + 4096])
        rot = continuous_quats(out, inplace=True)
        static, track_of = _translation_parts(T, J, skeleton.offsets, translations, root_positions, tracks, copy)
        frame_time = _validate.positive("frame_time", frame_time)
        if frame_time_problem(frame_time):
            raise MocycleError(frame_time_problem(frame_time))
        rot.setflags(write=False)
        self.skeleton = skeleton
        self.rotations = rot
        self._static = static
        self._tracks = track_of
        self.frame_time = frame_time

    @classmethod
    def _adopt(cls, skeleton: Skeleton, rotations: np.ndarray, static: np.ndarray, tracks: dict[int, np.ndarray],
               frame_time: float) -> Motion:
        """A motion that takes the arrays as they are: for readers that made them and checked them as
        ``__init__`` does (float64 unit, sign-continuous quaternions ``(T, J, 4)``, finite ``(J, 3)`` constant
        translations and ``{joint: (T, 3)}`` tracks, sorted by joint, within ±MAX_MAGNITUDE, a checked frame
        time).  Only the shapes are checked again; the arrays are frozen, not copied."""
        J = skeleton.n_joints
        T = rotations.shape[0]
        if T < 1 or rotations.shape != (T, J, 4) or rotations.dtype != np.float64 or static.shape != (J, 3) \
                or any(not 0 <= j < J or t.shape != (T, 3) or t.dtype != np.float64 for j, t in tracks.items()):
            raise MocycleError(f"rotations (T, {J}, 4), translations ({J}, 3) and (T, 3) tracks of T >= 1 frames "
                               f"expected; got {rotations.shape}, {static.shape} and "
                               f"{[t.shape for t in tracks.values()]}")
        self = object.__new__(cls)
        rotations.setflags(write=False)
        static.setflags(write=False)
        for t in tracks.values():
            t.setflags(write=False)
        self.skeleton = skeleton
        self.rotations = rotations
        self._static = static
        self._tracks = tracks
        self.frame_time = float(frame_time)
        return self

    # -- basic facts -----------------------------------------------------
    @property
    def n_frames(self) -> int:
        return self.rotations.shape[0]

    def __len__(self) -> int:
        return self.n_frames

    @property
    def n_joints(self) -> int:
        return self.skeleton.n_joints

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.n_frames - 1) * self.frame_time

    @property
    def root_positions(self) -> np.ndarray:
        """``(T, 3)`` root translation per frame (read-only)."""
        return self.joint_translations(0)

    # -- translations ----------------------------------------------------
    @property
    def translations(self) -> np.ndarray:
        """``(T, J, 3)`` local translations (read-only).  Made on each use from the constant translations and the
        tracks (a view, if no joint moves): a long take's code asks :meth:`joint_translations` or
        :meth:`translations_at` for what it needs instead."""
        if not self._tracks:
            return np.broadcast_to(self._static, (self.n_frames,) + self._static.shape)
        out = self.translations_at(slice(None))
        out.setflags(write=False)
        return out

    @property
    def tracked_joints(self) -> tuple[int, ...]:
        """The joints whose translations are stored per frame (in order): every joint whose translation changes
        is one of them (a slice of a take may hold some that stand still in it)."""
        return tuple(self._tracks)

    @property
    def tracks(self) -> dict[int, np.ndarray]:
        """``{joint: (T, 3)}``: the stored translations of :attr:`tracked_joints` (read-only; a new dict)."""
        return dict(self._tracks)

    def moving_joints(self, tol: float = 0.0) -> list[int]:
        """The joints whose local translation changes by more than ``tol`` (file units, peak to peak along an
        axis) over the take, in order."""
        return [j for j, track in self._tracks.items() if np.ptp(track, axis=0).max() > tol]

    def joint_translations(self, joint: int) -> np.ndarray:
        """``(T, 3)`` local translations of one joint (read-only; a view, not a copy)."""
        track = self._tracks.get(joint)
        if track is not None:
            return track
        return np.broadcast_to(self._static[joint], (self.n_frames, 3))

    def translations_at(self, index) -> np.ndarray:
        """The local translations of the frames ``index`` (a new array): ``(J, 3)`` for a frame number,
        ``(n, J, 3)`` for a slice or an array of frame numbers."""
        rows = np.broadcast_to(np.int8(0), (self.n_frames,))[index]  # the selection's shape, nothing allocated
        out = np.empty(np.shape(rows) + self._static.shape)
        out[...] = self._static
        for j, track in self._tracks.items():
            out[..., j, :] = track[index]
        return out

    @property
    def travel_joint(self) -> int:
        """Index of the joint whose translation carries the travel: the first joint
        (parents first) whose local translation changes over the take; in a take where
        none changes (one frame, a still pose) the body's root (:meth:`Skeleton.body_root`).

        Usually the root; in files such as the Bandai Namco set the root is a
        static ``joint_Root`` and ``Hips`` carries the motion in its position channels.
        A one-frame take cannot show which joint moves: taking the file's root there
        would put ``joint_Root``, at the room's origin metres away, into the body (its
        size, its vertical: a one-frame Bandai take was 457 units tall and lay on -Z).
        """
        known = getattr(self, "_travel", None)  # the arrays are read-only: found once per motion
        if known is None:
            moving = self.moving_joints(1e-9)
            known = self._travel = moving[0] if moving else self.skeleton.body_root()
        return known

    def cache(self, key: str, make: Callable[[Motion], Any] | None = None) -> Any:
        """A value derived from this motion, made by ``make(motion)`` on the first call with ``key`` and kept
        with the motion after that; with no ``make``, the kept value or ``None``.

        The motion's arrays are read-only, so a derived value never goes stale: what several steps of one
        run each need (the vertical axis, the heading frame) is computed once per motion.  A value is
        returned as it was kept: make it read-only, or copy it where the caller may change it.  ``key`` names
        the value; the modules that keep one say which (``"up"``: :func:`mocycle.axes.vertical_axis`,
        ``"heading"`` and ``"heading tilt"``: :class:`mocycle.features.HeadingFrame`, ``"heading degrees"``:
        :func:`mocycle.activities.heading_degrees`).

        Examples
        --------
        >>> from mocycle.datasets import synthetic_walk
        >>> walk = synthetic_walk(n_frames=60).motion
        >>> walk.cache("frames x2") is None
        True
        >>> walk.cache("frames x2", lambda m: 2 * m.n_frames), walk.cache("frames x2", lambda m: 0)
        (120, 120)
        """
        kept = getattr(self, "_cache", None)
        if kept is None:
            kept = self._cache = {}
        if key not in kept:
            if make is None:
                return None
            kept[key] = make(self)
        return kept[key]

    def __repr__(self) -> str:
        return (
            f"Motion({self.n_frames} frames, {self.n_joints} joints, "
            f"{self.fps:.6g} fps, {self.duration:.3f} s)"
        )

    # -- rotations -------------------------------------------------------
    def rotation(self, joint: int | str) -> Rotation:
        """The local rotations of one joint as a scipy ``Rotation`` of length T."""
        j = self.skeleton.index(joint) if isinstance(joint, str) else joint
        return Rotation.from_quat(self.rotations[:, j])

    def rotation_matrices(self) -> np.ndarray:
        """``(T, J, 3, 3)`` local rotation matrices."""
        T, J = self.n_frames, self.n_joints
        return Rotation.from_quat(self.rotations.reshape(-1, 4)).as_matrix().reshape(T, J, 3, 3)

    # -- forward kinematics ---------------------------------------------
    def world_transforms(self) -> tuple[np.ndarray, np.ndarray]:
        """World rotations ``(T, J, 3, 3)`` and world joint positions ``(T, J, 3)``."""
        return _forward_kinematics(self.rotations, self.translations, self.skeleton.parents, self._tracks)

    def world_positions(self, end_sites: bool = False, step: int = 1) -> np.ndarray:
        """Forward kinematics: world joint positions ``(T, J, 3)`` in file units.

        Computed in blocks of frames, so that the ``(T, J, 3, 3)`` rotation matrices are never held whole.

        Parameters
        ----------
        end_sites : append the End Site points: ``(T, J + E, 3)``.
        step : every ``step``-th frame only: the same numbers as ``motion[::step].world_positions()``, without
            making that motion (a sample of a take's frames, as :func:`mocycle.contacts.body_height` takes).

        Returns
        -------
        ``(T, J, 3)`` (or ``(T, J + E, 3)``) float array, joints in skeleton order (``T``: the frames taken).

        Examples
        --------
        >>> from mocycle.datasets import synthetic_walk
        >>> walk = synthetic_walk(n_frames=300, fps=60).motion
        >>> walk.world_positions().shape, walk.world_positions(end_sites=True).shape
        ((300, 22, 3), (300, 27, 3))
        """
        ends = self.skeleton.end_sites if end_sites else []
        step = int(step)
        if step < 1:
            raise ValueError(f"step must be a positive whole number; got {step}")
        quats = self.rotations[::step]
        T, J = quats.shape[0], self.n_joints
        out = np.empty((T, J + len(ends), 3))
        for f0 in range(0, T, _FK_BLOCK):
            block = slice(f0, f0 + _FK_BLOCK)
            q = quats[block]
            if step > 1:  # normalised again, as Motion() does those of motion[::step]
                q = q / vector_norms(q, keepdims=True)
            frames = slice(f0 * step, (f0 + _FK_BLOCK) * step, step)
            world_r, world_p = _forward_kinematics(q, self.translations_at(frames), self.skeleton.parents,
                                                   self._tracks)
            out[block, :J] = world_p
            for k, s in enumerate(ends):
                out[block, J + k] = world_p[:, s.parent] + _turned(world_r[:, s.parent], np.asarray(s.offset))
        return out

    def joint_path(self, joint: int) -> np.ndarray:
        """World positions ``(T, 3)`` of one joint (the same numbers as ``world_positions()[:, joint]``): forward
        kinematics of its chain from the root only, a block of frames at a time."""
        out = np.empty((self.n_frames, 3))
        for rows, _, W in chain_kinematics_blocks(self, self.skeleton.chain_to(joint), _FK_BLOCK):
            out[rows] = W[:, -1]
        return out

    # -- new motions -----------------------------------------------------
    def replace(self, *, copy: bool = True, **changes) -> Motion:
        """A copy with some of ``skeleton``, ``rotations``, ``translations``, ``tracks``, ``frame_time`` changed.

        ``translations`` (``(T, J, 3)`` or ``(J, 3)``) replaces every joint's; ``tracks`` (``{joint: (T, 3)}``)
        replaces some joints' over the others.  Arrays not changed are shared (they are read-only), not copied.
        ``copy=False``: the caller hands the new arrays over (they are normalised in place and frozen, as
        ``Motion(..., copy=False)`` does)."""
        unknown = set(changes) - {"skeleton", "rotations", "translations", "tracks", "frame_time"}
        if unknown:
            raise TypeError(f"replace() got unexpected changes: {', '.join(sorted(unknown))}")
        kept = {} if "translations" in changes else dict(self._tracks)  # checked already: shared, not copied
        given = changes.get("tracks") or {}
        if "skeleton" not in changes and "rotations" not in changes:  # the checked rotations are kept as they are
            frame_time = _validate.positive("frame_time", changes.get("frame_time", self.frame_time))
            if frame_time_problem(frame_time):
                raise MocycleError(frame_time_problem(frame_time))
            static = self._static
            if "translations" in changes or given:
                static, new = _translation_parts(self.n_frames, self.n_joints, static, changes.get("translations"),
                                                 None, given, copy)
                kept = dict(sorted({**kept, **new}.items()))
            return Motion._adopt(self.skeleton, self.rotations, static, kept, frame_time)
        return Motion(changes.get("skeleton", self.skeleton), changes.get("rotations", self.rotations),
                      changes.get("translations", self._static), changes.get("frame_time", self.frame_time),
                      tracks={**kept, **given}, copy=copy)

    def hand_over(self) -> tuple[np.ndarray, np.ndarray, dict[int, np.ndarray]]:
        """The motion's ``rotations``, constant translations ``(J, 3)`` and tracks, writable, for a caller that
        makes the next motion from them and holds the last reference to this one (a long take's edit without a
        copy of it: ``Motion(skeleton, rotations, static, frame_time, tracks=tracks, copy=False)``).

        The motion is emptied: any later use of it raises AttributeError.  An array that another object may
        see (a view, a view's base or an array another motion shares, as :meth:`replace` and slices share
        them) is copied instead, so handing over never changes what anyone else holds."""
        probe = np.empty(0)  # an array only a local name holds: the count of a sole reference, measured alike
        static, tracks = self._static.copy(), self._tracks  # each motion has its own dict of tracks
        arrays = [self.rotations]
        self._cache = {}  # values derived from the arrays go with them
        del self.rotations, self._static, self._tracks
        joints = list(tracks)
        arrays += [tracks.pop(j) for j in joints]
        out = []
        for _ in range(len(arrays)):
            array = arrays.pop(0)
            # any other holder (a view holds its base) counts one more than the probe
            if array.base is None and sys.getrefcount(array) <= sys.getrefcount(probe):
                array.setflags(write=True)
            else:
                array = array.copy()
            out.append(array)
            del array
        return out[0], static, dict(zip(joints, out[1:], strict=True))

    def __getitem__(self, index) -> Motion:
        """Frames by slice (``motion[10:200]``, ``motion[::2]``) or index array.

        A slice of consecutive frames shares this motion's (read-only) arrays: it is a view, not a copy."""
        if isinstance(index, (int, np.integer)):
            index = slice(int(index), int(index) + 1 if index != -1 else None)
        step = index.step if isinstance(index, slice) and index.step else 1
        rot = self.rotations[index]
        if rot.shape[0] == 0:
            raise MocycleError(f"frame selection {index!r} is empty (motion has {self.n_frames} frames)")
        tracks = {j: track[index] for j, track in self._tracks.items()}
        if isinstance(index, slice) and step == 1:  # unit, continuous and checked already
            return Motion._adopt(self.skeleton, rot, self._static, tracks, self.frame_time)
        return Motion(self.skeleton, rot, self._static, self.frame_time * step, tracks=tracks, copy=False)

    def slice(self, start: int = 0, stop: int | None = None) -> Motion:
        """Frames ``start`` (inclusive) to ``stop`` (exclusive); negative indices count from the end."""
        return self[start:stop]

    def resample(self, fps: float) -> Motion:
        """Resample to ``fps`` frames per second over the same duration.

        Rotations are interpolated by slerp, translations linearly.  The first frame is kept; the last new
        frame is the old last frame when the new frame time divides the duration, else the last new frame
        before it.  The frame time is taken as the rate it was rounded from (:func:`frame_time_fraction`: a
        file's ``0.0333333`` is 1/30 s), so the count is exact at any length: 273 frames at 30 fps give 545
        at 60 fps, 108,000 give 431,997 at 120 fps, and every fourth new frame is an old one.
        """
        from fractions import Fraction

        fps = _validate.positive("fps", fps)
        if frame_time_problem(1.0 / fps):
            raise MocycleError(f"fps must be a positive number within [1e-4, 1e6]; got {fps:g}")
        new_dt = 1.0 / fps
        if self.n_frames == 1:
            return self.replace(frame_time=new_dt)
        # old frames per new frame, exactly: the new frames fall at k * step in old frames
        step = 1 / (Fraction(repr(float(fps))) * frame_time_fraction(self.frame_time))
        n_new = check_frames((self.n_frames - 1) // step + 1, self.n_joints,
                             f"resampling {self.n_frames} frames to {fps:g} fps")
        old_t = np.arange(self.n_frames, dtype=np.float64)
        new_t = np.minimum(np.arange(n_new) * float(step), old_t[-1])
        rot = np.empty((n_new, self.n_joints, 4))
        for j in range(self.n_joints):
            rot[:, j] = Slerp(old_t, Rotation.from_quat(self.rotations[:, j]))(new_t).as_quat()
        tracks = {j: np.stack([np.interp(new_t, old_t, col) for col in track.T], axis=1)
                  for j, track in self._tracks.items()}
        return Motion(self.skeleton, rot, self._static, new_dt, tracks=tracks, copy=False)

    @classmethod
    def rest(cls, skeleton: Skeleton, n_frames: int = 1, frame_time: float = 1 / 30) -> Motion:
        """The rest pose (identity rotations, rest offsets) repeated ``n_frames`` times."""
        q = np.zeros((n_frames, skeleton.n_joints, 4))
        q[..., 3] = 1.0
        return cls(skeleton, q, None, frame_time)


def frame_time_fraction(frame_time: float):
    """The frame time (s) as the exact fraction it was rounded from: ``1/N`` or NTSC's ``1001/(1000 N)`` s for
    the whole rate ``N`` nearest to it when that lies within half a unit of the last digit of its shortest
    decimal, or rounds to the same float (``0.0333333`` -> 1/30, ``0.016667`` -> 1/60, ``0.0333667`` ->
    1001/30000, ``1 / 60`` -> 1/60), else the decimal itself (``0.0123456789``).  A ``fractions.Fraction``.
    """
    import math
    from decimal import Decimal
    from fractions import Fraction

    x = float(frame_time)
    text = Decimal(repr(x))
    value = Fraction(text)
    exponent = text.as_tuple().exponent
    half = max(Fraction(1, 2) * Fraction(10) ** (exponent if isinstance(exponent, int) else 0),
               Fraction(math.ulp(x)) / 2)
    for ntsc in (Fraction(1), Fraction(1001, 1000)):
        rate = round(ntsc / value)
        if rate >= 1 and abs(ntsc / rate - value) <= half:
            return ntsc / rate
    return value


def concatenate(motions: Sequence[Motion]) -> Motion:
    """Frames of several motions with the same skeleton and frame time, one after another."""
    first = motions[0]
    for m in motions[1:]:
        if not m.skeleton.same_as(first.skeleton):
            raise MocycleError("cannot concatenate motions with different skeletons")
        if not np.isclose(m.frame_time, first.frame_time):
            raise MocycleError("cannot concatenate motions with different frame times")
    static = first.translations_at(0)
    moving = {j for m in motions for j in m.tracked_joints}
    moving |= {j for m in motions for j in np.flatnonzero((m.translations_at(0) != static).any(axis=1)).tolist()}
    return Motion(
        first.skeleton,
        np.concatenate([m.rotations for m in motions]),
        static,
        first.frame_time,
        tracks={j: np.concatenate([m.joint_translations(j) for m in motions]) for j in sorted(moving)},
        copy=False,
    )
