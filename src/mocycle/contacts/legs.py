"""The legs of any humanoid skeleton: which joints are the feet, which way is up, and the legs' chains
(their forward kinematics a block of frames at a time).

A :class:`Foot` is one leg's chain for two-bone IK (hip, knee, ankle) and its
contact joints: the ankle (heel) and, when the rig has one, the toe (ball of
the foot).  They are found by name patterns that cover the common rigs:

* CMU ASF ``lfemur/ltibia/lfoot/ltoes``, CMU BVH and Mixamo
  ``LeftUpLeg/LeftLeg/LeftFoot/LeftToeBase`` (``mixamorig:`` prefix allowed),
* Bandai Namco ``UpperLeg_L/LowerLeg_L/Foot_L/Toes_L``,
* Character Creator / iClone ``CC_Base_L_Thigh/CC_Base_L_Calf/CC_Base_L_Foot/CC_Base_L_ToeBase``,

and, when they fail, named by the caller (``"lfoot:ltoes,rfoot:rtoes"``).
The knee and hip are the ankle's parent and grandparent, skipping joints
whose offset is too short to be a leg bone (twist or helper joints).
"""

from __future__ import annotations

import fnmatch
import re
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..axes import vertical_axis
from ..errors import MocycleError
from ..motion import Motion, Skeleton, chain_forward_kinematics, chain_kinematics_blocks

#: Glob patterns (case-insensitive) of ankle joints and toe joints.
ANKLE_PATTERNS = ("*foot", "*foot_l", "*foot_r", "*foot.l", "*foot.r", "*ankle*", "?foot*", "foot*")
TOE_PATTERNS = ("*toebase", "*toe", "*toes", "*toes_l", "*toes_r", "*toe_l", "*toe_r", "*toebase_l",
                "*toebase_r", "*ball*", "*toe.l", "*toe.r")
_LEFT = re.compile(r"(^|[^a-z])l($|[^a-z])|left|^l(?=foot|toe|ankle|femur|tibia)")
_RIGHT = re.compile(r"(^|[^a-z])r($|[^a-z])|right|^r(?=foot|toe|ankle|femur|tibia)")
SHORT_BONE = 0.05  # of the body height: a shorter offset is a helper joint, not a leg bone
MAX_LISTED = 12


@dataclass(frozen=True)
class Foot:
    """One leg: ``side`` (``"left"``, ``"right"`` or the ankle's name), joint indices ``hip``, ``knee``,
    ``ankle`` and ``toe`` (``None`` when the rig has no toe joint)."""

    side: str
    hip: int
    knee: int
    ankle: int
    toe: int | None

    @property
    def contact_joints(self) -> tuple[int, ...]:
        """The joints that touch the floor: ankle (heel) and toe."""
        return (self.ankle,) if self.toe is None else (self.ankle, self.toe)

    def names(self, skeleton: Skeleton) -> dict[str, str | None]:
        return self.names_of(skeleton.names)

    def names_of(self, n: Sequence[str]) -> dict[str, str | None]:
        return {"hip": n[self.hip], "knee": n[self.knee], "ankle": n[self.ankle],
                "toe": None if self.toe is None else n[self.toe]}


def _bare(name: str) -> str:
    """The lower-case name without a namespace prefix (``mixamorig:LeftFoot`` -> ``leftfoot``)."""
    return name.rsplit(":", 1)[-1].rsplit("|", 1)[-1].lower()


_GLOBS: dict[tuple[str, ...], re.Pattern] = {}


def _matches(name: str, patterns: Sequence[str]) -> bool:
    glob = _GLOBS.get(tuple(patterns))
    if glob is None:   # the patterns as one regular expression (a 100-joint rig is matched in well under 1 ms)
        glob = _GLOBS[tuple(patterns)] = re.compile("|".join(fnmatch.translate(p) for p in patterns))
    return glob.match(_bare(name)) is not None


def side_of(name: str) -> str | None:
    """``"left"``, ``"right"`` or ``None`` from a joint name."""
    n = _bare(name)
    left, right = bool(_LEFT.search(n)), bool(_RIGHT.search(n))
    return "left" if left and not right else "right" if right and not left else None


def _ancestors(skeleton: Skeleton, j: int) -> list[int]:
    out = []
    while skeleton.parents[j] >= 0:
        j = int(skeleton.parents[j])
        out.append(j)
    return out


def _descendants(skeleton: Skeleton, j: int) -> list[int]:
    """Joints below ``j``, nearest first."""
    out, frontier = [], [j]
    while frontier:
        nxt = [c for f in frontier for c in skeleton.children(f)]
        out.extend(nxt)
        frontier = nxt
    return out


def _rest_height(skeleton: Skeleton) -> float:
    """A length scale of the rig from its offsets alone: the longest root-to-leaf chain of offsets."""
    lengths = np.zeros(skeleton.n_joints)
    norms = np.linalg.norm(skeleton.offsets, axis=1)
    for j in range(1, skeleton.n_joints):
        lengths[j] = lengths[skeleton.parents[j]] + norms[j]
    return float(lengths.max()) or 1.0


def _leg(skeleton: Skeleton, ankle: int, toe: int | None, side: str) -> Foot:
    """Knee and hip above ``ankle``: the nearest ancestors whose offsets are long enough to be leg bones."""
    short = SHORT_BONE * _rest_height(skeleton)
    norms = np.linalg.norm(skeleton.offsets, axis=1)
    chain, j = [], ankle
    for _ in range(2):
        # the bone ending at j is j's offset; a helper joint (short offset) in between is skipped
        p = int(skeleton.parents[j])
        while p >= 0 and norms[j] < short and skeleton.parents[p] >= 0:
            j, p = p, int(skeleton.parents[p])
        if p < 0:
            raise MocycleError(f"foot joint {skeleton.names[ankle]!r} has no knee and hip above it")
        chain.append(p)
        j = p
    knee, hip = chain
    return Foot(side, hip, knee, ankle, toe)


def _toe_below(skeleton: Skeleton, ankle: int) -> int | None:
    below = _descendants(skeleton, ankle)
    hits = [j for j in below if _matches(skeleton.names[j], TOE_PATTERNS)]
    if not hits:
        hits = [j for j in below if "toe" in _bare(skeleton.names[j]) and "share" not in _bare(skeleton.names[j])]
    if not hits:
        kids = skeleton.children(ankle)  # a single child of the ankle is the ball of the foot
        return kids[0] if len(kids) == 1 else None
    return hits[0]


def _listed(skeleton: Skeleton) -> str:
    names = skeleton.names
    shown = ", ".join(names[:MAX_LISTED])
    return shown + (f" and {len(names) - MAX_LISTED} more" if len(names) > MAX_LISTED else "")


def _split_item(skeleton: Skeleton, item: str) -> tuple[str, str]:
    """``"ANKLE:TOE"`` or ``"ANKLE"`` into names; a ``:`` inside a joint name (``mixamorig:LeftFoot``) is
    kept by trying every split."""
    if item in skeleton.names:
        return item, ""
    for k in [m.start() for m in re.finditer(":", item)]:
        a, t = item[:k], item[k + 1:]
        if a in skeleton.names and t in skeleton.names:
            return a, t
    a, _, t = item.partition(":")
    return a, t


def _named(skeleton: Skeleton, spec: str | Sequence[str]) -> list[Foot]:
    items = [s.strip() for s in spec.split(",")] if isinstance(spec, str) else [s.strip() for s in spec]
    items = [s for s in items if s]
    if not items:
        raise MocycleError("name the feet as ANKLE[:TOE],ANKLE[:TOE] (e.g. lfoot:ltoes,rfoot:rtoes)")
    feet = []
    for item in items:
        ankle_name, toe_name = _split_item(skeleton, item)
        ankle = skeleton.index(ankle_name)
        toe = skeleton.index(toe_name) if toe_name else None
        if toe is not None and ankle not in _ancestors(skeleton, toe):
            raise MocycleError(f"toe joint {toe_name!r} is not below the ankle {ankle_name!r}")
        feet.append(_leg(skeleton, ankle, toe, side_of(ankle_name) or ankle_name))
    return feet


def find_feet(skeleton: Skeleton, names: str | Sequence[str] | None = None) -> list[Foot]:
    """The feet of ``skeleton``, left first.

    ``names``: ``None`` to find them by name patterns, or ``"ANKLE[:TOE],ANKLE[:TOE]"`` (a string or a
    list of such items) to name them.  Raises :class:`MocycleError` naming the joints when no feet are
    found (so the caller can name them).
    """
    if names:
        return _named(skeleton, names)
    known = _FOUND.get(skeleton)  # the name patterns, once per skeleton (a 100-joint rig: ~3 ms a search)
    if known is None:
        known = _FOUND[skeleton] = tuple(_by_name(skeleton))
    return list(known)


#: the feet :func:`find_feet` found by name on each skeleton (skeletons are immutable)
_FOUND: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _by_name(skeleton: Skeleton) -> list[Foot]:
    found = [j for j, n in enumerate(skeleton.names) if _matches(n, ANKLE_PATTERNS) and "toe" not in _bare(n)]
    found = [j for j in found if not any(a in found for a in _ancestors(skeleton, j))]  # the top-most per leg
    feet: dict[str, Foot] = {}
    for j in found:
        side = side_of(skeleton.names[j])
        if side is None or side in feet:
            continue
        feet[side] = _leg(skeleton, j, _toe_below(skeleton, j), side)
    if len(feet) < 2:
        have = ", ".join(skeleton.names[f.ankle] for f in feet.values()) or "none"
        raise MocycleError(
            f"no left and right foot found by name (foot joints found: {have}); name them as "
            f"ANKLE[:TOE],ANKLE[:TOE] (option 'foot_joints'); joints are: {_listed(skeleton)}")
    return [feet["left"], feet["right"]]


def along(vectors: np.ndarray, up: np.ndarray) -> np.ndarray:
    """``vectors @ up``: the components ``(...)`` of ``vectors`` ``(..., k, 3)`` along ``up`` ``(3,)``.  Stacked,
    numpy makes one BLAS matrix-vector product per ``(k, 3)`` matrix (a frame's joints); for a C-ordered array
    with ``k >= 2`` the rows are taken as one ``(n k, 3)`` matrix instead, one BLAS call with the same dot
    products, the same numbers (a single row, ``k == 1``, is numpy's own dot, and a strided array may be numpy's
    own loop: both left as they are)."""
    if vectors.ndim > 2 and vectors.shape[-2] >= 2 and vectors.flags.c_contiguous:
        return (vectors.reshape(-1, 3) @ up).reshape(vectors.shape[:-1])
    return vectors @ up


def up_axis(motion: Motion, up=None) -> np.ndarray:
    """The world up direction ``(3,)`` of ``motion`` (:func:`mocycle.axes.vertical_axis`; ``up`` overrides)."""
    return vertical_axis(motion, up)


def body_height(motion: Motion, up: np.ndarray | None = None, positions: np.ndarray | None = None) -> float:
    """The body's height along ``up`` in file units: the extent of the mean pose of the travel joint, the
    joints below it and their End Sites, each frame taken relative to the travel joint (about 50 frames).
    ``positions``: ``motion.world_positions(end_sites=True)`` when the caller has it (saves recomputing)."""
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    skel, travel = motion.skeleton, motion.travel_joint
    above, j = set(), int(skel.parents[travel])
    while j >= 0:
        above.add(j)
        j = int(skel.parents[j])
    keep = [j for j in range(skel.n_joints) if j not in above] + [
        skel.n_joints + i for i, site in enumerate(skel.end_sites) if site.parent not in above]
    step = max(1, motion.n_frames // 50)
    W = motion.world_positions(end_sites=True, step=step) if positions is None else positions[::step]
    pose = (W[:, keep] - W[:, travel:travel + 1]).mean(axis=0)
    return float(np.ptp(pose @ up)) or 1.0


def leg_joints(feet: Sequence[Foot]) -> list[int]:
    """The hip, knee, ankle and toe of every foot, in skeleton order."""
    return sorted({j for f in feet for j in (f.hip, f.knee, f.ankle) + f.contact_joints})


def chain_joints(motion: Motion, joints) -> list[int]:
    """``joints``, the travel joint and all their ancestors, in skeleton order (parents first)."""
    parents = motion.skeleton.parents
    out: set[int] = set()
    for j in list(joints) + [motion.travel_joint]:
        j = int(j)
        while j >= 0 and j not in out:
            out.add(j)
            j = int(parents[j])
    return sorted(out)


class ChainArray:
    """Per-joint arrays of the joints of a chain, read as a ``(T, J, ...)`` array would be,
    ``array[frames, joint]`` or ``array[frames, [joints]]`` (NaN for a joint outside the chain), but holding
    the chain's joints only (``data``: ``(T, len(chain), ...)``)."""

    def __init__(self, n_frames: int, chain: list[int], tail: tuple[int, ...]):
        self.column = {int(j): i for i, j in enumerate(chain)}
        self.data = np.empty((n_frames, len(chain)) + tuple(tail))

    @property
    def shape(self) -> tuple[int, ...]:
        """The shape of the ``(T, J, ...)`` array it stands for (J: one past the chain's last joint)."""
        return (self.data.shape[0], max(self.column, default=-1) + 1) + self.data.shape[2:]

    def __getitem__(self, key) -> np.ndarray:
        rows, joints = key
        if np.ndim(joints) == 0:
            i = self.column.get(int(joints))
            if i is None:
                return np.full(self.data[rows, 0].shape, np.nan)
            return self.data[rows, i]
        cols = [self.column.get(int(j)) for j in joints]
        if None not in cols:
            return self.data[rows][:, cols]
        return np.stack([self[rows, j] for j in joints], axis=1)

    def add(self, joints: np.ndarray, value: np.ndarray) -> None:
        """``array[:, joints] += value[:, None]`` for the chain's joints among ``joints`` (a ``(J,)`` mask)."""
        cols = [i for j, i in self.column.items() if j < len(joints) and joints[j]]
        if cols:
            self.data[:, cols] += value[:, None]


#: the world rotations of a chain (``tail`` (3, 3))
ChainRotations = ChainArray


def chain_transforms(motion: Motion, chain: list[int]) -> tuple[ChainArray, ChainArray]:
    """World rotations (``[frames, joint]`` -> ``(..., 3, 3)``) and positions (``[frames, joint]`` ->
    ``(..., 3)``) of the joints of ``chain`` (:class:`ChainArray`, NaN for the others): forward kinematics of
    the legs only, not of a 100-joint rig's fingers and face, held for the chain's joints only."""
    T = motion.n_frames
    Rw = ChainArray(T, chain, (3, 3))
    W = ChainArray(T, chain, (3,))
    chain_forward_kinematics(motion, chain, slice(None), Rw.data, W.data)
    return Rw, W


#: frames per block of :func:`chain_positions` (its world rotations are held for one block only)
POSITIONS_BLOCK = 16384


def chain_positions(motion: Motion, chain: list[int]) -> ChainArray:
    """The world positions of :func:`chain_transforms` alone, computed a block of frames at a time: for a long
    take only the ``(T, len(chain), 3)`` positions are held, not the rotations (three times their size)."""
    W = ChainArray(motion.n_frames, chain, (3,))
    for rows, _, positions in chain_kinematics_blocks(motion, chain, POSITIONS_BLOCK):
        W.data[rows] = positions
    return W


def chain_rotation_blocks(motion: Motion, chain: list[int], block: int | None = None):
    """The world rotations of :func:`chain_transforms` a block of frames at a time: yields ``(rows, Rw)``, the
    frames (a slice) and their rotations ``(n, len(chain), 3, 3)`` (columns in chain order; one buffer,
    reused: read a block before asking for the next); ``block``: frames per block (default POSITIONS_BLOCK)."""
    for rows, Rw, _ in chain_kinematics_blocks(motion, chain, POSITIONS_BLOCK if block is None else block):
        yield rows, Rw
