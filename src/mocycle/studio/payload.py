"""What the page receives: motions and planes as one compact binary buffer (not BVH text).

Layout: ``b"MOCY"``, a little-endian ``uint32`` header length, the JSON header (UTF-8, padded with spaces
to a multiple of 4 bytes), then float32 blocks; ``header["blocks"][name] = {"offset", "shape"}`` (offset in
bytes from the start of the data).  ``static/payload.js`` reads it.
"""

from __future__ import annotations

import json
import struct

import numpy as np

MAGIC = b"MOCY"


def pack(header: dict, arrays: dict[str, np.ndarray]) -> bytes:
    """One buffer: ``header`` (JSON-ready) and the ``arrays`` as float32 blocks."""
    chunks = [np.ascontiguousarray(a, dtype="<f4").tobytes() for a in arrays.values()]
    return _head(header, {name: np.shape(a) for name, a in arrays.items()}) + b"".join(chunks)


def _head(header: dict, shapes: dict[str, tuple]) -> bytes:
    """The buffer up to its float32 blocks, which follow in the order of ``shapes`` (name -> shape)."""
    blocks, offset = {}, 0
    for name, shape in shapes.items():
        blocks[name] = {"offset": offset, "shape": [int(n) for n in shape]}
        offset += 4 * int(np.prod(shape, dtype=np.int64))
    text = json.dumps({**header, "blocks": blocks}, allow_nan=False).encode()
    text += b" " * (-len(text) % 4)
    return MAGIC + struct.pack("<I", len(text)) + text


def unpack(data: bytes) -> tuple[dict, dict[str, np.ndarray]]:
    """The inverse of :func:`pack` (tests and scripts)."""
    if data[:4] != MAGIC:
        raise ValueError("not a mocycle studio payload")
    (n,) = struct.unpack("<I", data[4:8])
    header = json.loads(data[8: 8 + n])
    base = 8 + n
    arrays = {}
    for name, b in header["blocks"].items():
        count = int(np.prod(b["shape"])) if b["shape"] else 1
        arrays[name] = np.frombuffer(data, "<f4", count, base + b["offset"]).reshape(b["shape"])
    return header, arrays


def skeleton_header(motion) -> dict:
    """The figure to draw: point names and parents (joints, then End Sites), the vertical, floor and height."""
    from ..contacts import body_height, floor_height, up_axis

    skel = motion.skeleton
    up = up_axis(motion)
    names = list(skel.names) + [s.name or f"{skel.names[s.parent]} end" for s in skel.end_sites]
    parents = [int(p) for p in skel.parents] + [int(s.parent) for s in skel.end_sites]
    return {"frames": motion.n_frames, "fps": motion.fps, "names": names, "parents": parents,
            "joints": skel.n_joints, "travel": motion.travel_joint, "up": [float(v) for v in up],
            "floor": floor_height(motion), "height": body_height(motion, up)}


def motion_payload(motion, extra: dict | None = None) -> bytes:
    """World positions of every joint and End Site per frame ``(T, J + E, 3)`` with the skeleton header."""
    return b"".join(motion_payload_pieces(motion, extra))


def motion_payload_pieces(motion, extra: dict | None = None, frames: int = 8192):
    """:func:`motion_payload` as an iterator of byte pieces, the positions ``frames`` frames at a time (a
    long take's payload is written without holding its positions or the buffer whole)."""
    header = {**skeleton_header(motion), **(extra or {})}
    T, points = motion.n_frames, motion.n_joints + len(motion.skeleton.end_sites)
    yield _head(header, {"positions": (T, points, 3)})
    for f0 in range(0, T, frames):
        yield np.ascontiguousarray(motion[f0:f0 + frames].world_positions(end_sites=True), dtype="<f4").tobytes()


def plane_payload(motion, plane: dict, facts: dict) -> bytes:
    """The authoring plane: every frame's 2-D point, the keyframes' local rotation matrices ``(K, J, 9)``,
    the take's first-frame translations ``(J, 3)`` and the End Site offsets ``(E, 3)`` (the page
    back-projects and poses the skeleton itself)."""
    from scipy.spatial.transform import Rotation

    key = np.asarray(plane["keyframes"], dtype=np.int64)
    points = plane["optimized"] if plane.get("optimized") is not None else plane["points"]
    K, J = len(key), motion.n_joints
    rot = Rotation.from_quat(motion.rotations[key].reshape(-1, 4)).as_matrix().reshape(K, J, 9)
    sites = np.array([s.offset for s in motion.skeleton.end_sites], dtype=np.float64).reshape(-1, 3)
    header = {**skeleton_header(motion), "keyframes": key.tolist(), "projection": facts.get("projection"),
              "select": facts.get("select"), "stress": facts.get("stress_optimized", facts.get("stress")),
              "optimized": plane.get("optimized") is not None}
    return pack(header, {"points": points, "key_rotations": rot, "rest": motion.translations_at(0),
                         "sites": sites})
