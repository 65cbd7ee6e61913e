"""mocycle: turn raw motion capture into reusable animation.

The public surface most users need::

    import mocycle
    motion = mocycle.read("walk.bvh")          # BVH, or ASF+AMC via mocycle.io.read_asfamc
    X, decoder = mocycle.pose_matrix(motion, rep="expmap", root="velocity")
    mocycle.write(decoder.decode(X), "copy.bvh")
"""

from .errors import MocycleError, MocycleWarning, MotionFileError
from .features import delay_embed, pose_matrix
from .io import read, write
from .motion import EndSite, Motion, Skeleton

__version__ = "0.1.0"

__all__ = [
    "EndSite",
    "MocycleError",
    "MocycleWarning",
    "Motion",
    "MotionFileError",
    "Skeleton",
    "delay_embed",
    "pose_matrix",
    "read",
    "write",
]
