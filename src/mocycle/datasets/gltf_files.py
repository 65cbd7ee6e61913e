"""Small glTF files written from plain data (the JSON as a dict, the buffer as bytes): for the tests, the
fuzzer's seeds and the hostile-input benchmark (a 10,000-node chain, a buffer ``uri`` naming a file outside
the folder, a span of key times claiming millions of frames).

:func:`chain_document` makes the JSON and binary buffer of a chain of nodes with one or more animations
turning its root; :func:`gltf_file` writes them as ``.glb``, or as ``.gltf`` with the buffer as a data URI or
any ``uri`` (a file written beside it, or a uri left as given).
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import numpy as np

__all__ = ["chain_document", "gltf_file"]

FLOAT = 5126


def chain_document(n_nodes: int = 3, times=(0.0, 1.0), *, names=None, n_animations: int = 1, skin: bool = True,
                   animation_names=None) -> tuple[dict, bytes]:
    """``(JSON, buffer)`` of a chain of ``n_nodes`` nodes (each 0.1 above its parent along Y; all joints of one
    skin unless ``skin`` is false) and ``n_animations`` animations, each turning the root about X from 0 to 90
    degrees at the key ``times`` (seconds; LINEAR).  ``names``: the nodes' names (default ``n0``, ``n1``...);
    ``animation_names``: the animations' (default ``take0``...)."""
    names = names if names is not None else [f"n{i}" for i in range(n_nodes)]
    times = np.asarray(times, dtype="<f4")
    angles = np.linspace(0.0, np.pi / 2, len(times))
    quats = np.stack([np.sin(angles / 2), 0 * angles, 0 * angles, np.cos(angles / 2)], axis=1).astype("<f4")
    blob = times.tobytes() + quats.tobytes()
    nodes = []
    for i in range(n_nodes):
        node: dict = {"name": names[i]}
        if i:
            node["translation"] = [0.0, 0.1, 0.0]
        if i + 1 < n_nodes:
            node["children"] = [i + 1]
        nodes.append(node)
    anim_names = animation_names if animation_names is not None else [f"take{k}" for k in range(n_animations)]
    doc = {
        "asset": {"version": "2.0", "generator": "mocycle tests"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes,
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": times.nbytes},
                        {"buffer": 0, "byteOffset": times.nbytes, "byteLength": quats.nbytes}],
        "accessors": [{"bufferView": 0, "componentType": FLOAT, "count": len(times), "type": "SCALAR",
                       "min": [float(times.min())], "max": [float(times.max())]},
                      {"bufferView": 1, "componentType": FLOAT, "count": len(times), "type": "VEC4"}],
        "animations": [{"name": anim_names[k], "samplers": [{"input": 0, "output": 1, "interpolation": "LINEAR"}],
                        "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}
                       for k in range(n_animations)],
    }
    if skin:
        doc["skins"] = [{"joints": list(range(n_nodes))}]
    return doc, blob


def _padded(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % 4)


def gltf_file(path, document: dict, blob: bytes = b"", *, uri: str | None = None) -> Path:
    """Write ``document`` and its buffer ``blob`` to ``path``: a ``.glb`` holds the buffer in its binary chunk;
    a ``.gltf`` names it by ``uri`` (default: the document's own, else a base64 data URI; a plain name: ``blob``
    written to that file beside ``path`` unless the name leads elsewhere, then the uri is left as given).
    Returns ``path``."""
    path = Path(path)
    doc = json.loads(json.dumps(document))
    if path.suffix.lower() == ".glb":
        text = _padded(json.dumps(doc).encode(), b" ")
        chunks = struct.pack("<I4s", len(text), b"JSON") + text
        if blob:
            chunks += struct.pack("<I4s", len(_padded(blob, b"\0")), b"BIN\0") + _padded(blob, b"\0")
        path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)
        return path
    if doc.get("buffers") and (uri is not None or "uri" not in doc["buffers"][0]):
        if uri is None:
            doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
        else:
            doc["buffers"][0]["uri"] = uri
            if "/" not in uri and ":" not in uri and "%" not in uri:
                (path.parent / uri).write_bytes(blob)
    path.write_text(json.dumps(doc))
    return path
