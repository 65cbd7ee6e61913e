"""FBX input (``.fbx``, binary or ASCII): a skeleton and one animation stack as a Motion, through ufbx.

The file is read by ufbx (a single-file C loader; Godot imports FBX with it) through its Python binding
``pufbx`` (``pip install 'mocycle[fbx]'``; imported only when a file is read; ``docs/formats.md`` says why this
binding and not ``pyufbx``).  What is read:

* **the skeleton**: the file's bones (FBX ``LimbNode``/``Root``/``Limb`` nodes: ufbx's bone attribute), with any
  node lying between two bones; meshes, lights, cameras and empties beside them are not joints.  The nodes
  above the root bone (Blender's or Maya's armature object, Mixamo's ``Armature``) are composed into the root.
  Names are kept as written (Mixamo's ``mixamorig:Hips``; the joint groups ``legs``, ``arms`` and ``spine``
  match them by pattern).  A leaf bone that does not move (Blender's ``_end`` bones) becomes an End Site.
* **the animation**: one animation stack (``take``: its name or 0-based index; default the first), baked by
  ufbx (``ufbx_bake_anim``): layers, pre/post rotations, rotation orders, pivots and scaling offsets composed
  into each node's local translation, rotation and scale, linearly keyed; then sampled at the frame rate.
* **the frame rate**: ``fps`` when given; else the keys' own rate when the baked keys lie on a regular grid of at
  least 12 keys a second (rounded to a whole number when within 1e-4), else 30 fps.  (pufbx 0.1.0 does not
  expose the scene's settings, so the file's declared ``TimeMode`` is not read; exporters key every frame, which
  gives it.)
* **units and axes**: the file's own, as its nodes hold them (FBX files are often centimetres, Y up; Blender's
  exporter writes the unit into the armature's scale): the joints' world positions are the file's, whatever
  scale (also non-uniform or animated) sits above or on the bones; see :mod:`._nodes`.

A damaged file is one :class:`~mocycle.errors.MotionFileError` (ufbx checks its input: sizes against the file,
nesting, counts; it was fuzzed by its author and by ``benchmarks/fuzz.py``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import MocycleError, MotionFileError
from ..limits import check_frames, frame_time_problem
from ..motion import Motion
from ._nodes import NodeTRS, choose_take, member_nodes, motion_from_nodes, skeleton_order, unique_names
from .fbx_scan import opened

__all__ = ["DEFAULT_FPS", "fbx_takes", "read_fbx"]

DEFAULT_FPS = 30.0
#: the largest file read (bytes)
MAX_FILE_BYTES = 2**31


def _import():
    try:
        import pufbx
    except ImportError:
        raise MocycleError("reading FBX files needs pufbx (the ufbx loader): pip install 'mocycle[fbx]'") from None
    return pufbx


def _load(path: Path):
    pufbx = _import()
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise MotionFileError(f"cannot read file ({exc.strerror or exc})", path) from None
    if path.is_dir():
        raise MotionFileError("is a folder; mocycle reads FBX files", path)
    if size > MAX_FILE_BYTES:
        raise MotionFileError(f"the file holds {size:,} bytes; FBX files over {MAX_FILE_BYTES:,} are not read", path)
    try:
        with opened(path) as name:  # regular files only, no deflate bomb; any file name (fbx_scan)
            return pufbx.load_fbx(name)
    except MotionFileError:
        raise
    except Exception as exc:  # ufbx's error (its message says what it expected), or the binding's
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise MotionFileError(f"not a readable FBX file ({text})", path) from None


def _stack_names(scene) -> list[str]:
    return unique_names([s.name for s in scene.anim_stacks], prefix="take")


def fbx_takes(path: str | os.PathLike) -> list[str]:
    """The names of the animation stacks (takes) in an FBX file."""
    p = Path(path)
    return _stack_names(_load(p))


def _choose(scene, take, path) -> int | None:
    return choose_take(_stack_names(scene), take, path, "take", "animation stack")


def _keys(struct_array) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of a baked key array (fields ``time`` and ``value`` with x, y, z[, w])."""
    times = np.asarray(struct_array["time"], dtype=np.float64)
    v = struct_array["value"]
    values = np.stack([np.asarray(v[c], dtype=np.float64) for c in v.dtype.names], axis=1)
    return times, values


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


def _regular_rate(times: np.ndarray) -> float | None:
    """The rate of key times on one regular grid, or ``None``."""
    times = np.unique(times)
    if len(times) < 2:
        return None
    step = float(np.min(np.diff(times)))
    if not step > 1e-6:
        return None
    k = (times - times[0]) / step
    if not np.allclose(k, np.round(k), rtol=0, atol=1e-3):
        return None
    rate = 1.0 / step
    if rate < 12.0:  # a few keys far apart: authored keys, not one per frame
        return None
    return float(round(rate)) if abs(rate - round(rate)) < 1e-4 * rate else rate


def read_fbx(path: str | os.PathLike, *, take: str | int | None = None, fps: float | None = None) -> Motion:
    """Read an FBX file's skeleton and one animation stack as a :class:`Motion`.

    Parameters
    ----------
    path : the ``.fbx`` file.
    take : the animation stack's name (or 0-based index); default the first (:func:`fbx_takes` lists them).
    fps : the frame rate to sample at; default the keys' own when regular, else :data:`DEFAULT_FPS`.

    Raises
    ------
    MotionFileError
        A damaged file, an unknown take (the message lists them), or no bones.
    """
    p = Path(path)
    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise MotionFileError(f"the frame rate must be positive; got {fps!r}", p)
    pufbx = _import()
    scene = _load(p)
    try:
        return _read(pufbx, scene, p, take, fps)
    except (MocycleError, MemoryError):
        raise
    except Exception as exc:  # the binding raises its own errors on odd scenes
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise MotionFileError(f"cannot read the FBX scene ({type(exc).__name__}: {text})", p) from None


def _read(pufbx, scene, p: Path, take, fps) -> Motion:
    nodes = list(scene.nodes)
    N = len(nodes)
    index = {id(n): i for i, n in enumerate(nodes)}
    by_typed = {n.typed_id: i for i, n in enumerate(nodes)}
    parents = np.full(N, -1, dtype=np.int64)
    children: list[list[int]] = [[] for _ in range(N)]
    for i, n in enumerate(nodes):
        for c in n.children:
            j = by_typed.get(c.typed_id, index.get(id(c)))
            if j is None or parents[j] >= 0 or j == i:
                raise MotionFileError("the node tree is not a tree", p)
            parents[j] = i
            children[i].append(j)
    from pufbx.enums import ElementType

    bone_type = ElementType.BONE
    bones = [i for i, n in enumerate(nodes) if n.attrib_type == bone_type]
    if not bones:
        raise MotionFileError("no bones (LimbNode, Root or Limb nodes): nothing to read as a skeleton", p)
    members = skeleton_order(parents, children, bones, p)

    stack = _choose(scene, take, p)
    baked_nodes = {}
    rate: float | None = fps
    start = end = 0.0
    if stack is not None:
        anim = scene.anim_stacks[stack].anim
        baked = pufbx.bake_anim(scene, anim, resample_rate=fps or DEFAULT_FPS)
        for b in baked.modified_nodes:
            at = by_typed.get(b.typed_id)
            if at is not None:
                baked_nodes[at] = (_keys(b.translation_keys), _keys(b.rotation_keys), _keys(b.scale_keys))
        all_times = [k[0] for trs in baked_nodes.values() for k in trs]
        if all_times:
            times_all = np.concatenate(all_times)
            if not np.isfinite(times_all).all():
                raise MotionFileError("key times are not finite", p)
            start, end = float(times_all.min()), float(times_all.max())
            if rate is None:
                rate = _regular_rate(times_all) or DEFAULT_FPS
                if rate != DEFAULT_FPS:  # bake again at the keys' own rate (no resampled points in between)
                    baked = pufbx.bake_anim(scene, anim, resample_rate=rate)
                    baked_nodes = {}
                    for b in baked.modified_nodes:
                        at = by_typed.get(b.typed_id)
                        if at is not None:
                            baked_nodes[at] = (_keys(b.translation_keys), _keys(b.rotation_keys),
                                               _keys(b.scale_keys))
        stack_begin, stack_end = float(scene.anim_stacks[stack].time_begin), float(scene.anim_stacks[stack].time_end)
        if np.isfinite(stack_begin) and np.isfinite(stack_end) and stack_end > stack_begin:
            start, end = stack_begin, stack_end
    rate = float(rate or DEFAULT_FPS)
    problem = frame_time_problem(1.0 / rate)
    if problem:
        raise MotionFileError(problem, p)
    if not (end - start < 1e9):
        raise MotionFileError(f"the animation spans {end - start:g} s", p)
    T = check_frames(int(round((end - start) * rate)) + 1, len(members), "the animation", p)
    times = start + np.arange(T) / rate

    names = unique_names([n.name for n in nodes])
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
                           _sample(times, st, sv, False) if moving[2] else sv[:1], animated=any(moving))
        else:
            local = nodes[i].local_transform
            t, r, s = local.translation, local.rotation, local.scale
            node = NodeTRS(names[i], np.array([[t.x, t.y, t.z]], dtype=float),
                           np.array([[r.x, r.y, r.z, r.w]], dtype=float), np.array([[s.x, s.y, s.z]], dtype=float))
        trs[i] = node
        return node

    ancestors, joints, jparents = member_nodes(members, parents, node_trs)
    return motion_from_nodes(ancestors, joints, jparents, T, 1.0 / rate, p)
