"""From a scene's node transforms to a :class:`~mocycle.motion.Motion`: what the glTF and FBX readers share.

A scene file (glTF, FBX) gives each node a local translation, rotation and scale (TRS), some of them animated.
A mocycle motion has neither scale nor nodes between joints, so the readers hand over the chain of nodes from
the scene's top down to the skeleton's root (*ancestors*: an ``Armature`` object, a unit or axis conversion)
and the joints below it, with their TRS sampled at the motion's frames, and this module

* composes each node's world matrix ``M = M_parent · T · R · S`` a block of frames at a time;
* takes each joint's world position and world rotation (the matrix's rotation, scale divided out: the nearest
  rotation when the scale is not uniform), and gives the motion what reproduces them: the root's world
  rotation and position, and every other joint's rotation and offset seen from its parent's world rotation.

Every joint's world position is therefore the file's, whatever pre/post rotations, scales (also animated or
non-uniform) and conversions sit above it; the joints' orientations are the file's up to any shear a
non-uniform parent scale adds (a mocycle joint cannot shear).  Joints whose offset stays still (within
``1e-7`` of the skeleton's size) keep one constant offset; the others, and every joint whose translation some
take of the file keys (``NodeTRS.translated``: one skeleton for every take), get a translation track and position
channels.  A leaf joint with no animation of its own becomes an End Site (its orientation moves nothing).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import DefaultTake, MocycleError, MotionFileError
from ..limits import MAX_MAGNITUDE, check_frames, frame_time_problem
from ..motion import EndSite, Motion, Skeleton
from ..rotations import nearest_rotations

_MOVING = ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")
_TURNING = ("Zrotation", "Xrotation", "Yrotation")
_BLOCK = 2048  # most frames per block of world matrices
_BLOCK_CELLS = 1 << 18  # most frames x joints per block: the world matrices of a block take 128 bytes a cell


class Sampled:
    """An animated translation, rotation or scale sampled only when a block of frames is asked for:
    ``sample(times) -> (len(times), width)``.  A reader hands one to :class:`NodeTRS` instead of the whole
    ``(T, width)`` array, so that reading holds one block of every node's values, not the whole take of each
    (a file's key times may claim a long span in a few bytes)."""

    def __init__(self, times: np.ndarray, width: int, sample):
        self.times, self.width, self.sample = times, width, sample

    def __len__(self) -> int:
        return len(self.times)

    @property
    def shape(self) -> tuple[int, int]:
        return len(self.times), self.width

    def __getitem__(self, rows: slice) -> np.ndarray:
        return np.asarray(self.sample(self.times[rows]), dtype=np.float64).reshape(-1, self.width)


@dataclass
class NodeTRS:
    """One node's local transform, sampled at the motion's frames: ``translation (T, 3)`` or ``(1, 3)`` when
    constant, ``rotation (T, 4)`` or ``(1, 4)`` (x, y, z, w), ``scale (T, 3)`` or ``(1, 3)``; an animated one
    may be a :class:`Sampled` (``T`` frames, made a block at a time)."""

    name: str
    translation: np.ndarray | Sampled
    rotation: np.ndarray | Sampled
    scale: np.ndarray | Sampled
    animated: bool = False
    #: some take of the file keys its translation: it has position channels in every take (even one that keys
    #: it still, or not at all), so that every take of a file has one skeleton (blend a file's walk with its run)
    translated: bool = False


def _matrices(node: NodeTRS, rows: slice, n: int, path=None) -> np.ndarray:
    """``(n, 4, 4)`` local matrices ``T · R · S`` of ``node`` over the frames ``rows``."""
    def take(a, what):
        if isinstance(a, Sampled):
            block = a[rows]
            _check_values(node.name, what, block, path)
            return block
        return np.broadcast_to(a if len(a) == 1 else a[rows], (n, a.shape[1]))

    q = take(node.rotation, "rotation")
    m = np.zeros((n, 4, 4))
    m[:, :3, :3] = Rotation.from_quat(q).as_matrix() * take(node.scale, "scale")[:, None, :]
    m[:, :3, 3] = take(node.translation, "translation")
    m[:, 3, 3] = 1.0
    return m


def _constant(node: NodeTRS) -> bool:
    return all(not isinstance(a, Sampled) and len(a) == 1 for a in (node.translation, node.rotation, node.scale))


def _rotation_part(m: np.ndarray) -> np.ndarray:
    """The rotations ``(n, 3, 3)`` of world matrices ``(n, 3, 3)``: scale divided out (per column), then the
    nearest rotation (exact already when the scale is uniform; a mirror's reflection taken out)."""
    norms = np.linalg.norm(m, axis=1, keepdims=True)
    norms[norms < 1e-300] = 1.0
    r = m / norms
    det = np.linalg.det(r)
    if np.all(np.abs(det - 1.0) < 1e-9):
        return r
    return nearest_rotations(r)


def _check_values(name: str, what: str, a: np.ndarray, path) -> None:
    """Refuse NaN, infinite or absurd values (and zero rotations) in one node's ``what`` (one clear error)."""
    if a.size and not (np.isfinite(a).all() and np.abs(a).max() <= MAX_MAGNITUDE):
        raise MotionFileError(f"node {name!r}: its {what} holds NaN, infinite or absurd values", path)
    if what == "rotation" and a.size and np.any(np.linalg.norm(a, axis=1) < 1e-12):
        raise MotionFileError(f"node {name!r}: a zero rotation quaternion", path)


def check_trs(nodes: list[NodeTRS], path) -> None:
    """Refuse NaN, infinite or absurd values and zero rotations in the transforms (one clear error); a
    :class:`Sampled` one is checked a block at a time as it is sampled."""
    for node in nodes:
        for what, a in (("translation", node.translation), ("rotation", node.rotation), ("scale", node.scale)):
            if not isinstance(a, Sampled):
                _check_values(node.name, what, a, path)


def unique_names(names: list[str | None], prefix: str = "node") -> list[str]:
    """Node names made usable as joint names: a name for each unnamed node, ``.1``, ``.2`` after repeats
    (linear in the names: each base name's next number is kept)."""
    out, taken = [], set()
    following: dict[str, int] = {}  # base name -> the next number to try after it
    for i, name in enumerate(names):
        base = str(name).strip() if name is not None and str(name).strip() else f"{prefix}{i}"
        base = " ".join(base.split())  # one line, no tabs: a BVH joint name
        candidate, k = base, following.get(base, 1)
        if candidate in taken:
            candidate = f"{base}.{k}"
            while candidate in taken:
                k += 1
                candidate = f"{base}.{k}"
            following[base] = k + 1
        taken.add(candidate)
        out.append(candidate)
    return out


def joint_names(names: list[str | None], members: list[int]) -> list[str]:
    """A name for every node (``names``: the file's, by node index) made unique among the skeleton's nodes
    (``members``) first, in skeleton order, then among the others: a mesh or an empty called like a bone
    (RobotExpressive's ``Torso``) does not rename the bone."""
    member = set(members)  # made once: built per node it made this quadratic (20,000 nodes: 12 s)
    order = list(members) + [i for i in range(len(names)) if i not in member]
    unique = unique_names([names[i] for i in order])
    out = [""] * len(names)
    for i, name in zip(order, unique, strict=True):
        out[i] = name
    return out


def motion_from_nodes(ancestors: list[NodeTRS], joints: list[NodeTRS], parents: list[int], n_frames: int,
                      frame_time: float, path, *, leaves_as_sites: bool = True, up=None,
                      metres_per_unit: float | None = None) -> Motion:
    """The motion that plays ``joints`` as the scene does.

    Parameters
    ----------
    ancestors : the nodes above the root joint, top first (each the parent of the next; may be empty).
    joints : the skeleton's nodes, parents first; ``joints[0]`` is the root, child of ``ancestors[-1]``.
    parents : index of each joint's parent among ``joints`` (``-1`` for the root only).
    n_frames, frame_time : the frames the transforms were sampled at.
    path : the file, for messages.
    leaves_as_sites : make leaf joints without animation End Sites.
    up, metres_per_unit : the vertical and unit the file declares (``None``: it does not), kept by the skeleton.
    """
    declared_up, T, J = up, int(n_frames), len(joints)
    check_frames(T, J, "the animation", path)
    up = np.asarray(parents, dtype=np.int64)  # checked as an array, used as one
    if J == 0 or up.shape != (J,) or up[0] != -1 or np.any(up[1:] < 0) or np.any(up[1:] >= np.arange(1, J)):
        raise MotionFileError("the skeleton's joints are not in parents-first order under one root", path)
    check_trs(ancestors + joints, path)

    children = np.zeros(J, dtype=int)
    np.add.at(children, up[1:], 1)
    sites = [j for j in range(1, J) if leaves_as_sites and children[j] == 0 and not joints[j].animated]
    site_set = set(sites)
    keep = [j for j in range(J) if j not in site_set]
    new_index = {j: k for k, j in enumerate(keep)}

    # which joints' local translations can change: their own translation is animated, or a scale above them
    scale_moves = any(len(a.scale) > 1 for a in ancestors)
    anc_moves = any(len(a.translation) > 1 or len(a.rotation) > 1 or len(a.scale) > 1 for a in ancestors)
    varying = np.zeros(J, dtype=bool)
    scaled_above = np.zeros(J, dtype=bool)  # some node above the joint has an animated scale
    for j in range(J):
        p = up[j]
        scaled_above[j] = scale_moves if p < 0 else (scaled_above[p] or len(joints[p].scale) > 1)
        varying[j] = len(joints[j].translation) > 1 or scaled_above[j] or (j == 0 and anc_moves) or joints[j].translated
    K = len(keep)
    rotations = np.empty((T, K, 4))
    tracks = {new_index[j]: np.empty((T, 3)) for j in keep if varying[j]}
    static = np.zeros((K, 3))
    site_offsets = {j: np.zeros(3) for j in sites}
    block = max(1, min(_BLOCK, _BLOCK_CELLS // J))
    # a joint whose transform does not change: its local matrix made once, not once per block
    still: list[np.ndarray | None] = [_matrices(node, slice(0, 1), 1, path)[0] if _constant(node) else None
                                      for node in joints]
    for start in range(0, T, block):
        rows = slice(start, min(T, start + block))
        n = rows.stop - start
        top = np.broadcast_to(np.eye(4), (n, 4, 4))
        for a in ancestors:
            top = top @ _matrices(a, rows, n, path)
        world = np.empty((n, J, 4, 4))
        for j in range(J):
            fixed = still[j]
            local = fixed if fixed is not None else _matrices(joints[j], rows, n, path)
            world[:, j] = (top if up[j] < 0 else world[:, up[j]]) @ local
        rot = _rotation_part(world[:, :, :3, :3].reshape(-1, 3, 3)).reshape(n, J, 3, 3)
        pos = world[:, :, :3, 3]
        r_locals = np.empty((n, K, 3, 3))
        for j in range(J):
            p = up[j]
            if p < 0:
                r_local, t_local = rot[:, j], pos[:, j]
            else:
                rp = rot[:, p]
                r_local = np.swapaxes(rp, 1, 2) @ rot[:, j]
                t_local = (np.swapaxes(rp, 1, 2) @ (pos[:, j] - pos[:, p])[..., None])[..., 0]
            if j in site_offsets:
                if start == 0:
                    site_offsets[j] = t_local[0].copy()
                continue
            k = new_index[j]
            r_locals[:, k] = r_local
            if k in tracks:
                tracks[k][rows] = t_local
            elif start == 0:
                static[k] = t_local[0]
        rotations[rows] = Rotation.from_matrix(r_locals.reshape(-1, 3, 3)).as_quat().reshape(n, K, 4)
    if not np.isfinite(rotations).all():
        raise MotionFileError("the node transforms give no usable rotation (a zero scale?)", path)

    # tracks that stand still (within 1e-7 of the skeleton's size) become constant offsets
    size = max(float(np.abs(static).max(initial=0.0)), max((float(np.abs(t).max()) for t in tracks.values()),
                                                             default=0.0), 1e-12)
    translated = {new_index[j] for j in keep if joints[j].translated}
    for k in list(tracks):
        if k not in translated and np.ptp(tracks[k], axis=0).max() <= 1e-7 * size:
            static[k] = tracks.pop(k)[0]
    offsets = static.copy()
    for k, t in tracks.items():
        offsets[k] = t[0]
    names = [joints[j].name for j in keep]
    kparents = [-1] + [new_index[int(up[j])] for j in keep[1:]]
    channels = [_MOVING if k in tracks else _TURNING for k in range(K)]
    end_sites = tuple(EndSite(parent=new_index[int(up[j])], offset=_vec3(site_offsets[j]),
                              name=joints[j].name) for j in sites)
    try:
        skeleton = Skeleton(tuple(names), np.asarray(kparents), offsets, tuple(channels), end_sites, up=declared_up,
                            metres_per_unit=metres_per_unit)
        return Motion(skeleton, rotations, static, frame_time, tracks=tracks, copy=False)
    except MocycleError as exc:
        raise MotionFileError(str(exc), path) from None


def skeleton_order(parents: np.ndarray, children: list[list[int]], chosen, path) -> list[int]:
    """The skeleton's nodes, depth first from its root with children in the file's order (a BVH's order): the
    ``chosen`` nodes (a skin's joints, a file's bones), any node lying between two of them, and, when they have
    several roots, their lowest common ancestor (refused when they have none).  ``parents`` must form a tree.

    Linear in the nodes: one pass from the tops down (which nodes have a chosen node above them), one from the
    leaves up (which have one below)."""
    N = len(parents)
    up = [int(p) for p in np.asarray(parents).tolist()]
    member = np.zeros(N, dtype=bool)
    member[[int(i) for i in chosen]] = True
    if not member.any():
        raise MotionFileError("no joints: nothing to read as a skeleton", path)
    order = _top_down(up, children)
    below = _counts_below(order, up, member)  # chosen nodes in each node's subtree, itself included
    above = _any_above(order, up, member)  # a chosen node above (not counting the node itself)
    tops = [i for i in order if member[i] and not above[i]]
    if len(tops) > 1:  # several roots: their lowest common ancestor joins them
        tops_below = _counts_below(order, up, np.isin(np.arange(N), tops))
        common = [i for i in order if tops_below[i] == len(tops)]
        if not common:
            raise MotionFileError(f"the skeleton's joints have {len(tops)} roots with no common parent node", path)
        root = common[-1]  # the deepest: the last of them from the top down
        member[root] = True
        below = _counts_below(order, up, member)
        above = _any_above(order, up, member)
    else:
        root = tops[0]
    # nodes between a joint and a joint above it are joints too: a chosen node above and one below
    member |= above & (below > 0)
    out, stack = [], [root]
    while stack:
        i = stack.pop()
        out.append(i)
        stack += [c for c in reversed(children[i]) if member[c]]
    return out


def _top_down(up: list[int], children: list[list[int]]) -> list[int]:
    """Every node, each after its parent (depth first from the tops)."""
    order: list[int] = []
    stack = [i for i, p in enumerate(up) if p < 0]
    while stack:
        i = stack.pop()
        order.append(i)
        stack += children[i]
    return order


def _counts_below(order: list[int], up: list[int], marked: np.ndarray) -> np.ndarray:
    """How many ``marked`` nodes each node's subtree holds (itself included)."""
    counts = marked.astype(np.int64)
    for i in reversed(order):
        if up[i] >= 0:
            counts[up[i]] += counts[i]
    return counts


def _any_above(order: list[int], up: list[int], marked: np.ndarray) -> np.ndarray:
    """Whether a ``marked`` node lies strictly above each node."""
    above = np.zeros(len(up), dtype=bool)
    for i in order:
        p = up[i]
        if p >= 0:
            above[i] = above[p] or marked[p]
    return above


#: the frame rate of a take whose keys lie on no regular grid (unless the caller says otherwise), glTF and FBX
DEFAULT_FPS = 30.0
#: key rates below this (frames per second) are taken for sparse authored keys: sampled at DEFAULT_FPS instead
MIN_KEY_RATE = 12.0
#: the largest glTF or FBX file read (bytes): a glTF's buffers and an FBX scene are read into memory
MAX_FILE_BYTES = 2**31

MAX_LISTED_TAKES = 20
"""How many take names a message lists; the rest are counted (``mocycle info FILE``, ``gltf_takes`` and
``fbx_takes`` list them all)."""


def key_rate(step: float | None) -> float | None:
    """The frame rate of one key per ``step`` seconds (rounded to a whole number within 1e-4), or ``None`` for
    no step or sparse authored keys (fewer than :data:`MIN_KEY_RATE` a second): a take's own rate, glTF and FBX."""
    if step is None or 1.0 / step < MIN_KEY_RATE:
        return None
    rate = 1.0 / step
    return float(round(rate)) if abs(rate - round(rate)) < 1e-4 * rate and round(rate) > 0 else rate


def listed(names: list[str]) -> str:
    """``names`` joined for a message: the first :data:`MAX_LISTED_TAKES`, then how many more."""
    shown = ", ".join(names[:MAX_LISTED_TAKES])
    more = len(names) - MAX_LISTED_TAKES
    return shown + (f" and {more} more" if more > 0 else "")


def choose_take(names: list[str], take, path, noun: str, none_held: str) -> int | None:
    """The index of the take (an animation stack, a glTF animation) called ``take`` (its name, or its index as
    text) among ``names``; ``None`` when the file holds none and none was asked for, 0 when none was asked for.
    ``noun``/``none_held`` word the one error line (``take`` / ``animation stack``)."""
    if not names:
        if take is not None:
            raise MotionFileError(f"no {noun} named {take!r}: the file holds no {none_held}", path)
        return None
    if take is None:
        return 0
    text = str(take)
    if text in names:
        return names.index(text)
    if text.isdigit() and int(text) < len(names):
        return int(text)
    raise MotionFileError(f"no {noun} named {text!r}; the file holds: {listed(names)}", path)


def default_take(names: list[str], moves: Callable[[int], bool], path, noun: str, stacklevel: int = 3) -> int:
    """The take read when none is named: the first of ``names`` that ``moves(k)`` (moves the skeleton), else the
    first.  When the file holds several a :class:`~mocycle.errors.DefaultTake` warning says which and why, and
    lists the others (``(still)`` after those seen not to move); ``noun`` words the reason when none moves
    (``take``, ``animation``).  ``stacklevel``: the warning's, counted from here."""
    chosen = next((k for k in range(len(names)) if moves(k)), None)
    none_moves = chosen is None
    chosen = 0 if chosen is None else chosen
    if len(names) > 1:
        others = [f"{name!r}" + (" (still)" if k < chosen or none_moves else "")
                  for k, name in enumerate(names) if k != chosen]
        why = f"the first: no {noun} moves the skeleton" if none_moves else "the first that moves the skeleton"
        warnings.warn(f"{path}: read take {names[chosen]!r} ({why}); the file also holds {listed(others)}: "
                      f"choose one with option 'take'", DefaultTake, stacklevel=stacklevel)
    return chosen


def frame_times(start: float, end: float, rate: float, n_joints: int, path) -> np.ndarray:
    """The times (s) of a take's frames, from ``start`` to ``end`` at ``rate`` frames a second; a frame time mocycle
    does not read, an absurd span, or more frames than :func:`~mocycle.limits.check_frames` allows, refused."""
    problem = frame_time_problem(1.0 / rate)
    if problem:
        raise MotionFileError(problem, path)
    if not end - start < 1e9:
        raise MotionFileError(f"the animation spans {end - start:g} s", path)
    n_frames = check_frames(int(round((end - start) * rate)) + 1, n_joints, "the animation", path)
    return start + np.arange(n_frames) / rate


def member_nodes(members: list[int], parents, node_trs) -> tuple[list, list, list[int]]:
    """The skeleton's nodes from a file's node tree: the nodes above its root (``node_trs`` of each, outermost
    first), its joints' nodes (``members``, parents first) and each joint's parent among them (-1: the root)."""
    above = []
    i = int(parents[members[0]])
    while i >= 0:
        above.append(i)
        i = int(parents[i])
    position = {node: k for k, node in enumerate(members)}
    return ([node_trs(i) for i in reversed(above)], [node_trs(i) for i in members],
            [-1] + [position[int(parents[i])] for i in members[1:]])


def _vec3(v) -> tuple[float, float, float]:
    x, y, z = (float(c) for c in v)
    return x, y, z
