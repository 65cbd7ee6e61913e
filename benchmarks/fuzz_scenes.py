"""Structure-aware mutations of glTF and FBX files, for ``benchmarks/fuzz.py`` (readers ``gltf`` and ``fbxs``).

Byte mutations rarely get past a glTF's JSON or an FBX's record offsets; these edit the file's structure and
write it again, so that what the reader meets is a well-formed file that lies:

* glTF (``.gltf`` text or ``.glb``): a field's value replaced by another JSON type or an absurd number (also
  ``1e400``, NaN), a field removed, accessor counts and buffer lengths beyond the buffer, buffer ``uri``\\ s
  naming files outside the folder, devices, a FIFO, a link out, data URIs; odd node and animation names (lone
  surrogates, braces, line breaks, 10,000 characters, the same name many times); long chains of nodes, cycles
  and second parents; key times far apart (a span claiming millions of frames), NaN and infinite keys;
  interpolations, paths and types of every kind; extras of any shape on a file that says mocycle wrote it.
* FBX (binary, read back into records by :func:`mocycle.datasets.fbx_files.read_records`): property types
  swapped, array headers (``arrayLength``, ``encoding``, ``compressedLength``) set to absurd values, deflate
  bombs of 10^5 to 3·10^8 values added, bone names of every kind, records removed or repeated, connections to
  nothing, to themselves and in cycles, long chains of bones, the 7.5 format's 64-bit offsets.

A glTF is read in a folder (:func:`sandbox`) holding its buffer ``good.bin``, a FIFO ``pipe.bin``, a link
``link.bin`` to a secret beside the folder and a sub-folder; :func:`reads_guarded` makes any open of the secret,
of ``/etc``, ``/dev`` or ``/proc`` an error (``ReadOutside``), which the fuzzer counts as a crash.
"""

from __future__ import annotations

import builtins
import contextlib
import copy
import json
import os
import random
import struct
from pathlib import Path

from mocycle.datasets.fbx_files import Node, ObjectName, Raw, Zeros, fbx_bytes, read_records

__all__ = ["ReadOutside", "mutate_fbx", "mutate_gltf", "reads_guarded", "sandbox"]

BIG = "__1e400__"  # written as the JSON number 1e400 (beyond float)
VALUES = [None, True, False, 0, -1, 1, 2, 3, 4, 5126, 2**31 - 1, 2**32, 2**63, 10**30, -(2**31), 1.5, -0.0, 1e308,
          float("nan"), float("inf"), BIG, "", "x", "SCALAR", "VEC4", "MAT4", "rotation", "weights", "CUBICSPLINE",
          "\ud800", "{", "a\nb", [], [0], [1, 2, 3], [[]], list(range(100)), {}, {"a": 1}, {"mocycle": 1}]
URIS = ["../secret.bin", "/etc/hostname", "/dev/zero", "/dev/urandom", "/proc/self/environ", "pipe.bin", "link.bin",
        "good.bin", "%2e%2e/secret.bin", "file:///etc/hostname", "file:good.bin", "data:application/octet-stream;"
        "base64,AAAA", "data:x", "data:;base64,!!!!", "sub/../../secret.bin", "good.bin?x", "C:\\x", "folder", "",
        ".", "./good.bin", "good%00.bin", "folder/../good.bin", "\\\\server\\x", "http://example.com/x.bin"]
NAMES = ["\ud800", "\udcff", "{", "}", "a{b}", "a b", "tab\there", "line\nbreak", "", " ", "x" * 10_000, "Hips",
         "End Site", "ROOT", "mixamorig:Hips", "\x1b[31mred", "\u202e", "../x", "<script>"]


class ReadOutside(Exception):
    """A reader opened a file outside the glTF's folder (or a device, /etc, /proc)."""


# ---------------------------------------------------------------- glTF
def split_gltf(data: bytes) -> tuple[dict, bytes, bool]:
    """``(JSON, binary chunk, is GLB)`` of a glTF file (ValueError when it is neither)."""
    if data[:4] == b"glTF":
        n = struct.unpack_from("<I", data, 12)[0]
        doc = json.loads(data[20:20 + n])
        blob = b""
        if len(data) > 28 + n:
            m = struct.unpack_from("<I", data, 20 + n)[0]
            blob = data[28 + n:28 + n + m]
        return doc, blob, True
    return json.loads(data), b"", False


def join_gltf(doc, blob: bytes, binary: bool) -> bytes:
    text = json.dumps(doc).replace(f'"{BIG}"', "1e400").encode("utf-8", "surrogatepass")
    if not binary:
        return text
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text
    if blob:
        blob += b"\0" * (-len(blob) % 4)
        body += struct.pack("<I4s", len(blob), b"BIN\0") + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def _spots(doc, rng: random.Random, limit: int = 400) -> list[tuple[object, object]]:
    """Up to ``limit`` (container, key) places in the JSON tree, found breadth first and sampled."""
    out, todo = [], [doc]
    while todo and len(out) < 20 * limit:
        value = todo.pop(rng.randrange(len(todo)))
        items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
        for key, child in items:
            out.append((value, key))
            if isinstance(child, (dict, list)):
                todo.append(child)
    rng.shuffle(out)
    return out[:limit]


def _list(doc: dict, key: str) -> list:
    value = doc.get(key)
    if not isinstance(value, list):
        value = doc[key] = []
    return value


def _items(value) -> list[dict]:
    """The objects of a JSON list (none when ``value`` is not a list)."""
    return [x for x in value if isinstance(x, dict)] if isinstance(value, list) else []


def _edit_gltf(doc: dict, blob: bytearray, rng: random.Random) -> None:
    op = rng.choice(("value", "value", "delete", "count", "uri", "name", "nodes", "cycle", "times", "anims",
                     "type", "interp", "path", "extras", "length"))
    if op in ("value", "delete"):
        spots = _spots(doc, rng)
        if spots:
            container, key = spots[0]
            if op == "value":
                container[key] = copy.deepcopy(rng.choice(VALUES))  # a fresh [] or {}: no list inside itself
            elif isinstance(container, dict):
                del container[key]
            else:
                container.pop(key)
        return
    dicts = lambda key: [x for x in _list(doc, key) if isinstance(x, dict)]  # noqa: E731
    if op == "count" and dicts("accessors"):
        rng.choice(dicts("accessors"))["count"] = rng.choice([0, 1, 2, 3, 31, 10**6, 2**31 - 1, 2**32, -1])
    elif op == "length" and dicts("bufferViews"):
        view = rng.choice(dicts("bufferViews"))
        view[rng.choice(["byteLength", "byteOffset", "byteStride"])] = rng.choice([0, 1, 4, 252, 10**9, -4, 2**40])
    elif op == "uri":
        buffers = dicts("buffers") or [{}]
        buf = rng.choice(buffers)
        buf["uri"] = rng.choice(URIS)
        if rng.random() < 0.5:
            buf["byteLength"] = rng.choice([0, 1, 64, len(blob), 10**9, 2**31])
        if not doc.get("buffers"):
            doc["buffers"] = buffers
    elif op == "name":
        pool = dicts("nodes") + dicts("animations")
        if pool:
            for item in rng.sample(pool, min(len(pool), rng.randint(1, 5))):
                item["name"] = rng.choice(NAMES)
    elif op == "nodes":
        nodes = _list(doc, "nodes")
        k, first = rng.choice([100, 1000, 3000]), len(nodes)
        same = rng.random() < 0.5
        nodes += [{"name": "joint" if same else f"n{first + i}", "translation": [0, 0.1, 0],
                   **({"children": [first + i + 1]} if i + 1 < k else {})} for i in range(k)]
        if nodes[:first] and isinstance(nodes[0], dict):
            nodes[0].setdefault("children", [])
            if isinstance(nodes[0]["children"], list):
                nodes[0]["children"].append(first)
        if rng.random() < 0.5 and dicts("skins"):
            joints = dicts("skins")[0].setdefault("joints", [])
            if isinstance(joints, list):
                joints += list(range(first, first + k))
    elif op == "cycle":
        nodes = dicts("nodes")
        if nodes:
            a, b = rng.randrange(len(nodes)), rng.randrange(len(nodes))
            nodes[a].setdefault("children", [])
            if isinstance(nodes[a]["children"], list):
                nodes[a]["children"].append(b)
    elif op == "times" and len(blob) >= 8:
        at = rng.randrange(0, len(blob) - 3, 4)
        value = rng.choice([0.0, 1e6, 1e9, -1.0, float("nan"), float("inf"), 3.4e38, 66666.0, 1e-9])
        blob[at:at + 4] = struct.pack("<f", value)
    elif op == "anims":
        anims = _list(doc, "animations")
        if anims:
            name = rng.choice(["walk", "", None, "\ud800"])
            anims += [{**anims[0], "name": name} for _ in range(rng.choice([10, 1000, 5000]))]
    elif op == "type" and dicts("accessors"):
        rng.choice(dicts("accessors"))["type"] = rng.choice(["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT4", "x",
                                                             [], 3])
    elif op == "interp":
        samplers = [s for a in dicts("animations") for s in _items(a.get("samplers"))]
        if samplers:
            rng.choice(samplers)["interpolation"] = rng.choice(["LINEAR", "STEP", "CUBICSPLINE", "SPLINE", 1, None])
    elif op == "path":
        channels = [c for a in dicts("animations") for c in _items(a.get("channels"))]
        if channels:
            target = rng.choice(channels).setdefault("target", {})
            if isinstance(target, dict):
                target["path"] = rng.choice(["translation", "rotation", "scale", "weights", "pointer", [], 1, None])
                if rng.random() < 0.3:
                    target["node"] = rng.choice([0, 1, 2, -1, 10**9, "0", None])
    elif op == "extras":
        doc.setdefault("asset", {})
        if isinstance(doc["asset"], dict):
            doc["asset"]["generator"] = "mocycle"
        scenes = dicts("scenes") or [{}]
        scenes[0]["extras"] = rng.choice([1, "x", [1], {"mocycle": 1}, {"mocycle": {"units": [1]}},
                                          {"mocycle": {"units": {"metres_per_unit": BIG,
                                                                 "source_to_gltf_rotation_xyzw": [0, 0, 0, 1]}}},
                                          {"mocycle": {"units": {"metres_per_unit": 0.01,
                                                                 "source_to_gltf_rotation_xyzw": [[1], [2]]}}}])
        doc["scenes"] = scenes


def mutate_gltf(data: bytes, rng: random.Random) -> bytes:
    """1-4 structural edits of the glTF ``data`` (``.gltf`` or ``.glb``); ``data`` itself when it does not parse."""
    try:
        doc, blob, binary = split_gltf(data)
    except (ValueError, UnicodeDecodeError, struct.error, RecursionError):
        return data
    if not isinstance(doc, dict):
        return data
    blob = bytearray(blob)
    for _ in range(rng.randint(1, 4)):
        try:
            _edit_gltf(doc, blob, rng)
        except (TypeError, AttributeError, KeyError, IndexError, ValueError):  # an edit that does not fit this tree
            continue
    if rng.random() < 0.1:
        binary = not binary
    return join_gltf(doc, bytes(blob), binary)


def sandbox(scratch: Path, blob: bytes) -> Path:
    """``scratch/take`` (made): ``good.bin`` (``blob``), a FIFO ``pipe.bin``, ``link.bin`` linking to
    ``scratch/secret.bin`` and a folder ``folder``; returns the folder."""
    take = scratch / "take"
    take.mkdir(parents=True, exist_ok=True)
    (scratch / "secret.bin").write_bytes(b"SECRET" * 1000)
    (take / "good.bin").write_bytes(blob)
    makers = (("pipe.bin", os.mkfifo), ("link.bin", lambda p: os.symlink(scratch / "secret.bin", p)),
              ("folder", Path.mkdir))
    for name, make in makers:
        if not os.path.lexists(take / name):
            make(take / name)
    return take


@contextlib.contextmanager
def reads_guarded(scratch: Path):
    """Any ``os.open``/``open`` of ``scratch/secret.bin`` or of a path under ``/etc``, ``/dev`` or ``/proc``
    raises :class:`ReadOutside` while the block runs."""
    secret = os.path.realpath(scratch / "secret.bin")
    real_open, real_builtin = os.open, builtins.open

    def check(path):
        if isinstance(path, int):
            return
        where = os.path.realpath(os.fsdecode(path))
        if where == secret or where.startswith(("/etc/", "/dev/", "/proc/")):
            raise ReadOutside(f"opened {where}")

    def os_open(path, *args, **kwargs):
        check(path)
        return real_open(path, *args, **kwargs)

    def builtin_open(path, *args, **kwargs):
        check(path)
        return real_builtin(path, *args, **kwargs)

    os.open, builtins.open = os_open, builtin_open
    try:
        yield
    finally:
        os.open, builtins.open = real_open, real_builtin


# ---------------------------------------------------------------- FBX
def _all_nodes(records: list[Node]) -> list[tuple[list[Node], int]]:
    out, todo = [], [records]
    while todo:
        siblings = todo.pop()
        for i, node in enumerate(siblings):
            out.append((siblings, i))
            todo.append(node.children)
    return out


def _name_raw(name: str, cls: str) -> Raw:
    try:
        text = name.encode("utf-8", "surrogateescape")  # a byte that is not UTF-8 as that byte
    except UnicodeEncodeError:
        text = name.encode("utf-8", "surrogatepass")  # any other lone surrogate as its (invalid) UTF-8
    raw = text + b"\x00\x01" + cls.encode()
    return Raw(b"S", struct.pack("<I", len(raw)) + raw)


def _objects(records: list[Node]) -> Node:
    for node in records:
        if node.name == "Objects":
            return node
    node = Node("Objects", (), [])
    records.append(node)
    return node


def _connections(records: list[Node]) -> Node:
    for node in records:
        if node.name == "Connections":
            return node
    node = Node("Connections", (), [])
    records.append(node)
    return node


def _edit_fbx(records: list[Node], rng: random.Random) -> None:
    op = rng.choice(("name", "array", "array", "bomb", "type", "delete", "repeat", "connect", "bones"))
    spots = _all_nodes(records)
    if not spots:
        return
    siblings, i = rng.choice(spots)
    node = siblings[i]
    if op == "name":
        models = [n for s, k in spots for n in (s[k],) if n.name in ("Model", "NodeAttribute") and len(n.props) > 1]
        for n in rng.sample(models, min(len(models), rng.randint(1, 4))):
            props = list(n.props)
            props[1] = _name_raw(rng.choice(NAMES), "Model")
            n.props = tuple(props)
    elif op == "array":
        arrays = [(n, k) for s, j in spots for n in (s[j],) for k, p in enumerate(n.props)
                  if isinstance(p, Raw) and p.code in (b"f", b"d", b"l", b"i", b"b")]
        if arrays:
            n, k = rng.choice(arrays)
            count, encoding, stored = struct.unpack_from("<III", n.props[k].payload)
            which = rng.randrange(3)
            value = rng.choice([0, 1, 2, 3, 2**31 - 1, 2**32 - 1, 300_000_000, 10**6])
            head = [count, encoding, stored]
            head[which] = value if which != 1 else rng.choice([0, 1, 2, 255])
            props = list(n.props)
            props[k] = Raw(n.props[k].code, struct.pack("<III", *head) + n.props[k].payload[12:])
            n.props = tuple(props)
    elif op == "bomb":
        count = rng.choice([10**5, 10**7, 3 * 10**7, 10**8, 3 * 10**8])
        _objects(records).children.append(Node("Geometry", (rng.randrange(10**6), ObjectName("Geometry", "g"),
                                                            "Mesh"), [Node("Vertices", (Zeros(count),))]))
    elif op == "type" and node.props:
        props = list(node.props)
        k = rng.randrange(len(props))
        props[k] = rng.choice([Raw(b"L", struct.pack("<q", rng.choice([-1, 0, 2**62]))),
                               Raw(b"D", struct.pack("<d", rng.choice([float("nan"), 1e308, -0.0]))),
                               Raw(b"S", struct.pack("<I", 3) + b"abc"), Raw(b"C", b"\x01"),
                               Raw(b"i", struct.pack("<III", 2, 0, 8) + b"\0" * 8)])
        node.props = tuple(props)
    elif op == "delete":
        del siblings[i]
    elif op == "repeat":
        siblings[i:i] = [node] * rng.choice([1, 2, 50])
    elif op == "connect":
        ids = [struct.unpack("<q", n.props[0].payload)[0] for s, k in spots for n in (s[k],)
               if n.name == "Model" and n.props and isinstance(n.props[0], Raw) and n.props[0].code == b"L"]
        a = rng.choice(ids) if ids else 1
        b = rng.choice(ids + [0, -1, 123456789]) if ids else 2
        links = [("OO", a, b)] + ([("OO", b, a)] if rng.random() < 0.5 else [])
        _connections(records).children += [Node("C", link) for link in links]
    elif op == "bones":
        k = rng.choice([10, 300, 2000])
        base = 2_000_000 + rng.randrange(10**6)
        name = rng.choice([None, "joint", "\udcff"])
        objects, connections = _objects(records), _connections(records)
        for j in range(k):
            objects.children += [
                Node("Model", (base + 2 * j, ObjectName("Model", name or f"b{j}"), "LimbNode"), [
                    Node("Properties70", (), [Node("P", ("Lcl Translation", "Lcl Translation", "", "A", 0.0, 1.0,
                                                          0.0))])]),
                Node("NodeAttribute", (base + 2 * j + 1, ObjectName("NodeAttribute", "b"), "LimbNode"))]
            connections.children += [Node("C", ("OO", base + 2 * j, base + 2 * j - 2 if j else 0)),
                                     Node("C", ("OO", base + 2 * j + 1, base + 2 * j))]


def mutate_fbx(data: bytes, rng: random.Random) -> bytes:
    """1-3 structural edits of the binary FBX ``data`` (its records read back, edited, written again, at times in
    the other format version); ``data`` itself when its records do not read."""
    try:
        version, records = read_records(data)
    except (ValueError, struct.error, RecursionError, IndexError):
        return data
    for _ in range(rng.randint(1, 3)):
        try:
            _edit_fbx(records, rng)
        except (TypeError, AttributeError, KeyError, IndexError, ValueError, struct.error):
            continue
    if rng.random() < 0.2:
        version = 7500 if version < 7500 else 7400
    try:
        return fbx_bytes(records, version=version)
    except (struct.error, OverflowError, ValueError):
        return data
