"""The file suffixes mocycle reads and writes: one list per idea, for the library and every front end.
Standard library only (the CLI's ``--help``, batch's discovery and the studio import it without numpy)."""

from __future__ import annotations

#: the files a motion (a take) is read from; batch takes these from a folder
MOTION_READ_SUFFIXES = (".bvh", ".amc", ".fbx", ".glb", ".gltf")
#: the motion files that may hold several takes (glTF animations, FBX animation stacks)
MULTI_TAKE_SUFFIXES = (".fbx", ".glb", ".gltf")
#: the files a motion is written as
MOTION_WRITE_SUFFIXES = (".bvh", ".glb")
#: everything ``mocycle.read`` reads: motions, compressed keyframes, swing segmentations
READ_SUFFIXES = (*MOTION_READ_SUFFIXES, ".mck", ".mosw", ".json")
#: everything ``mocycle.write`` writes
WRITE_SUFFIXES = (*MOTION_WRITE_SUFFIXES, ".mck", ".mosw", ".json")

__all__ = ["MOTION_READ_SUFFIXES", "MOTION_WRITE_SUFFIXES", "MULTI_TAKE_SUFFIXES", "READ_SUFFIXES", "WRITE_SUFFIXES"]
