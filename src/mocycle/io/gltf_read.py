"""glTF 2.0 input (``.glb`` and ``.gltf``): a skinned skeleton and one of its animations as a Motion.

What is read (``docs/formats.md`` has the whole story):

* **the skeleton**: the joints of the file's skin (the one with the most joints when there are several), plus any
  node lying between two of them; parents first.  The nodes above the skeleton's root (Blender's armature object,
  an axis or unit conversion) are composed into the root.  Without a skin, the animated nodes and the nodes
  between them form the skeleton (the nodes any animation moves: the same for every take).  A leaf joint that
  no channel of any animation animates becomes an End Site: every take has the same joints.
* **the animation**: one of the file's animations (``take``: its name or its 0-based index; default the first
  that moves the skeleton, said in a :class:`~mocycle.errors.DefaultTake` warning when there are several),
  its ``translation``, ``rotation`` and ``scale`` channels on those nodes (``weights`` are morph targets: not
  read), with LINEAR (slerp for rotations), STEP and CUBICSPLINE (Hermite, glTF's tangents scaled by the key
  interval) samplers, sampled at the file's frame rate (``fps`` when given): the key rate of its animations,
  the one on whose frames the keys of most of them lie (rounded to a whole number of frames per second when
  within 1e-4 of one), else 30; a take whose keys lie off those frames says so (a MocycleWarning).
  A file without animations is its rest pose, one frame.
* **units and axes**: glTF's metres and +Y up, as the file holds them and as the skeleton says
  (:attr:`Skeleton.up`, :attr:`Skeleton.metres_per_unit`); except in a file mocycle wrote (its
  scene's ``extras.mocycle.units``), whose unit scale and vertical turn are undone, so the motion read is the
  one written.
* scale on nodes (also animated): the joints' world positions are the file's; see :mod:`._nodes`.

Hostile files: every index, count, offset and stride is checked against the buffers the file holds before any
array is made, the node tree must be a tree (no cycles, one parent per node), and anything else wrong is one
:class:`~mocycle.errors.MotionFileError` naming the file and what was expected.

The JSON is read with the standard library (pygltflib, which the writer uses, builds a dataclass per JSON object:
85% of the time of a 100-joint file) and every field is checked here.
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import MocycleWarning, MotionFileError
from ..motion import Motion
from ._nodes import (
    DEFAULT_FPS,
    MAX_FILE_BYTES,
    NodeTRS,
    Sampled,
    choose_take,
    default_take,
    frame_times,
    joint_names,
    key_rate,
    member_nodes,
    motion_from_nodes,
    skeleton_order,
    unique_names,
)
from .regular import read_regular

__all__ = ["DEFAULT_FPS", "gltf_takes", "read_gltf"]

_COMPONENTS = {5120: ("i1", 127.0), 5121: ("u1", 255.0), 5122: ("<i2", 32767.0), 5123: ("<u2", 65535.0),
               5125: ("<u4", None), 5126: ("<f4", None)}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_PATHS = {"translation": 3, "rotation": 4, "scale": 3}


class _Obj(dict):
    """A glTF JSON object with attribute access (``node.children``; a missing key is ``None``); objects and lists
    inside are wrapped when reached."""

    def __getattr__(self, name):
        value = self.get(name)
        wrapped = _wrap(value)
        if wrapped is not value:
            self[name] = wrapped  # wrapped once
        return wrapped


class _List(list):
    """A JSON list whose objects are wrapped."""


def _wrap(value):
    if isinstance(value, dict) and not isinstance(value, _Obj):
        return _Obj(value)
    if isinstance(value, list) and not isinstance(value, _List):
        return _List(_Obj(v) if isinstance(v, dict) and not isinstance(v, _Obj) else v for v in value)
    return value


def _int(value, what: str, path, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int within [low, high], or one clear error."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low \
            or (high is not None and value > high):
        bound = f"{low} to {high}" if high is not None else f"at least {low}"
        raise MotionFileError(f"{what} must be a whole number, {bound}; got {value!r}", path)
    return int(value)


def _list(value, what: str, path) -> list:
    if value is None:
        return []
    if not isinstance(value, list):
        raise MotionFileError(f"{what} must be a list; got {type(value).__name__}", path)
    return value


# The fields the reader uses and their JSON types ("int": a whole number, not true/false; "num": any number;
# [x]: a list of x; {...}: an object with those fields). Other fields are not read, and extras are anyone's.
_SCHEMA = {
    "asset": {"generator": "str"},
    "nodes": [{"name": "str", "children": ["int"], "translation": ["num"], "rotation": ["num"], "scale": ["num"],
               "matrix": ["num"]}],
    "skins": [{"joints": ["int"]}],
    "accessors": [{"bufferView": "int", "byteOffset": "int", "componentType": "int", "normalized": "bool",
                   "count": "int", "type": "str"}],
    "bufferViews": [{"buffer": "int", "byteOffset": "int", "byteLength": "int", "byteStride": "int"}],
    "buffers": [{"uri": "str", "byteLength": "int"}],
    "animations": [{"name": "str", "channels": [{"sampler": "int", "target": {"node": "int", "path": "str"}}],
                    "samplers": [{"input": "int", "output": "int", "interpolation": "str"}]}],
    "scenes": [{"nodes": ["int"]}],
}
_TYPES = {"int": ((int,), "a whole number"), "num": ((int, float), "a number"), "str": ((str,), "text"),
          "bool": ((bool,), "true or false")}


def _what(value) -> str:
    if value is None:
        return "null"
    return {bool: "true/false", str: "text", list: "a list", dict: "an object"}.get(type(value), "a number")


def check_types(document: dict, path) -> None:
    """Every field the reader uses has its JSON type (:data:`_SCHEMA`), or one :class:`MotionFileError` naming
    it (``accessors[3].type must be text; got a list``); a field set to ``null`` counts as absent.  Values and
    indices are checked where they are used; this is the one place types are."""
    todo: list[tuple[Any, Any, str]] = [(document, _SCHEMA, "")]
    while todo:
        value, schema, where = todo.pop()
        if value is None:
            continue
        if isinstance(schema, dict):
            if not isinstance(value, dict):
                raise MotionFileError(f"{where or 'the glTF JSON'} must be an object; got {_what(value)}", path)
            todo += [(value.get(k), sub, f"{where}.{k}" if where else k) for k, sub in schema.items()]
        elif isinstance(schema, list):
            if not isinstance(value, list):
                raise MotionFileError(f"{where} must be a list; got {_what(value)}", path)
            item = schema[0]
            if isinstance(item, str):
                kinds, name = _TYPES[item]
                bad = next((i for i, x in enumerate(value) if isinstance(x, bool) or not isinstance(x, kinds)), None)
                if bad is not None:
                    raise MotionFileError(f"{where}[{bad}] must be {name}; got {_what(value[bad])}", path)
            else:
                bad = next((i for i, x in enumerate(value) if not isinstance(x, dict)), None)
                if bad is not None:
                    raise MotionFileError(f"{where}[{bad}] must be an object; got {_what(value[bad])}", path)
                todo += [(x, item, f"{where}[{i}]") for i, x in enumerate(value)]
        else:
            kinds, name = _TYPES[schema]
            if isinstance(value, bool) != (schema == "bool") or not isinstance(value, kinds):
                raise MotionFileError(f"{where} must be {name}; got {_what(value)}", path)


class _File:
    """A loaded glTF: its JSON (as pygltflib objects) and its buffers' bytes, every access checked."""

    def __init__(self, path: Path):
        self.path = path
        data = read_regular(path, MAX_FILE_BYTES, "the file")  # no FIFO, device or folder; bounded
        binary = data[:4] == b"glTF"
        if path.suffix.lower() == ".glb" and not binary:
            raise MotionFileError("not a binary glTF file: expected it to start with 'glTF'", path)
        self.blob: bytes | bytearray | None = None
        text: bytes | bytearray
        if binary:
            text, self.blob = self._chunks(data)
        else:
            text = data
        try:
            document = json.loads(text.decode("utf-8"))
        except RecursionError:
            raise MotionFileError("the glTF JSON is nested too deeply", path) from None
        except (UnicodeDecodeError, ValueError) as exc:
            raise MotionFileError(f"the glTF JSON does not parse ({str(exc)[:120]})", path) from None
        if not isinstance(document, dict) or not isinstance(document.get("nodes", []), list):
            raise MotionFileError("not a glTF file: expected a JSON object with a 'nodes' list", path)
        check_types(document, path)
        self.gl = _Obj(document)
        self._buffers: dict[int, bytes | bytearray] = {}
        self._buffer_bytes = 0  # of the buffers read so far (at most MAX_FILE_BYTES together)

    def _chunks(self, data: bytes | bytearray) -> tuple[bytes | bytearray, bytes | bytearray | None]:
        """The JSON chunk and the binary chunk (or ``None``) of a GLB, every length checked against the file."""
        if len(data) < 20:
            raise MotionFileError(f"a binary glTF file holds at least 20 bytes; this one {len(data)}", self.path)
        length = int.from_bytes(data[8:12], "little")
        if length > len(data):
            raise MotionFileError(f"the header says {length:,} bytes; the file holds {len(data):,} (truncated?)",
                                  self.path)
        at, chunks, text, blob = 12, 0, None, None
        while at < length:
            if at + 8 > length:
                raise MotionFileError(f"a chunk header at byte {at} runs past the end of the file", self.path)
            n = int.from_bytes(data[at:at + 4], "little")
            kind = data[at + 4:at + 8]
            if chunks == 0 and kind != b"JSON":
                raise MotionFileError("the first chunk of a binary glTF must be JSON", self.path)
            if at + 8 + n > length:
                raise MotionFileError(f"chunk {chunks} claims {n:,} bytes; the file holds {length - at - 8:,} after "
                                      f"its header (truncated?)", self.path)
            if chunks == 0:
                text = data[at + 8:at + 8 + n]
            elif chunks == 1 and kind == b"BIN\0":
                blob = data[at + 8:at + 8 + n]
            at += 8 + n
            chunks += 1
        if text is None:
            raise MotionFileError(f"the header says {length} bytes: no room for the JSON chunk", self.path)
        return text, blob

    def items(self, kind: str) -> list:
        return _list(getattr(self.gl, kind, None), kind, self.path)

    def item(self, kind: str, index, what: str):
        items = self.items(kind)
        i = _int(index, what, self.path, 0, max(len(items) - 1, 0))
        if i >= len(items):
            raise MotionFileError(f"{what} is {i}, but the file has no {kind}", self.path)
        return items[i]

    def buffer(self, index: int) -> bytes | bytearray:
        if index in self._buffers:
            return self._buffers[index]
        buf = self.item("buffers", index, "bufferView.buffer")
        uri = getattr(buf, "uri", None)
        length = _int(getattr(buf, "byteLength", None), f"buffers[{index}].byteLength", self.path)
        if uri is None:
            if self.blob is None or index != 0:
                raise MotionFileError(f"buffers[{index}] has no uri and the file no binary chunk for it", self.path)
            data = self.blob
        elif not isinstance(uri, str):
            raise MotionFileError(f"buffers[{index}].uri must be text", self.path)
        elif uri.startswith("data:"):
            import base64
            import binascii

            head, _, body = uri.partition(",")
            if not head.endswith(";base64"):
                raise MotionFileError(f"buffers[{index}]: only base64 data URIs are read", self.path)
            if len(body) > 4 * (length // 3 + 2):
                raise MotionFileError(f"buffers[{index}]: the data URI is longer than byteLength {length}", self.path)
            try:
                data = base64.b64decode(body, validate=True)
            except (binascii.Error, ValueError):
                raise MotionFileError(f"buffers[{index}]: the data URI is not base64", self.path) from None
        else:
            label = f"buffers[{index}]'s file {uri[:120]!r}"
            data = read_regular(self.local_file(uri, f"buffers[{index}].uri"), MAX_FILE_BYTES - self._buffer_bytes,
                                label, self.path, exact=length)  # never more than byteLength
        if len(data) < length:
            raise MotionFileError(f"buffers[{index}] says {length:,} bytes but holds {len(data):,} (truncated?)",
                                  self.path)
        self._buffer_bytes += len(data)
        self._buffers[index] = data
        return data

    def local_file(self, uri: str, what: str) -> Path:
        """The file a relative ``uri`` names in the glTF's own folder (links followed, and only when they stay
        inside it).  An absolute path, a scheme (``file:``, ``http:``), ``..`` or a link leading out is refused
        with one message that says nothing of what lies outside."""
        from urllib.parse import unquote, urlsplit

        text = unquote(uri)
        try:
            scheme = urlsplit(uri).scheme
        except ValueError:
            scheme = "?"
        parts = text.split("/")
        if scheme or not text or text.startswith("/") or "\\" in text or "\0" in text or ".." in parts:
            raise MotionFileError(f"{what} must be a relative path to a file in the glTF's own folder (no '..', no "
                                  f"absolute path, no scheme); got {uri[:120]!r}", self.path)
        folder = self.path.parent.resolve()
        try:
            target = (folder / text).resolve()
        except (OSError, RuntimeError):
            target = None
        if target is None or folder not in target.parents:
            raise MotionFileError(f"{what} {uri[:120]!r} leads outside the glTF's own folder (a symbolic link); "
                                  f"only files in the folder are read", self.path)
        return target

    def accessor(self, index, what: str, widths: tuple[int, ...]) -> np.ndarray:
        """Accessor ``index`` as float64 ``(count, width)`` (normalised integers scaled to [-1, 1] or [0, 1]);
        every size checked against its buffer before anything is made."""
        acc = self.item("accessors", index, what)
        label = f"accessors[{index}] ({what})"
        if getattr(acc, "sparse", None) is not None:
            raise MotionFileError(f"{label} is sparse; sparse accessors are not read", self.path)
        kind = getattr(acc, "type", None)
        if kind not in _WIDTH or _WIDTH[kind] not in widths:
            raise MotionFileError(f"{label}: expected {' or '.join(str(w) for w in widths)} components a value; "
                                  f"type is {kind!r}", self.path)
        width = _WIDTH[kind]
        component = getattr(acc, "componentType", None)
        if component not in _COMPONENTS:
            raise MotionFileError(f"{label}: unknown componentType {component!r}", self.path)
        dtype, norm = _COMPONENTS[component]
        if component != 5126 and not getattr(acc, "normalized", False):
            raise MotionFileError(f"{label}: integer values must be normalized to be read as numbers", self.path)
        count = _int(getattr(acc, "count", None), f"{label}.count", self.path, 1)
        size = np.dtype(dtype).itemsize
        element = size * width
        view_index = getattr(acc, "bufferView", None)
        if view_index is None:
            raise MotionFileError(f"{label} has no bufferView (all zeros) where values are expected", self.path)
        view = self.item("bufferViews", view_index, f"{label}.bufferView")
        buf_index = _int(getattr(view, "buffer", None), f"bufferViews[{view_index}].buffer", self.path)
        data = self.buffer(buf_index)
        v_off = _int(getattr(view, "byteOffset", None) or 0, f"bufferViews[{view_index}].byteOffset", self.path)
        v_len = _int(getattr(view, "byteLength", None), f"bufferViews[{view_index}].byteLength", self.path, 1)
        stride = getattr(view, "byteStride", None)
        stride = element if stride is None else _int(stride, f"bufferViews[{view_index}].byteStride", self.path,
                                                     4, 252)
        a_off = _int(getattr(acc, "byteOffset", None) or 0, f"{label}.byteOffset", self.path)
        if stride < element:
            raise MotionFileError(f"{label}: byteStride {stride} is shorter than one value ({element} bytes)",
                                  self.path)
        if v_off + v_len > len(data):
            raise MotionFileError(f"bufferViews[{view_index}] ends at byte {v_off + v_len:,}; its buffer holds "
                                  f"{len(data):,}", self.path)
        need = a_off + stride * (count - 1) + element
        if need > v_len:
            raise MotionFileError(f"{label}: {count:,} values need {need:,} bytes; its bufferView holds {v_len:,}",
                                  self.path)
        if (v_off + a_off) % size:
            raise MotionFileError(f"{label}: values not aligned to their {size}-byte components", self.path)
        raw = np.ndarray((count, width), dtype=dtype, buffer=data, offset=v_off + a_off, strides=(stride, size))
        out = raw.astype(np.float64)
        if norm is not None:
            out /= norm
            if dtype.lstrip("<")[0] == "i":
                np.maximum(out, -1.0, out=out)
        return out


def _parents(f: _File) -> np.ndarray:
    """Each node's parent (``-1`` at the top); a node with two parents or a cycle is refused (linear time: the
    nodes reached from the tops are the tree, any other node lies on a cycle)."""
    nodes = f.items("nodes")
    N = len(nodes)
    parents = np.full(N, -1, dtype=np.int64)
    for i, node in enumerate(nodes):
        for c in _list(getattr(node, "children", None), f"nodes[{i}].children", f.path):
            c = _int(c, f"nodes[{i}].children", f.path, 0, N - 1)
            if c == i or parents[c] >= 0:
                raise MotionFileError(f"node {c} has two parents (or is its own child); the nodes must form a tree",
                                      f.path)
            parents[c] = i
    children: list[list[int]] = [[] for _ in range(N)]
    for c, p in enumerate(parents.tolist()):
        if p >= 0:
            children[p].append(c)
    reached = np.zeros(N, dtype=bool)
    stack = np.flatnonzero(parents < 0).tolist()
    while stack:
        i = stack.pop()
        reached[i] = True
        stack += children[i]
    if not reached.all():
        raise MotionFileError(f"the node tree has a cycle through node {int(np.argmin(reached))}", f.path)
    return parents


def _rest_trs(f: _File, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A node's own translation, rotation and scale (its ``matrix`` decomposed when it has one)."""
    node = f.items("nodes")[i]

    def vec(name, n, default):
        v = getattr(node, name, None)
        if v is None:
            return np.asarray(default, dtype=float)
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            a = np.zeros(0)
        if a.shape != (n,):
            raise MotionFileError(f"nodes[{i}].{name} must hold {n} numbers", f.path)
        return a

    m = getattr(node, "matrix", None)
    if m is not None and not np.array_equal(np.asarray(vec("matrix", 16, np.eye(4).ravel())), np.eye(4).ravel()):
        mat = vec("matrix", 16, None).reshape(4, 4).T  # column-major
        if not np.isfinite(mat).all():
            raise MotionFileError(f"nodes[{i}].matrix holds NaN or infinite values", f.path)
        t = mat[:3, 3].copy()
        s = np.linalg.norm(mat[:3, :3], axis=0)
        if np.linalg.det(mat[:3, :3]) < 0:
            s[0] = -s[0]
        if np.any(np.abs(s) < 1e-300):
            raise MotionFileError(f"nodes[{i}].matrix has a zero scale", f.path)
        from ..rotations import nearest_rotations

        q = Rotation.from_matrix(nearest_rotations(mat[:3, :3] / s)).as_quat()
        return t, q, s
    return (vec("translation", 3, [0, 0, 0]), vec("rotation", 4, [0, 0, 0, 1]), vec("scale", 3, [1, 1, 1]))


def _animations(f: _File) -> list:
    return f.items("animations")


def _names(f: _File) -> list[str]:
    anims = _animations(f)
    return unique_names([getattr(a, "name", None) for a in anims], prefix="animation")


def gltf_takes(path: str | os.PathLike) -> list[str]:
    """The names of the animations in a glTF file (unnamed ones are ``animation0``, ``animation1``, ...)."""
    return _names(_File(Path(path)))


def _sample(times: np.ndarray, keys: np.ndarray, values: np.ndarray, interpolation: str, rotation: bool,
            path, label: str) -> np.ndarray:
    """``values`` keyed at ``keys`` (glTF sampler) at ``times``: ``(len(times), width)``."""
    n = len(keys)
    cubic = interpolation == "CUBICSPLINE"
    if cubic:
        if len(values) != 3 * n:
            raise MotionFileError(f"{label}: a CUBICSPLINE sampler needs 3 values per key ({3 * n}); it has "
                                  f"{len(values)}", path)
        tin, v, tout = values[0::3], values[1::3], values[2::3]
    else:
        if len(values) != n:
            raise MotionFileError(f"{label}: {n} key times but {len(values)} values", path)
        v = values
    k = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, n - 1)
    if interpolation == "STEP" or n == 1:
        out = v[k]
    else:
        k = np.minimum(k, n - 2)
        t0, t1 = keys[k], keys[k + 1]
        span = t1 - t0
        safe = np.where(span > 0, span, 1.0)
        s = np.clip((times - t0) / safe, 0.0, 1.0)
        s[span <= 0] = 0.0
        s = s[:, None]
        if cubic:
            s2, s3 = s * s, s * s * s
            d = span[:, None]
            out = ((2 * s3 - 3 * s2 + 1) * v[k] + (s3 - 2 * s2 + s) * d * tout[k] + (-2 * s3 + 3 * s2) * v[k + 1]
                   + (s3 - s2) * d * tin[k + 1])
        elif rotation:
            a, b = v[k], v[k + 1].copy()
            flip = np.sum(a * b, axis=1) < 0
            b[flip] = -b[flip]
            dot = np.clip(np.sum(a * b, axis=1), -1.0, 1.0)[:, None]
            theta = np.arccos(dot)
            sin = np.sin(theta)
            small = sin[:, 0] < 1e-9
            wa = np.where(small[:, None], 1 - s, np.sin((1 - s) * theta) / np.where(small[:, None], 1.0, sin))
            wb = np.where(small[:, None], s, np.sin(s * theta) / np.where(small[:, None], 1.0, sin))
            out = wa * a + wb * b
        else:
            out = v[k] + s * (v[k + 1] - v[k])
    if rotation:
        norms = np.linalg.norm(out, axis=1, keepdims=True)
        if np.any(norms < 1e-12) or not np.isfinite(norms).all():
            raise MotionFileError(f"{label}: a zero, NaN or infinite rotation", path)
        out = out / norms
    return out


def _sampler(keys: np.ndarray, values: np.ndarray, interpolation: str, rotation: bool, path, label: str):
    """``times -> values`` of one sampler (:func:`_sample`), its key and value counts checked now."""
    n = len(keys)
    if interpolation == "CUBICSPLINE" and len(values) != 3 * n:
        raise MotionFileError(f"{label}: a CUBICSPLINE sampler needs 3 values per key ({3 * n}); it has "
                              f"{len(values)}", path)
    if interpolation != "CUBICSPLINE" and len(values) != n:
        raise MotionFileError(f"{label}: {n} key times but {len(values)} values", path)

    def sample(times: np.ndarray) -> np.ndarray:
        return _sample(times, keys, values, interpolation, rotation, path, label)

    return sample


def _distinct(all_keys: list[np.ndarray]) -> list[np.ndarray]:
    """The key arrays of ``all_keys`` once each (channels that share an input accessor share its array)."""
    return list({id(k): k for k in all_keys}.values())


def _grid_step(all_keys: list[np.ndarray]) -> float | None:
    """The step (seconds) of the one regular grid, from the animation's first key, that every key time lies
    on (within 1e-3 of a step), or ``None``."""
    all_keys = _distinct(all_keys)
    steps = np.concatenate([np.diff(k) for k in all_keys if len(k) > 1] or [np.zeros(0)])
    steps = steps[steps > 0]
    if not len(steps):
        return None
    step = float(np.median(steps))
    return step if step > 0 and _on_grid(all_keys, 1.0 / step) else None


def _on_grid(all_keys: list[np.ndarray], rate: float) -> bool:
    """Whether every key time lies on the frames of ``rate`` from the animation's first key (within 1e-3 of
    a frame)."""
    joined = np.concatenate(_distinct(all_keys))
    frames = (joined - joined.min()) * rate
    return bool(np.all(np.abs(frames - np.round(frames)) <= 1e-3))


MAX_CANDIDATE_RATES = 8
"""How many of the animations' own key rates (the most common) :func:`_file_rate` weighs: a file of
thousands of animations each keyed at its own rate costs one pass per candidate, not per animation."""


def _file_rate(keys_by_animation: list[list[np.ndarray]]) -> float | None:
    """The file's frame rate: among the key rates of its animations (the :data:`MAX_CANDIDATE_RATES` most
    common), the one on whose frames the keys of the most animations lie (the lower on a tie); ``None`` when
    no animation keys each frame.  Animations that share their key arrays are weighed once, times their count."""
    shared: dict[tuple[int, ...], tuple[list[np.ndarray], int]] = {}
    for keys in keys_by_animation:
        if keys:
            keys = _distinct(keys)
            sign = tuple(sorted(id(k) for k in keys))
            shared[sign] = (keys, shared.get(sign, (keys, 0))[1] + 1)
    own: dict[float, int] = {}
    for keys, count in shared.values():
        rate = key_rate(_grid_step(keys))
        if rate:
            own[rate] = own.get(rate, 0) + count
    rates = sorted(sorted(own, key=lambda r: (-own[r], r))[:MAX_CANDIDATE_RATES])
    if not rates:
        return None
    return max(rates, key=lambda r: (sum(count for keys, count in shared.values() if _on_grid(keys, r)), -r))


def _skeleton_nodes(f: _File, parents: np.ndarray, animated: set[int]) -> list[int]:
    """The skeleton's nodes, parents first: the skin's joints (and any node between two of them)."""
    skins = f.items("skins")
    N = len(parents)
    chosen: list[int] = []
    if skins:
        best = max(range(len(skins)), key=lambda s: len(_list(getattr(skins[s], "joints", None), "skin.joints",
                                                                 f.path)))
        chosen = [_int(j, f"skins[{best}].joints", f.path, 0, N - 1)
                  for j in _list(getattr(skins[best], "joints", None), "skin.joints", f.path)]
    if not chosen:
        chosen = sorted(animated)
    if not chosen:
        raise MotionFileError("no skin and no animated node: nothing to read as a skeleton", f.path)
    nodes = f.items("nodes")
    children = [[int(c) for c in _list(getattr(n, "children", None), "children", f.path)] for n in nodes]
    return skeleton_order(parents, children, chosen, f.path)


def _is_mocycle(f: _File) -> dict | None:
    """The unit conversion of a file mocycle wrote (its scene's extras), or ``None``."""
    asset = getattr(f.gl, "asset", None)
    if getattr(asset, "generator", None) != "mocycle":
        return None
    for scene in f.items("scenes"):
        extras = getattr(scene, "extras", None)  # anyone's: any JSON at all
        ours = extras.get("mocycle") if isinstance(extras, dict) else None
        units = ours.get("units") if isinstance(ours, dict) else None
        if isinstance(units, dict):
            try:
                scale = float(units["metres_per_unit"])
                quat = np.asarray(units["source_to_gltf_rotation_xyzw"], dtype=float)
            except (KeyError, TypeError, ValueError, OverflowError):
                return None
            if np.isfinite(scale) and scale > 0 and quat.shape == (4,) and np.isfinite(quat).all() \
                    and np.linalg.norm(quat) > 0.5:
                return {"scale": scale, "rotation": quat / np.linalg.norm(quat)}
    return None


def _channels(f: _File, index: int, n_nodes: int, values: bool = True, inputs: dict | None = None) -> list:
    """The ``translation``, ``rotation`` and ``scale`` channels of animation ``index`` that target a node:
    ``(node, path, key times, values or None, interpolation, label)``; ``values=False`` reads the key times
    only (``inputs`` keeps them by accessor: samplers often share theirs)."""
    p = f.path
    anim = _animations(f)[index]
    samplers = _list(getattr(anim, "samplers", None), "animation.samplers", p)
    out = []
    for c, ch in enumerate(_list(getattr(anim, "channels", None), "animation.channels", p)):
        target = getattr(ch, "target", None)
        kind = getattr(target, "path", None)
        node = getattr(target, "node", None)
        if kind not in _PATHS or node is None:
            continue  # morph weights, pointers, no node: nothing a skeleton plays
        node = _int(node, f"channels[{c}].target.node", p, 0, n_nodes - 1)
        s = _int(getattr(ch, "sampler", None), f"channels[{c}].sampler", p, 0, max(len(samplers) - 1, 0))
        if s >= len(samplers):
            raise MotionFileError(f"channels[{c}] names sampler {s}; the animation has none", p)
        sampler = samplers[s]
        interp = getattr(sampler, "interpolation", None) or "LINEAR"
        if interp not in ("LINEAR", "STEP", "CUBICSPLINE"):
            raise MotionFileError(f"samplers[{s}]: unknown interpolation {interp!r}", p)
        source = getattr(sampler, "input", None)
        keys = None if inputs is None or not isinstance(source, int) else inputs.get(source)
        if keys is None:
            keys = f.accessor(source, f"samplers[{s}].input", (1,))[:, 0]
            if not np.isfinite(keys).all() or np.any(np.diff(keys) < 0):
                raise MotionFileError(f"samplers[{s}].input: key times must be finite and increasing", p)
            if inputs is not None and isinstance(source, int):
                inputs[source] = keys
        data = None
        if values:
            data = f.accessor(getattr(sampler, "output", None), f"samplers[{s}].output", (_PATHS[kind],))
            if not np.isfinite(data).all():
                raise MotionFileError(f"samplers[{s}].output holds NaN or infinite values", p)
        out.append((node, kind, keys, data, interp, f"animation {index} channel {c}"))
    return out


def _targets(f: _File, n_nodes: int) -> dict[int, set[str]]:
    """The nodes that a channel of any animation moves, each with the paths keyed (``translation``,
    ``rotation``, ``scale``): the JSON only, no data read."""
    out: dict[int, set[str]] = {}
    for anim in _animations(f):
        for ch in _list(getattr(anim, "channels", None), "animation.channels", f.path):
            target = getattr(ch, "target", None)
            node = getattr(target, "node", None)
            path = getattr(target, "path", None)
            if path in _PATHS and node is not None:
                out.setdefault(_int(node, "channels.target.node", f.path, 0, n_nodes - 1), set()).add(path)
    return out


def _moves(channels: list, nodes: set[int]) -> bool:
    """Whether a channel on ``nodes`` changes its value."""
    return any(node in nodes and len(data) > 1 and float(np.ptp(data, axis=0).max()) > 0
               for node, _, _, data, _, _ in channels)


def _default_take(f: _File, body: set[int], n_nodes: int, names: list[str]) -> tuple[int, list]:
    """The first animation that moves the skeleton (``body``: its nodes and the nodes above it), or the first,
    and its channels (:func:`._nodes.default_take`: a warning names it and the others)."""
    seen: dict[int, list] = {}  # the channels of the animation looked at last: the one read, unless none moves

    def moves(k: int) -> bool:
        seen.clear()
        seen[k] = _channels(f, k, n_nodes)
        return _moves(seen[k], body)

    chosen = default_take(names, moves, f.path, "animation", stacklevel=4)
    return chosen, seen[chosen] if chosen in seen else _channels(f, chosen, n_nodes)


def read_gltf(path: str | os.PathLike, *, take: str | int | None = None, fps: float | None = None) -> Motion:
    """Read a glTF file's skeleton and one of its animations as a :class:`Motion`.

    Parameters
    ----------
    path : a ``.glb`` or ``.gltf`` file.
    take : the animation's name (or 0-based index); default the first that moves the skeleton
        (:func:`gltf_takes` lists them).
    fps : the frame rate to sample at; default the file's: the key rate of its animations (the one most of
        them key every frame at), else :data:`DEFAULT_FPS`.

    Raises
    ------
    MotionFileError
        A damaged or hostile file, an unknown animation name (the message lists them), or no skeleton.
    """
    p = Path(path)
    if fps is not None and not (np.isfinite(fps) and fps > 0):
        raise MotionFileError(f"the frame rate must be positive; got {fps!r}", p)
    f = _File(p)
    parents = _parents(f)
    N = len(parents)
    keyed = _targets(f, N)  # every take's: the same skeleton and End Sites for each
    targets = set(keyed)
    translated = {i for i, paths in keyed.items() if "translation" in paths}  # and the same position channels
    members = _skeleton_nodes(f, parents, targets)
    names = _names(f) if _animations(f) else []
    body = set(members)  # the skeleton's nodes and the nodes above it
    i = int(parents[members[0]])
    while i >= 0:
        body.add(i)
        i = int(parents[i])
    if take is None and names:
        index: int | None
        index, channels = _default_take(f, body, N, names)
    else:
        index = choose_take(names, take, p, "animation", "animation")
        channels = _channels(f, index, N) if index is not None else []
    channels = [c for c in channels if c[0] in body]  # a mesh's or a camera's keys do not make the take longer
    if channels:
        keys = [c[2] for c in channels]
        rate = fps
        if rate is None:
            inputs: dict = {}
            rate = _file_rate([[c[2] for c in _channels(f, k, N, values=False, inputs=inputs)]
                               for k in range(len(names))]) or DEFAULT_FPS
            if not _on_grid(keys, rate):
                assert index is not None  # keys come from a take's channels
                warnings.warn(f"{p}: the keys of take {names[index]!r} lie on no regular grid of the file's "
                              f"{rate:g} fps frames; sampled at {rate:g} fps", MocycleWarning, stacklevel=2)
        times = frame_times(min(float(k[0]) for k in keys), max(float(k[-1]) for k in keys), rate, len(members), p)
    else:
        rate, times = fps or DEFAULT_FPS, np.zeros(1)
    T = len(times)

    node_names = joint_names([getattr(f.items("nodes")[i], "name", None) for i in range(N)], members)
    trs: dict[int, NodeTRS] = {}

    def node_trs(i: int) -> NodeTRS:
        if i not in trs:
            t, q, s = _rest_trs(f, i)
            trs[i] = NodeTRS(
                node_names[i], t[None], q[None], s[None], animated=i in targets, translated=i in translated
            )
        return trs[i]

    used = set(members) | _above(members[0], parents)
    for node, kind, keys, values, interp, label in channels:
        if node not in used:
            continue
        n = node_trs(node)
        # sampled a block of frames at a time when the motion is made (never the whole take per channel)
        setattr(n, kind, Sampled(times, _PATHS[kind], _sampler(keys, values, interp, kind == "rotation", p, label)))
    ancestors, joints, jparents = member_nodes(members, parents, node_trs)
    units = _is_mocycle(f)
    up, metres = (0.0, 1.0, 0.0), 1.0  # glTF: metres, +Y up (the specification)
    if units is not None:  # undo mocycle's writer: back to the motion's own units and axes
        back = Rotation.from_quat(units["rotation"]).inv()
        ancestors.insert(0, NodeTRS("mocycle units", np.zeros((1, 3)), back.as_quat()[None],
                                    np.full((1, 3), 1.0 / units["scale"])))
        up, metres = tuple(back.apply([0.0, 1.0, 0.0])), units["scale"]
    motion = motion_from_nodes(ancestors, joints, jparents, T, 1.0 / rate, p, up=up, metres_per_unit=metres)
    if index is not None:
        name = names[index]
        motion.cache("take", lambda _: name)  # the take read (mocycle info says which)
    return motion


def _above(node: int, parents: np.ndarray) -> set[int]:
    """The nodes above ``node`` (its parent, its parent's parent, ...)."""
    out = set()
    i = int(parents[node])
    while i >= 0:
        out.add(i)
        i = int(parents[i])
    return out
