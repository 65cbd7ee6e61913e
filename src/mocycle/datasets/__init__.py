"""Built-in demo data and test ground truth (synthetic takes with exact phase)."""

from .synthetic import (
    STEADY_KINDS,
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
    synthetic_walk_then_wave,
    synthetic_walk_turn_walk,
    synthetic_wave,
    to_z_up,
)

__all__ = [
    "STEADY_KINDS",
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
    "synthetic_walk_then_wave",
    "synthetic_walk_turn_walk",
    "synthetic_wave",
    "to_z_up",
]
