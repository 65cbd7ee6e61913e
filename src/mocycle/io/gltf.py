"""Binary glTF 2.0 (``.glb``) output: a skinned skeleton and one animation clip, for engines and three.js.

What the file holds (``docs/formats.md`` has the whole story):

* one node per joint, then one per End Site, named as in the motion, with the rest offsets as translations
  and no rotation: the bind pose is the BVH rest pose;
* a skin over all of them (inverse bind matrices of the rest pose) and a small "stick figure" mesh bound to
  it (one octahedral bone per parent-child pair, rigidly weighted to the parent) so that every viewer shows
  something and engines see a skinned character;
* one animation, sampled at every frame with LINEAR interpolation: rotations of every joint, translations of
  the joints whose translation is not the rest offset (the root, Bandai's ``Hips``); key ``k`` at ``k``
  frame times.

**Units and axes.**  glTF is metres, +Y up, +Z forward.  Lengths are multiplied by ``scale`` (metres per
file unit; ``"auto"``: the unit among :data:`UNITS` that makes the body about :data:`HUMAN_HEIGHT_M` tall),
and the motion's vertical (detected by :func:`mocycle.axes.vertical_axis`, or given) is turned onto +Y by
the smallest rotation, baked into the root joint's rotation and translation (so the root joint's
translation is the root motion in glTF axes; a Z-up take's -Y front becomes +Z, as Blender exports).

pygltflib is imported only when a file is written (``pip install 'mocycle[gltf]'``).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..clip import Clip, jsonable
from ..errors import MocycleError, MocycleWarning, MotionFileError, OptionError
from ..motion import Motion
from ..rotations import quat_multiply
from ..text import renamed, valid_unicode
from .atomic import atomic_write

__all__ = ["HUMAN_HEIGHT_M", "UNITS", "GltfFrame", "check_options", "gltf_frame", "write_gltf"]

#: the length units ``scale="auto"`` chooses from: name -> metres per unit (``cmu``: the CMU ASF/AMC unit,
#: inch / 0.45, which the CMU BVH conversions keep)
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "cmu": 0.0254 / 0.45}
#: the body size ``scale="auto"`` aims at, metres
HUMAN_HEIGHT_M = 1.7
#: ``scale="auto"`` warns when the chosen unit still leaves the body outside this range, metres
PLAUSIBLE_HEIGHT_M = (0.5, 3.5)

_FLOAT, _USHORT, _UINT, _UBYTE = 5126, 5123, 5125, 5121
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963


@dataclass(frozen=True)
class GltfFrame:
    """From the motion's units and axes to glTF's: ``p_gltf = scale * rotation @ p``.

    scale : metres per motion unit.
    unit : the unit's name (a key of :data:`UNITS`; ``"given"`` when ``scale`` was a number, ``"file"`` for a
        unit the file declares that is none of them).
    up : ``(3,)`` the motion's vertical, motion axes.
    rotation : ``(3, 3)`` the rotation that takes ``up`` to +Y.
    body_size : the body's size in motion units (what ``"auto"`` measured).
    """

    scale: float
    unit: str
    up: np.ndarray
    rotation: np.ndarray
    body_size: float

    def point(self, p: np.ndarray) -> np.ndarray:
        """Positions ``(..., 3)`` in motion units and axes -> glTF metres and axes."""
        return self.scale * np.asarray(p, dtype=float) @ self.rotation.T

    def direction(self, v: np.ndarray) -> np.ndarray:
        """Directions ``(..., 3)`` (no scaling) in motion axes -> glTF axes."""
        return np.asarray(v, dtype=float) @ self.rotation.T

    def to_dict(self) -> dict:
        return {"metres_per_unit": self.scale, "unit": self.unit, "source_up": self.up.tolist(),
                "source_to_gltf_rotation_xyzw": Rotation.from_matrix(self.rotation).as_quat().tolist(),
                "body_size_units": self.body_size}


def body_size(motion: Motion) -> float:
    """The body's size in motion units: the largest extent of the rest pose (a T-pose's height or arm span)
    or of the median frame's pose, whichever is larger; the travel joint and the joints and End Sites below
    it (a static ``joint_Root`` left behind at the room's origin is no part of the body), or the body's root
    and everything below it when the travel joint has no joint below it (an IK target that moves, as
    RobotExpressive's feet)."""
    sk = motion.skeleton
    parents = list(sk.parents) + [site.parent for site in sk.end_sites]
    travel, below = motion.travel_joint, []
    if not sk.children(travel):
        travel = sk.body_root()
    for i, p in enumerate(parents):  # parents come first
        if i == travel or (p >= 0 and p in below):
            below.append(i)
    rest = Motion.rest(sk).world_positions(end_sites=True)[0, below]
    poses = motion[::max(1, motion.n_frames // 50)].world_positions(end_sites=True)[:, below]
    moving = float(np.median(np.ptp(poses, axis=1).max(axis=1)))
    return max(float(np.ptp(rest, axis=0).max()), moving)


def check_options(scale: float | str = "auto", up=None) -> tuple[float | str, object]:
    """``scale`` and ``up`` in their normal form (``"auto"`` or a unit name or metres per unit; ``None`` or an
    up vector), or an :class:`~mocycle.errors.OptionError` naming ``gltf_scale`` or ``gltf_up``: what a
    front end checks before any work is done."""
    from ..axes import parse_up

    if isinstance(scale, str) and scale.strip().lower() in ("auto", *UNITS):
        scale = scale.strip().lower()
    else:
        _units(scale, 1.0)
        scale = float(scale)
    if isinstance(up, str) and up.strip().lower() == "auto":
        up = None
    if up is not None:
        try:
            up = parse_up(up)
        except OptionError as exc:
            raise OptionError("gltf_up", exc.reason.replace("must be one of", "must be auto or one of")) from None
    return scale, up


def gltf_frame(motion: Motion, scale: float | str = "auto", up=None) -> GltfFrame:
    """The conversion of ``motion`` into glTF units and axes.

    Parameters
    ----------
    motion : the take.
    scale : metres per motion unit (a positive number), a unit name of :data:`UNITS`, or ``"auto"``: the unit
        the file declares (the skeleton's :attr:`~mocycle.motion.Skeleton.metres_per_unit`: glTF, FBX), the same
        for every take of a file; else the unit that makes the body (:func:`body_size`) closest to
        :data:`HUMAN_HEIGHT_M` on a log scale, with a :class:`~mocycle.errors.MocycleWarning` when even that
        leaves it outside :data:`PLAUSIBLE_HEIGHT_M`.
    up : ``None`` or ``"auto"`` for the motion's vertical (the declared one, else detected:
        :func:`mocycle.axes.vertical_axis`), or ``"y"``, ``"z"``, ``"-z"``, ... or a 3-vector.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk, to_z_up
    >>> walk = synthetic_walk(n_frames=60).motion
    >>> f = gltf_frame(walk)
    >>> f.unit, f.scale, f.rotation.round(6).tolist() == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    ('cm', 0.01, True)
    >>> gltf_frame(to_z_up(walk)).point([0, 0, 100]).round(6).tolist()
    [0.0, 1.0, 0.0]
    """
    from ..axes import vertical_axis

    scale, up = check_options(scale, up)
    v = vertical_axis(motion, up)
    size = body_size(motion)
    declared = motion.skeleton.metres_per_unit
    if scale == "auto" and declared is not None:
        unit = next((name for name, m in UNITS.items() if abs(m - declared) <= 1e-9 * m), "file")
        metres = declared
    else:
        unit, metres = _units(scale, size)
    if v[1] < -1 + 1e-12:  # upside down: half a turn about X (align_vectors has no unique answer)
        rot = np.diag([1.0, -1.0, -1.0])
    else:
        rot = Rotation.align_vectors([[0.0, 1.0, 0.0]], [v])[0].as_matrix()
        rot[np.abs(rot) < 1e-12] = 0.0
    return GltfFrame(scale=metres, unit=unit, up=v, rotation=rot, body_size=size)


def _units(scale, size: float) -> tuple[str, float]:
    """(unit name, metres per unit) of a ``scale`` option, for a body ``size`` units tall."""
    if isinstance(scale, str):
        name = scale.strip().lower()
        if name in UNITS:
            return name, UNITS[name]
        if name == "auto":
            if not size > 0:
                return "m", 1.0
            unit = min(UNITS, key=lambda u: abs(np.log(size * UNITS[u] / HUMAN_HEIGHT_M)))
            lo, hi = PLAUSIBLE_HEIGHT_M
            if not lo <= size * UNITS[unit] <= hi:
                warnings.warn(f"glTF units: the body is {size:.4g} units tall; no common unit makes that a person "
                              f"({size * UNITS[unit]:.3g} m in {unit}); pass option 'gltf_scale' (metres per unit)",
                              MocycleWarning, stacklevel=3)
            return unit, UNITS[unit]
    try:
        metres = float(scale)
    except (TypeError, ValueError):
        metres = float("nan")
    if not (np.isfinite(metres) and 0 < metres < 1e6):
        raise OptionError("gltf_scale", f"must be 'auto', a unit ({', '.join(UNITS)}) or a positive number of "
                                        f"metres per unit; got {scale!r}")
    return "given", metres


class _Blob:
    """The GLB's binary chunk: arrays appended as buffer views and accessors (4-byte aligned)."""

    def __init__(self, gl):
        self.gl, self.parts, self.length = gl, [], 0

    def add(self, array: np.ndarray, kind: str, component: int, target: int | None = None,
            bounds: bool = False) -> int:
        from pygltflib import Accessor, BufferView

        dtype = {_FLOAT: "<f4", _USHORT: "<u2", _UINT: "<u4", _UBYTE: "u1"}[component]
        a = np.ascontiguousarray(array, dtype=dtype)
        data = a.tobytes()
        self.gl.bufferViews.append(BufferView(buffer=0, byteOffset=self.length, byteLength=len(data), target=target))
        pad = (-len(data)) % 4
        self.parts += [data, b"\0" * pad]
        self.length += len(data) + pad
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[kind]
        flat = a.reshape(-1, width)
        extra = {"min": flat.min(axis=0).tolist(), "max": flat.max(axis=0).tolist()} if bounds else {}
        self.gl.accessors.append(Accessor(bufferView=len(self.gl.bufferViews) - 1, componentType=component,
                                          count=flat.shape[0], type=kind, **extra))
        return len(self.gl.accessors) - 1

    def bytes(self) -> bytes:
        return b"".join(self.parts)


def _glb_pieces(gl, blob: _Blob):
    """The binary glTF container of ``gl`` (its one buffer: ``blob``, views laid out 4-byte aligned) piece by
    piece: the bytes pygltflib's ``save_to_bytes`` gives, without joining the blob into one copy and then a
    second (a long take's animation is most of the file)."""
    import struct

    text = gl.gltf_to_json(separators=(",", ":"), indent=None).encode("utf-8")
    text += b" " * (-(12 + len(text)) % 4)  # the binary chunk's data starts 4-byte aligned
    yield b"glTF" + struct.pack("<II", 2, 12 + 2 * 8 + len(text) + blob.length)
    yield struct.pack("<I", len(text)) + b"JSON" + text
    yield struct.pack("<I", blob.length) + b"BIN\0"
    yield from blob.parts


def _stick_figure(points: np.ndarray, parents: np.ndarray, size: float):
    """An octahedral bone from each parent to each child (rest positions ``points (N, 3)``), weighted to the
    parent: positions ``(V, 3)``, parent joint per vertex ``(V,)``, triangle indices ``(F*3,)``."""
    pos: list[np.ndarray] = []
    joint: list[int] = []
    tris: list[int] = []
    for c in range(len(points)):
        p = parents[c]
        if p < 0:
            continue
        a, b = points[p], points[c]
        axis = b - a
        length = float(np.linalg.norm(axis))
        if length < 1e-6 * size:
            continue
        d = axis / length
        helper = np.eye(3)[int(np.argmin(np.abs(d)))]
        u = np.cross(d, helper)
        u /= np.linalg.norm(u)
        w = np.cross(d, u)
        r, mid = 0.1 * length, a + 0.2 * axis
        ring = [mid + r * u, mid + r * w, mid - r * u, mid - r * w]
        base = len(pos)
        pos += [a, b, *ring]
        joint += [p] * 6
        for k in range(4):
            i, j = base + 2 + k, base + 2 + (k + 1) % 4
            tris += [base, j, i, base + 1, i, j]  # outward faces
    if not pos:
        return np.zeros((0, 3)), np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    return np.asarray(pos), np.asarray(joint), np.asarray(tris)


def _trs_matrix(q: np.ndarray, t: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(q).as_matrix()
    m[:3, 3] = t
    return m


def write_gltf(motion: Motion, path: str | os.PathLike, *, clip: Clip | None = None, scale: float | str = "auto",
               up=None, generator: str = "mocycle") -> Path:
    """Write ``motion`` as a binary glTF (``.glb``): skinned skeleton, stick-figure mesh, one animation clip.

    Parameters
    ----------
    motion : the motion; every frame becomes a key (LINEAR), key ``k`` at ``k * frame_time`` seconds.
    path : the ``.glb`` file (written atomically).
    clip : the clip's name and loop facts (:class:`~mocycle.clip.Clip`); written as the animation's name and,
        with the unit conversion, in the ``extras`` of the animation and of the scene (``"mocycle"``).
        Default: a clip named after the file, not loopable.
    scale, up : units and vertical (:func:`gltf_frame`).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from mocycle.datasets import synthetic_walk
    >>> out = write_gltf(synthetic_walk(n_frames=30).motion, pathlib.Path(tempfile.mkdtemp()) / "walk.glb")
    >>> out.read_bytes()[:4]
    b'glTF'
    """
    try:
        import pygltflib as g
    except ImportError:
        raise MocycleError("writing .glb files needs pygltflib: pip install 'mocycle[gltf]'") from None
    p = Path(path)
    frame = gltf_frame(motion, scale, up)
    clip = clip or Clip(name=p.stem)
    sk = motion.skeleton
    J, T = sk.n_joints, motion.n_frames
    names = list(sk.names) + [s.name or f"{sk.names[s.parent]}_end" for s in sk.end_sites]
    names = renamed(names, valid_unicode, "glTF (UTF-8 text)")  # a lone surrogate as U+FFFD, one warning
    clip = replace(clip, name=valid_unicode(clip.name))
    taken = set(names[:J])
    for i in range(J, len(names)):  # End Site names unique among the nodes
        base, k = names[i], 1
        while names[i] in taken:
            names[i], k = f"{base}.{k}", k + 1
        taken.add(names[i])
    parents = np.concatenate([sk.parents, [s.parent for s in sk.end_sites]]).astype(int)
    offsets = np.concatenate([sk.offsets, np.asarray([s.offset for s in sk.end_sites]).reshape(-1, 3)])
    N = len(names)

    # rest (bind) pose in glTF units: the vertical turn baked into the root joint
    r_quat = Rotation.from_matrix(frame.rotation).as_quat()
    rest_t = offsets * frame.scale
    rest_t[0] = frame.point(offsets[0])
    rest_q = np.tile([0.0, 0.0, 0.0, 1.0], (N, 1))
    rest_q[0] = r_quat
    world = np.empty((N, 4, 4))
    for i in range(N):
        local = _trs_matrix(rest_q[i], rest_t[i])
        world[i] = local if parents[i] < 0 else world[parents[i]] @ local
    inverse_bind = np.linalg.inv(world)

    # animation in glTF units (joint by joint: the translations of the joints that move are kept, as float32
    # like the rotations, so no float64 copy of the take is made)
    tol = 1e-7 * max(frame.body_size * frame.scale, 1e-9)
    trans32: dict[int, np.ndarray] = {}
    for j in range(J):
        tj = frame.point(motion.joint_translations(j)) if j == 0 else motion.joint_translations(j) * frame.scale
        if np.abs(tj - rest_t[j]).max() > tol:
            trans32[j] = tj.astype(np.float32)
    moves = list(trans32)

    gl = g.GLTF2(asset=g.Asset(version="2.0", generator=generator))
    blob = _Blob(gl)
    gl.nodes = [g.Node(name=names[i], translation=rest_t[i].tolist(),
                       rotation=rest_q[i].tolist() if i == 0 else None,
                       children=[int(c) for c in np.flatnonzero(parents == i)] or None) for i in range(N)]
    ibm = blob.add(inverse_bind.transpose(0, 2, 1).reshape(N, 16), "MAT4", _FLOAT)  # column-major
    gl.skins = [g.Skin(name=f"{clip.name}_skin", joints=list(range(N)), inverseBindMatrices=ibm, skeleton=0)]

    pos, owner, tris = _stick_figure(world[:, :3, 3], parents, frame.body_size * frame.scale)
    scene_nodes = [0]
    if len(pos):
        joints4 = np.zeros((len(pos), 4), dtype=int)
        joints4[:, 0] = owner
        weights = np.zeros((len(pos), 4))
        weights[:, 0] = 1.0
        attrs = g.Attributes(POSITION=blob.add(pos, "VEC3", _FLOAT, _ARRAY_BUFFER, bounds=True),
                             JOINTS_0=blob.add(joints4, "VEC4", _UBYTE if N <= 256 else _USHORT, _ARRAY_BUFFER),
                             WEIGHTS_0=blob.add(weights, "VEC4", _FLOAT, _ARRAY_BUFFER))
        index = blob.add(tris, "SCALAR", _USHORT if len(pos) < 65535 else _UINT, _ELEMENT_ARRAY_BUFFER)
        gl.materials = [g.Material(name="bones", doubleSided=False,
                                   pbrMetallicRoughness=g.PbrMetallicRoughness(baseColorFactor=[0.8, 0.8, 0.8, 1.0],
                                                                               metallicFactor=0.0))]
        gl.meshes = [g.Mesh(name=f"{clip.name}_bones", primitives=[g.Primitive(attributes=attrs, indices=index,
                                                                                  material=0)])]
        gl.nodes.append(g.Node(name=f"{clip.name}_figure", mesh=0, skin=0))
        scene_nodes.append(len(gl.nodes) - 1)

    times = np.arange(T, dtype=np.float64) * motion.frame_time
    if T > 1 and not np.all(np.diff(times.astype(np.float32)) > 0):
        raise MotionFileError(f"{T} frames of {motion.frame_time:g} s do not fit glTF's 32-bit key times", p)
    t_acc = blob.add(times, "SCALAR", _FLOAT, bounds=True)
    samplers, channels = [], []
    for j in range(J):
        q32 = (quat_multiply(np.broadcast_to(r_quat, (T, 4)), motion.rotations[:, 0]) if j == 0
               else motion.rotations[:, j]).astype(np.float32)
        q32 /= np.linalg.norm(q32, axis=-1, keepdims=True)
        samplers.append(g.AnimationSampler(input=t_acc, output=blob.add(q32, "VEC4", _FLOAT),
                                           interpolation="LINEAR"))
        channels.append(g.AnimationChannel(sampler=len(samplers) - 1, target=g.AnimationChannelTarget(
            node=j, path="rotation")))
    for j in moves:
        samplers.append(g.AnimationSampler(input=t_acc, output=blob.add(trans32.pop(j), "VEC3", _FLOAT),
                                           interpolation="LINEAR"))
        channels.append(g.AnimationChannel(sampler=len(samplers) - 1, target=g.AnimationChannelTarget(
            node=j, path="translation")))
    meta = clip.metadata(motion.frame_time, length=frame.point)
    meta["translated_joints"] = [names[j] for j in moves]
    gl.animations = [g.Animation(name=clip.name, samplers=samplers, channels=channels, extras=meta)]
    gl.scenes = [g.Scene(name=clip.name, nodes=scene_nodes,
                         extras={"mocycle": jsonable({"units": frame.to_dict(), "clips": [meta]})})]
    gl.scene = 0
    gl.buffers = [g.Buffer(byteLength=blob.length)]
    try:
        return atomic_write(p, _glb_pieces(gl, blob), binary=True)
    except OSError as exc:
        raise MotionFileError(f"cannot write file ({exc.strerror or exc})", p) from None
