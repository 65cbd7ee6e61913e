"""Time-frequency warping (paper 004): the lapped cosine transform and lengthening takes by replicating atoms."""

from .lct import bell, block_edges, fold, ilct, lct, unfold
from .stretch import StretchReport, fundamental_cycles, group_cycle, joint_groups, stretch_motion, warp_curves

__all__ = [
    "StretchReport",
    "bell",
    "block_edges",
    "fold",
    "fundamental_cycles",
    "group_cycle",
    "ilct",
    "joint_groups",
    "lct",
    "stretch_motion",
    "unfold",
    "warp_curves",
]
