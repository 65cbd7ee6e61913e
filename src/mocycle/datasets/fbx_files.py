"""Small FBX files written from plain data, binary or ASCII (FBX 7.4): for the tests, the fuzzer's seeds and the
hostile-input benchmark.

:func:`chain_scene` is a chain of bones under an armature with one animation stack (the first bone turning
about X); :func:`fbx_bytes` writes any tree of :class:`Node` records.  An array property may be a
:class:`Zeros`, an array of zeros compressed piece by piece: a deflate bomb of ``count`` values in a file of
about ``count * itemsize / 1000`` bytes, made without holding the array.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Node", "ObjectName", "Raw", "Zeros", "bomb_scene", "chain_scene", "fbx_bytes", "read_records", "write_fbx",
           "zeros_stream"]

#: FBX time ticks per second
SECOND = 46186158000
_HEADER = b"Kaydara FBX Binary  \x00\x1a\x00"
_ARRAYS = {np.dtype("<f8"): b"d", np.dtype("<f4"): b"f", np.dtype("<i8"): b"l", np.dtype("<i4"): b"i",
           np.dtype("bool"): b"b"}


@dataclass
class Node:
    """One FBX record: its name, its properties (int, float, str, bytes, :class:`ObjectName`, numpy arrays,
    :class:`Zeros`) and its children."""

    name: str
    props: tuple = ()
    children: list[Node] = field(default_factory=list)


@dataclass(frozen=True)
class ObjectName:
    """An object's name and class: ``"Model::Hips"`` in ASCII, ``"Hips\\x00\\x01Model"`` in binary."""

    cls: str
    name: str


@dataclass(frozen=True)
class Raw:
    """A property as a binary file holds it: its type code and its bytes (an array's header and stored data as
    they are, never decompressed); what :func:`read_records` gives, for mutating a file's structure."""

    code: bytes
    payload: bytes


@dataclass(frozen=True)
class Zeros:
    """``count`` zeros of ``dtype``, written compressed (never held whole)."""

    count: int
    dtype: str = "<f8"


def zeros_stream(n_bytes: int) -> bytes:
    """A zlib stream of ``n_bytes`` zero bytes, made in a fraction of a second whatever ``n_bytes``: one
    compressed block of 16 MiB of zeros (a full flush makes it stand alone) repeated, the rest, and the
    Adler-32 of ``n_bytes`` zeros (``(n mod 65521) << 16 | 1``)."""
    piece = 1 << 24
    z = zlib.compressobj(9, zlib.DEFLATED, -15)
    block = z.compress(bytes(piece)) + z.flush(zlib.Z_FULL_FLUSH)
    z = zlib.compressobj(9, zlib.DEFLATED, -15)
    tail = z.compress(bytes(n_bytes % piece)) + z.flush()
    return b"\x78\xda" + block * (n_bytes // piece) + tail + struct.pack(">I", ((n_bytes % 65521) << 16) | 1)


def _binary_array(value) -> bytes:
    if isinstance(value, Zeros):
        dtype = np.dtype(value.dtype)
        data = zeros_stream(value.count * dtype.itemsize)
        return _ARRAYS[dtype] + struct.pack("<III", value.count, 1, len(data)) + data
    a = np.ascontiguousarray(value)
    a = a.astype(a.dtype.newbyteorder("<")) if a.dtype.kind in "fi" else a
    raw = a.tobytes()
    if len(raw) > 128:
        data = zlib.compress(raw, 6)
        return _ARRAYS[a.dtype] + struct.pack("<III", len(a), 1, len(data)) + data
    return _ARRAYS[a.dtype] + struct.pack("<III", len(a), 0, len(raw)) + raw


def _encoded(text: str) -> bytes:
    """UTF-8, a byte that was not UTF-8 (U+DC80..U+DCFF) as that byte, another lone surrogate as its own bytes."""
    try:
        return text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:
        return text.encode("utf-8", "surrogatepass")


def _binary_prop(value) -> bytes:
    if isinstance(value, Raw):
        return value.code + value.payload
    if isinstance(value, (np.ndarray, Zeros)):
        return _binary_array(value)
    if isinstance(value, bool):
        return b"C" + bytes([value])
    if isinstance(value, int):
        return b"L" + struct.pack("<q", value)
    if isinstance(value, float):
        return b"D" + struct.pack("<d", value)
    if isinstance(value, ObjectName):
        value = _encoded(value.name) + b"\x00\x01" + value.cls.encode()
    if isinstance(value, str):
        value = _encoded(value)
        return b"S" + struct.pack("<I", len(value)) + value
    if isinstance(value, bytes):
        return b"R" + struct.pack("<I", len(value)) + value
    raise TypeError(f"no FBX property type for {type(value).__name__}")


def _binary_node(node: Node, at: int, wide: bool) -> bytes:
    """The record of ``node`` starting at file offset ``at`` (32-bit offsets before FBX 7.5, 64-bit from it)."""
    name = node.name.encode()
    props = b"".join(_binary_prop(p) for p in node.props)
    fields = "<QQQB" if wide else "<IIIB"
    head = struct.calcsize(fields) + len(name)
    body = bytearray()
    for child in node.children:
        body += _binary_node(child, at + head + len(props) + len(body), wide)
    if node.children:
        body += bytes(struct.calcsize(fields))
    end = at + head + len(props) + len(body)
    return struct.pack(fields, end, len(node.props), len(props), len(name)) + name + props + bytes(body)


def _ascii_prop(value) -> str:
    if isinstance(value, bool):
        return "T" if value else "F"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, ObjectName):
        return f'"{value.cls}::{value.name}"'
    if isinstance(value, str):
        return '"' + value.replace('"', "&quot;") + '"'
    raise TypeError(f"no ASCII FBX form for {type(value).__name__}")


def _ascii_node(node: Node, depth: int, out: list[str]) -> None:
    tab = "\t" * depth
    arrays = [p for p in node.props if isinstance(p, (np.ndarray, Zeros))]
    if arrays:
        a = arrays[0]
        values = np.zeros(a.count, a.dtype) if isinstance(a, Zeros) else np.asarray(a)
        text = ",".join(str(int(v)) if values.dtype.kind in "ib" else repr(float(v)) for v in values)
        out.append(f"{tab}{node.name}: *{len(values)} {{\n{tab}\ta: {text}\n{tab}}}\n")
        return
    line = f"{tab}{node.name}: {', '.join(_ascii_prop(p) for p in node.props)}"
    if node.children:
        out.append(line + " {\n")
        for child in node.children:
            _ascii_node(child, depth + 1, out)
        out.append(f"{tab}}}\n")
    else:
        out.append(line + "\n")


def fbx_bytes(nodes: list[Node], binary: bool = True, version: int = 7400) -> bytes:
    """The FBX file of the top-level records ``nodes`` (binary FBX ``version``, or ASCII)."""
    if not binary:
        out = ["; FBX 7.4.0 project file\n"]
        for node in nodes:
            _ascii_node(node, 0, out)
        return _encoded("".join(out))
    wide = version >= 7500
    data = bytearray(_HEADER + struct.pack("<I", version))
    for node in nodes:
        data += _binary_node(node, len(data), wide)
    data += bytes(25 if wide else 13)  # the end of the top-level records
    return bytes(data)


def _p(name: str, kind: str, *values) -> Node:
    return Node("P", (name, kind, "", "A", *values))


def chain_scene(n_bones: int = 3, frames: int = 31, fps: int = 30, names: list[str] | None = None,
                extra: Sequence[Node] = ()) -> list[Node]:
    """An armature (a null) holding a chain of ``n_bones`` bones, each 10 units above its parent along Y, and one
    animation stack ``walk`` of ``frames`` frames at ``fps`` in which the first bone turns 0 -> 90 degrees about X
    (linear keys).  ``names``: the bones' names (default ``bone0``, ``bone1``, ...); ``extra``: more records put
    in ``Objects`` (a mesh with a bomb in it)."""
    names = names or [f"bone{i}" for i in range(n_bones)]
    objects = [Node("Model", (1, ObjectName("Model", "Armature"), "Null"), [Node("Version", (232,))])]
    connections = [Node("C", ("OO", 1, 0))]
    for i, name in enumerate(names):
        model, attr = 10 + 2 * i, 11 + 2 * i
        objects.append(Node("Model", (model, ObjectName("Model", name), "LimbNode"), [
            Node("Version", (232,)),
            Node("Properties70", (), [_p("Lcl Translation", "Lcl Translation", 0.0, 10.0 if i else 0.0, 0.0)])]))
        objects.append(Node("NodeAttribute", (attr, ObjectName("NodeAttribute", name), "LimbNode"),
                            [Node("TypeFlags", ("Skeleton",))]))
        connections += [Node("C", ("OO", model, 10 + 2 * (i - 1) if i else 1)), Node("C", ("OO", attr, model))]
    step = SECOND // fps
    times = np.arange(frames, dtype="<i8") * step
    values = np.linspace(0.0, 90.0, frames).astype("<f4")
    stack, layer, curve_node, curve = 900_001, 900_002, 900_003, 900_004
    objects += [
        Node("AnimationStack", (stack, ObjectName("AnimStack", "walk"), ""), [Node("Properties70", (), [
            Node("P", ("LocalStart", "KTime", "Time", "", 0)),
            Node("P", ("LocalStop", "KTime", "Time", "", int(times[-1])))])]),
        Node("AnimationLayer", (layer, ObjectName("AnimLayer", "BaseLayer"), "")),
        Node("AnimationCurveNode", (curve_node, ObjectName("AnimCurveNode", "R"), ""), [Node("Properties70", (), [
            Node("P", ("d|X", "Number", "", "A", 0.0)), Node("P", ("d|Y", "Number", "", "A", 0.0)),
            Node("P", ("d|Z", "Number", "", "A", 0.0))])]),
        Node("AnimationCurve", (curve, ObjectName("AnimCurve", ""), ""), [
            Node("Default", (0.0,)), Node("KeyVer", (4009,)), Node("KeyTime", (times,)),
            Node("KeyValueFloat", (values,)), Node("KeyAttrFlags", (np.array([260], "<i4"),)),
            Node("KeyAttrDataFloat", (np.zeros(4, "<f4"),)), Node("KeyAttrRefCount", (np.array([frames], "<i4"),))]),
        *extra]
    connections += [Node("C", ("OO", layer, stack)), Node("C", ("OO", curve_node, layer)),
                    Node("C", ("OP", curve_node, 10, "Lcl Rotation")), Node("C", ("OP", curve, curve_node, "d|X"))]
    header = Node("FBXHeaderExtension", (), [Node("FBXHeaderVersion", (1003,)), Node("FBXVersion", (7400,))])
    settings = Node("GlobalSettings", (), [Node("Version", (1000,)), Node("Properties70", (), [
        Node("P", ("UpAxis", "int", "Integer", "", 1)), Node("P", ("UnitScaleFactor", "double", "Number", "", 1.0)),
        Node("P", ("TimeMode", "enum", "", "", 6))])])
    return [header, settings, Node("Objects", (), objects), Node("Connections", (), connections)]


_SIZES = {b"Y": 2, b"C": 1, b"B": 1, b"I": 4, b"F": 4, b"D": 8, b"L": 8}


def read_records(data: bytes) -> tuple[int, list[Node]]:
    """``(version, records)`` of a binary FBX file: each property a :class:`Raw` (arrays as stored).  Raises
    ``ValueError`` for a file whose records do not fit together (a test helper: no limits on nesting beyond
    the file's size)."""
    if not data.startswith(_HEADER[:21]) or len(data) < 27:
        raise ValueError("not a binary FBX file")
    version = struct.unpack_from("<I", data, 23)[0]
    fields = struct.Struct("<QQQB" if version >= 7500 else "<IIIB")

    def records(at: int, end: int) -> tuple[list[Node], int]:
        out: list[Node] = []
        while at + fields.size <= end:
            stop, n_props, props_len, name_len = fields.unpack_from(data, at)
            if stop == 0:
                return out, at + fields.size
            if not at < stop <= end:
                raise ValueError(f"a record at byte {at} ends at {stop}")
            name = data[at + fields.size:at + fields.size + name_len].decode("latin-1")
            p = at + fields.size + name_len
            props_end = p + props_len
            props = []
            for _ in range(n_props):
                code = data[p:p + 1]
                if code in _SIZES:
                    n = _SIZES[code]
                elif code in (b"S", b"R"):
                    n = 4 + struct.unpack_from("<I", data, p + 1)[0]
                elif code in (b"f", b"d", b"l", b"i", b"b", b"c"):
                    n = 12 + struct.unpack_from("<III", data, p + 1)[2]
                else:
                    raise ValueError(f"property type {code!r} at byte {p}")
                props.append(Raw(code, data[p + 1:p + 1 + n]))
                p += 1 + n
            if p > props_end:
                raise ValueError(f"the properties of the record at byte {at} run past it")
            children, _ = records(props_end, stop) if props_end < stop else ([], stop)
            out.append(Node(name, tuple(props), children))
            at = stop
        return out, at

    top, _ = records(27, len(data))
    return version, top


def write_fbx(path, nodes: list[Node], binary: bool = True, version: int = 7400) -> Path:
    """Write :func:`fbx_bytes` of ``nodes`` to ``path``; returns it."""
    path = Path(path)
    path.write_bytes(fbx_bytes(nodes, binary, version))
    return path


def bomb_scene(n_values: int = 300_000_000, n_bones: int = 3) -> list[Node]:
    """:func:`chain_scene` with a mesh whose vertices are ``n_values`` zero doubles, compressed: 300 million
    (2.4 GB as doubles) make a file of 2.3 MB."""
    mesh = Node("Geometry", (5000, ObjectName("Geometry", "body"), "Mesh"), [
        Node("Vertices", (Zeros(n_values),)), Node("PolygonVertexIndex", (np.array([0, 1, -3], "<i4"),))])
    return chain_scene(n_bones, extra=[mesh])
