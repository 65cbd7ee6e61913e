"""Keyframe compression and spatial keyframing (Costa 2018 thesis, chapters 3-5).

Pose distance and errors (:mod:`.distance`), keyframe selection (:mod:`.select`),
temporal reconstruction (:mod:`.temporal`), projections to 2-D (:mod:`.projection`),
Igarashi back-projection and Algorithm 12 (:mod:`.spatial`); ``compress`` and the ``Compressed``
take it makes (:mod:`.compressed`; its ``.mck`` file is encoded by :mod:`mocycle.io.mck`).
"""

from .authoring import author_motion, relayout, resample_stroke
from .compressed import SCHEMES, Compressed, compress, read_compressed
from .density import KeyDensity, keyframe_density, rhythm_period
from .distance import (
    error_per_frame_per_joint,
    frame_errors,
    joint_weights,
    pose_distance,
    pose_distance_matrix,
    pose_vectors,
    stress,
)
from .projection import ONE_STEP, PROJECTIONS, TWO_STEP, PoseSpace, project_one_step, select_keyframes, spatial_layout
from .select import METHODS, keyframe_count, select_pb, select_rols, select_scs, select_uniform
from .spatial import BackProjection, OptimizeResult, nearest_rotation, optimize_projection, reconstruct_spatial
from .temporal import interpolate_rotations, slerp

__all__ = [
    "BackProjection", "Compressed", "KeyDensity", "METHODS", "ONE_STEP", "OptimizeResult", "PROJECTIONS",
    "PoseSpace", "SCHEMES", "TWO_STEP", "author_motion", "compress", "error_per_frame_per_joint", "frame_errors",
    "interpolate_rotations", "joint_weights", "keyframe_count", "keyframe_density", "nearest_rotation",
    "optimize_projection", "pose_distance", "pose_distance_matrix", "pose_vectors", "project_one_step",
    "read_compressed", "reconstruct_spatial", "relayout", "resample_stroke", "rhythm_period", "select_keyframes",
    "select_pb", "select_rols", "select_scs", "select_uniform", "slerp", "spatial_layout", "stress",
]

