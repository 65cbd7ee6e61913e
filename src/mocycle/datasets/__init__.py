"""Built-in demo data and test ground truth (synthetic takes with exact phase)."""

from .synthetic import (
    SyntheticTake,
    humanoid_skeleton,
    synthetic_circle_walk,
    synthetic_gesture,
    synthetic_half_cycle_trap,
    synthetic_nonperiodic,
    synthetic_run,
    synthetic_still,
    synthetic_walk,
    synthetic_walk_then_run,
    to_z_up,
)

__all__ = [
    "SyntheticTake",
    "humanoid_skeleton",
    "synthetic_circle_walk",
    "synthetic_half_cycle_trap",
    "synthetic_gesture",
    "synthetic_nonperiodic",
    "synthetic_run",
    "synthetic_still",
    "synthetic_walk",
    "synthetic_walk_then_run",
    "to_z_up",
]
