"""FBX input (``.fbx``, binary or ASCII): a skeleton and one animation stack as a Motion, through ufbx.

The file is read by ufbx (a single-file C loader; Godot imports FBX with it) through the Python binding its
author publishes, ``ufbx`` on PyPI (``pip install 'mocycle[fbx]'``: wheels for Linux, macOS and Windows;
imported only when a file is read; ``docs/formats.md`` says why this binding).  What is read:

* **the skeleton**: the file's bones (FBX ``LimbNode``/``Root``/``Limb`` nodes: ufbx's bone attribute), with any
  node lying between two bones; meshes, lights, cameras and empties beside them are not joints.  The nodes
  above the root bone (Blender's or Maya's armature object, Mixamo's ``Armature``) are composed into the root.
  Names are kept as written (Mixamo's ``mixamorig:Hips``), made unique among the joints only (a mesh called
  like a bone does not rename the bone).  A leaf bone that no take of the file moves (Blender's ``_end``
  bones) becomes an End Site: every take of a file has the same joints.
* **the take**: one animation stack (``take``: its name or 0-based index; default the first stack that moves
  the skeleton, said in a :class:`~mocycle.errors.DefaultTake` warning when the file holds several: Mixamo files
  often begin with an empty ``Take 001``), baked by ufbx (``ufbx_bake_anim``): layers, pre/post rotations,
  rotation orders, pivots and scaling offsets composed into each node's local translation, rotation and
  scale, linearly keyed; then sampled at the frame rate from the skeleton's first key to its last, within the
  stack's start and stop (as Blender imports it).
* **the frame rate**: ``fps`` when given; else the one the file declares (``GlobalSettings``' ``TimeMode``,
  the same for every take); without one, the keys' own rate when they lie on a regular grid of at least 12
  keys a second, else 30 fps.
* **units and axes**: the joints' world positions are the file's, whatever scale (also non-uniform or
  animated) sits above or on the bones (see :mod:`._nodes`); the skeleton carries the vertical and the unit
  the file declares (``GlobalSettings``' axes and ``UnitScaleFactor``; :attr:`Skeleton.up`,
  :attr:`Skeleton.metres_per_unit`), which :func:`mocycle.axes.vertical_axis` and the glTF writer use.

A damaged file is one :class:`~mocycle.errors.MotionFileError` (ufbx checks its input: sizes against the file,
nesting, counts; it was fuzzed by its author and by ``benchmarks/fuzz.py``).
"""

from __future__ import annotations

import ctypes
import gc
import os
import sys
import traceback
from pathlib import Path

import numpy as np

from ..errors import MocycleError, MotionFileError
from ..limits import frame_time_problem
from ..motion import Motion
from . import _nodes
from ._nodes import DEFAULT_FPS, MAX_FILE_BYTES, NodeTRS
from .fbx_scan import opened

__all__ = ["DEFAULT_FPS", "fbx_takes", "read_fbx"]

#: the binding's CoordinateAxis values, in order: +X, -X, +Y, -Y, +Z, -Z (then UNKNOWN)
_AXES = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0))


def _import():
    try:
        import ufbx
    except ImportError:
        ufbx = None
    if ufbx is None or not hasattr(ufbx, "bake_anim"):
        # pufbx, the binding mocycle used before, installs a package called ufbx too (its C sources only)
        raise MocycleError("reading FBX files needs the ufbx binding: pip install 'mocycle[fbx]'"
                           + ("" if ufbx is None else " (the 'ufbx' found is not it: pip uninstall pufbx first)"))
    return ufbx


def _owned(elements) -> list:
    """The items of one of the binding's element lists (``scene.nodes``, ``node.children``, ``anim_stacks``) as
    a Python list whose references are all counted.

    ufbx 0.0.5 keeps one Python object per scene element in a cache that owns a reference to it (the scene
    releases them when it is freed), but hands the cached object out without a reference for the caller: the
    caller's reference is the cache's.  Dropped, the object dies while the cache still points at it, and the
    next access, the garbage collector visiting the scene, or freeing the scene uses freed memory (a
    segmentation fault; the binding's repository fixed it after 0.0.5: "every caller gets its own new ref").
    So each list is measured when it is read: when a second access of its first item does not raise that
    item's count, the binding lends, and every item handed out gets the reference it lacks.  A binding that
    counts right is left alone."""
    out = [elements[i] for i in range(len(elements))]
    if out:
        before = sys.getrefcount(out[0])
        again = elements[0]
        if sys.getrefcount(out[0]) == before:  # lent, not given: one reference short per access
            for item in (*out, again):
                ctypes.pythonapi.Py_IncRef(ctypes.py_object(item))
        del again
    return out


def _with_scene(path: Path, work):
    """``work(scene)`` on the file's scene, which is then freed; ``work`` returns plain data (no object of the
    binding), and on an error the frames of its traceback are cleared of the binding's objects.

    With every element counted (:func:`_owned`), the scene's cache and its elements hold each other: only
    freeing the scene breaks that cycle (left to the garbage collector, ufbx 0.0.5's context crashes in its own
    deallocation: it releases its name after the collector has cleared it, a null pointer).  Freeing leaves
    the context's element table freed but still listed, so the context must die at once, with nothing else
    holding it and no collection in between: the scene's last reference goes in the same call that frees it
    (``pop().free()``), with the collector off."""
    held = [_load(path)]
    error: BaseException | None = None
    try:
        result = work(held[0])
    except BaseException as exc:  # noqa: BLE001 - raised again below, once the scene is freed
        traceback.clear_frames(exc.__traceback__)
        error, result = exc, None
    enabled = gc.isenabled()
    gc.disable()
    try:
        held.pop().free()
    except Exception:  # noqa: BLE001 - a scene that cannot be freed is left to the binding
        pass
    finally:
        if enabled:
            gc.enable()
    if error is not None:
        raise error
    return result


def _load(path: Path):
    ufbx = _import()
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None
    if path.is_dir():
        raise MotionFileError("is a folder; mocycle reads FBX files", path)
    if size > MAX_FILE_BYTES:
        raise MotionFileError(f"the file holds {size:,} bytes; FBX files over {MAX_FILE_BYTES:,} are not read", path)
    try:  # meshes and embedded textures are not read: the motion is the skeleton's
        with opened(path) as name:  # regular files only, no deflate bomb; any file name (fbx_scan)
            return ufbx.load_file(name, ignore_geometry=True, ignore_embedded=True)
    except MotionFileError:
        raise
    except Exception as exc:  # ufbx's error (its message says what it expected), or the binding's
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise MotionFileError(f"not a readable FBX file ({text})", path) from None


def _stack_names(stacks) -> list[str]:
    return _nodes.unique_names([s.name for s in stacks], prefix="take")


def fbx_takes(path: str | os.PathLike) -> list[str]:
    """The names of the animation stacks (takes) in an FBX file."""
    p = Path(path)
    _import()
    return _guarded(p, lambda scene: _stack_names(_owned(scene.anim_stacks)))


def _guarded(p: Path, work):
    """:func:`_with_scene`, the binding's own errors on odd scenes made one :class:`MotionFileError`."""
    try:
        return _with_scene(p, work)
    except (MocycleError, MemoryError):
        raise
    except Exception as exc:
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        problem = f"cannot read the FBX scene ({type(exc).__name__}: {text})"
    raise MotionFileError(problem, p)


def _keys(keys, width: int) -> tuple[np.ndarray, np.ndarray]:
    """(times ``(n,)``, values ``(n, width)``) of a baked key list (items with ``time`` and ``value``)."""
    rows = [(k.time, *k.value) for k in (keys[i] for i in range(len(keys)))]
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 1 + width)
    return a[:, 0].copy(), a[:, 1:].copy()


def _sample(times: np.ndarray, keys: np.ndarray, values: np.ndarray, rotation: bool) -> np.ndarray:
    """Linearly keyed values at ``times`` (held before the first key and after the last); rotations nlerped
    (the baked keys are dense: ufbx resamples where its curves are not linear)."""
    if len(keys) == 1:
        return values[:1]
    k = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, len(keys) - 2)
    span = keys[k + 1] - keys[k]
    s = np.clip((times - keys[k]) / np.where(span > 0, span, 1.0), 0.0, 1.0)[:, None]
    a, b = values[k], values[k + 1]
    if rotation:
        b = np.where((np.sum(a * b, axis=1) < 0)[:, None], -b, b)
    out = a + s * (b - a)
    if rotation:
        out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out


def regular_rate(times: np.ndarray) -> float | None:
    """The rate (frames per second) of key times lying on one regular grid, or ``None`` (:func:`._nodes.key_rate`:
    at least 12 keys a second, rounded to a whole number within 1e-4)."""
    times = np.unique(times)
    if len(times) < 2:
        return None
    step = float(np.min(np.diff(times)))
    if not step > 1e-6:
        return None
    k = (times - times[0]) / step
    if not np.allclose(k, np.round(k), rtol=0, atol=1e-3):
        return None
    return _nodes.key_rate(step)  # a few keys far apart are authored keys, not one per frame: None


class _Scene:
    """An FBX scene as mocycle reads it: the node tree, the skeleton's nodes, the takes and what the file
    declares (frame rate, vertical, unit)."""

    def __init__(self, ufbx, scene, path: Path):
        self.ufbx, self.scene, self.path = ufbx, scene, path
        self.nodes = _owned(scene.nodes)
        N = len(self.nodes)
        self.by_typed = {n.typed_id: i for i, n in enumerate(self.nodes)}
        self.parents = np.full(N, -1, dtype=np.int64)
        self.children: list[list[int]] = [[] for _ in range(N)]
        for i, n in enumerate(self.nodes):
            for c in _owned(n.children):
                j = self.by_typed.get(c.typed_id)
                if j is None or self.parents[j] >= 0 or j == i:
                    raise MotionFileError("the node tree is not a tree", path)
                self.parents[j] = i
                self.children[i].append(j)
        bone = ufbx.ElementType.BONE
        bones = [i for i, n in enumerate(self.nodes) if n.attrib_type == bone]
        if not bones:
            raise MotionFileError("no bones (LimbNode, Root or Limb nodes): nothing to read as a skeleton", path)
        self.members = _nodes.skeleton_order(self.parents, self.children, bones, path)
        self.stacks = _owned(scene.anim_stacks)
        self.stack_names = _stack_names(self.stacks)
        settings = scene.settings
        props = settings.props
        declared = ufbx.find_prop(props, "TimeMode") is not None or ufbx.find_prop(props, "CustomFrameRate")
        rate = float(settings.frames_per_second)
        self.rate = rate if declared and np.isfinite(rate) and not frame_time_problem(1.0 / rate) else None
        up = int(settings.axes.up)
        self.up = _AXES[up] if 0 <= up < len(_AXES) and ufbx.find_prop(props, "UpAxis") is not None else None
        unit = float(settings.unit_meters)
        self.unit = unit if ufbx.find_prop(props, "UnitScaleFactor") is not None and np.isfinite(unit) \
            and 1e-9 < unit < 1e9 else None
        self._moves: dict[int, bool] = {}
        t = [self.nodes[i].local_transform.translation for i in self.members]
        self.rest = np.array([[v.x, v.y, v.z] for v in t], dtype=float).reshape(-1, 3)  # joints' rest offsets

    def skeleton_nodes(self) -> set[int]:
        """The skeleton's nodes and the nodes above its root."""
        out, i = set(self.members), int(self.parents[self.members[0]])
        while i >= 0:
            out.add(i)
            i = int(self.parents[i])
        return out

    def keys(self, stack: int, rate: float, among: set[int] | None = None) -> dict[int, tuple]:
        """``{node: ((times, translations), (times, rotations), (times, scales))}`` of ``stack`` baked by ufbx
        (its curves resampled at ``rate`` where they are not linear), for the nodes it animates (``among``
        them only, when given)."""
        baked = self.ufbx.bake_anim(self.scene, self.stacks[stack].anim, resample_rate=rate)
        out = {}
        for b in (baked.nodes[k] for k in range(len(baked.nodes))):
            at = self.by_typed.get(b.typed_id)
            if at is not None and (among is None or at in among):
                out[at] = (_keys(b.translation_keys, 3), _keys(b.rotation_keys, 4), _keys(b.scale_keys, 3))
        return out

    def moving(self, stack: int, among: set[int]) -> set[int]:
        """The nodes ``among`` the given ones that take ``stack`` moves: a translation changing by more than 1e-6
        of the skeleton's size, a rotation or scale by more than 1e-6 (exporters bake a still pose with
        rounding)."""
        size = max(float(np.abs(self.rest).max(initial=0.0)), 1e-12)
        found = set()
        for at, ((_, t), (_, r), (_, s)) in self.keys(stack, self.rate or DEFAULT_FPS, among).items():
            if (len(t) > 1 and np.ptp(t, axis=0).max() > 1e-6 * size) or \
                    (len(r) > 1 and np.ptp(r, axis=0).max() > 1e-6) or (len(s) > 1 and np.ptp(s, axis=0).max() > 1e-6):
                found.add(at)
        return found

    def moves(self, stack: int) -> bool:
        """Whether take ``stack`` moves the skeleton (or a node above it)."""
        if stack not in self._moves:
            self._moves[stack] = bool(self.moving(stack, self.skeleton_nodes()))
        return self._moves[stack]

    def choose(self, take) -> int | None:
        """The stack called ``take``, or without one the first that moves the skeleton (said in a warning when
        the file holds several takes)."""
        if take is not None or len(self.stacks) < 2:
            return _nodes.choose_take(self.stack_names, take, self.path, "take", "animation stack")
        return _nodes.default_take(self.stack_names, self.moves, self.path, "take", stacklevel=5)

    def still_leaves(self) -> set[int]:
        """The skeleton's leaf nodes that no take of the file moves."""
        member = set(self.members)
        leaves = {i for i in self.members if not any(c in member for c in self.children[i])}
        for k in range(len(self.stacks)):
            if not leaves:
                break
            leaves -= self.moving(k, leaves)
        return leaves


def read_fbx(path: str | os.PathLike, *, take: str | int | None = None, fps: float | None = None) -> Motion:
    """Read an FBX file's skeleton and one animation stack as a :class:`Motion`.

    Parameters
    ----------
    path : the ``.fbx`` file.
    take : the animation stack's name (or 0-based index); default the first that moves the skeleton
        (:func:`fbx_takes` lists them).
    fps : the frame rate to sample at; default the file's (its ``TimeMode``), else the keys' own when regular,
        else :data:`DEFAULT_FPS`.

    Raises
    ------
    MotionFileError
        A damaged file, an unknown take (the message lists them), or no bones.
    """
    p = Path(path)
    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise MotionFileError(f"the frame rate must be positive; got {fps!r}", p)
    ufbx = _import()
    ancestors, joints, jparents, T, rate, up, unit, name = _guarded(
        p, lambda scene: _read(_Scene(ufbx, scene, p), take, fps))
    motion = _nodes.motion_from_nodes(ancestors, joints, jparents, T, 1.0 / rate, p, up=up, metres_per_unit=unit)
    motion.cache("take", lambda _: name)  # the take read (mocycle info says which)
    return motion


def _read(fs: _Scene, take, fps) -> tuple:
    """The skeleton's nodes sampled at the frames of the take (:func:`._nodes.member_nodes`), the frame count and rate,
    the file's declared vertical and unit, and the take's name: plain data, nothing of the binding."""
    p = fs.path
    stack = fs.choose(take)
    baked_nodes: dict[int, tuple] = {}
    rate: float | None = fps or fs.rate
    start = end = 0.0
    if stack is not None:
        body = fs.skeleton_nodes()
        baked_nodes = fs.keys(stack, rate or DEFAULT_FPS)
        # the keys of the skeleton's channels that change (ufbx gives a still node two keys at the stack's ends)
        all_times = [t for at, trs in baked_nodes.items() if at in body for t, v in trs
                     if len(t) > 1 and np.ptp(v, axis=0).max() > 0]
        if all_times:
            times_all = np.concatenate(all_times)
            if not np.isfinite(times_all).all():
                raise MotionFileError("key times are not finite", p)
            start, end = float(times_all.min()), float(times_all.max())
            if rate is None:  # no rate declared: the keys' own, baked again at it (no resampled points between)
                rate = regular_rate(times_all) or DEFAULT_FPS
                if rate != DEFAULT_FPS:
                    baked_nodes = fs.keys(stack, rate)
        # the skeleton's keys within the stack's span (Maya's may run on past the last key: Blender, too, ends
        # a take at its last key)
        begin, stop = float(fs.stacks[stack].time_begin), float(fs.stacks[stack].time_end)
        if np.isfinite(begin) and np.isfinite(stop) and stop > begin:
            start, end = (max(start, begin), min(end, stop)) if all_times and min(end, stop) > max(start, begin) \
                else (begin, stop)
    rate = float(rate or DEFAULT_FPS)
    times = _nodes.frame_times(start, end, rate, len(fs.members), p)
    T = len(times)

    names = _nodes.joint_names([n.name for n in fs.nodes], fs.members)
    still = fs.still_leaves()
    trs: dict[int, NodeTRS] = {}

    def node_trs(i: int) -> NodeTRS:
        if i in trs:
            return trs[i]
        if i in baked_nodes:
            (tt, tv), (rt, rv), (st, sv) = baked_nodes[i]
            moving = [len(tt) > 1 and np.ptp(tv, axis=0).max() > 0, len(rt) > 1 and np.ptp(rv, axis=0).max() > 0,
                      len(st) > 1 and np.ptp(sv, axis=0).max() > 0]
            node = NodeTRS(names[i], _sample(times, tt, tv, False) if moving[0] else tv[:1],
                           _sample(times, rt, rv, True) if moving[1] else rv[:1],
                           _sample(times, st, sv, False) if moving[2] else sv[:1], animated=i not in still)
        else:
            local = fs.nodes[i].local_transform
            t, r, s = local.translation, local.rotation, local.scale
            node = NodeTRS(names[i], np.array([[t.x, t.y, t.z]], dtype=float),
                           np.array([[r.x, r.y, r.z, r.w]], dtype=float), np.array([[s.x, s.y, s.z]], dtype=float),
                           animated=i not in still)
        trs[i] = node
        return node

    ancestors, joints, jparents = _nodes.member_nodes(fs.members, fs.parents, node_trs)
    return ancestors, joints, jparents, T, rate, fs.up, fs.unit, None if stack is None else fs.stack_names[stack]
