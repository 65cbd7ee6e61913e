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
    """The figure to draw: point names and parents (joints, then End Sites), the vertical, floor and height,
    and the joints not drawn (``hidden``: :func:`detached_joints`)."""
    from ..contacts import body_height, floor_height, up_axis

    skel = motion.skeleton
    up = up_axis(motion)
    names = list(skel.names) + [s.name or f"{skel.names[s.parent]} end" for s in skel.end_sites]
    parents = [int(p) for p in skel.parents] + [int(s.parent) for s in skel.end_sites]
    return {"frames": motion.n_frames, "fps": motion.fps, "names": names, "parents": parents,
            "joints": skel.n_joints, "travel": motion.travel_joint, "up": [float(v) for v in up],
            "floor": floor_height(motion), "height": body_height(motion, up), "hidden": detached_joints(motion)}


#: a joint "never moves" when its world position spans at most this share of the body's longest bone
STILL_SHARE = 1e-4


def detached_joints(motion) -> list[int]:
    """The joints the viewer does not draw (nor their bones): a joint above the body (an ancestor of the travel
    joint) that never moves and comes farther from the body (the travel joint) than the body's longest bone is
    long, at some frame of the take.  Such a joint is a fixed point of the room, not a part of the body: the
    Bandai Namco files' ``joint_Root`` stays at the room's origin while ``Hips`` carries the walk, and drawn as a
    bone it is a stick from the origin to the hips that stretches across the room.  Decided from the motion
    (no joint name is looked at), once for the whole take, so that no bone comes and goes while it plays.

    The body's bones: the frame-0 offsets of the joints and End Sites hanging from the travel joint."""
    from ..motion import chain_kinematics_blocks

    skel = motion.skeleton
    travel = motion.travel_joint
    chain = skel.chain_to(travel)
    above = chain[:-1]
    if not above:
        return []
    body = {travel}
    for j in range(travel + 1, skel.n_joints):  # parents come first
        if int(skel.parents[j]) in body:
            body.add(j)
    rest = motion.translations_at(0)
    bones = [float(np.linalg.norm(rest[j])) for j in body if j != travel]
    bones += [float(np.linalg.norm(s.offset)) for s in skel.end_sites if s.parent in body]
    longest = max(bones, default=0.0)
    if not longest > 0:  # a body without bones (one joint): nothing to compare with
        return []
    low = np.full((len(above), 3), np.inf)
    high = np.full((len(above), 3), -np.inf)
    far = np.zeros(len(above))
    for _, _, W in chain_kinematics_blocks(motion, chain, 8192):
        low = np.minimum(low, W[:, :-1].min(axis=0))
        high = np.maximum(high, W[:, :-1].max(axis=0))
        far = np.maximum(far, np.linalg.norm(W[:, :-1] - W[:, -1:], axis=2).max(axis=0))
    still = (high - low).max(axis=1) <= STILL_SHARE * longest
    return [int(j) for j, s, d in zip(above, still, far, strict=True) if s and d > longest]


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
