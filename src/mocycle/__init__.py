"""mocycle: turn raw motion capture into reusable animation.

The public surface most users need::

    import mocycle
    motion = mocycle.read("walk.bvh")          # BVH, or ASF+AMC via mocycle.io.read_asfamc
    X, decoder = mocycle.pose_matrix(motion, rep="expmap", root_features="velocity")
    mocycle.write(decoder.decode(X), "copy.bvh")
"""

from .errors import MocycleError, MocycleWarning, MotionFileError

# The rest is imported on first use (PEP 562), so that ``import mocycle.cli`` stays cheap and the command
# line can take Ctrl-C cleanly from its first moment.
_LAZY = {"delay_embed": "features", "pose_matrix": "features", "read": "files", "write": "files", "EndSite": "motion",
         "Motion": "motion", "Skeleton": "motion"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

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
