"""Periodic structure: circular coordinates by persistent cohomology, periods, phase remaps."""

from .analysis import PeriodicMotion, PhaseResult, find_phase, phase_features
from .cohomology import CircleClass, CircleCoordinate, CircularCoordinates, choose_classes
from .period import autocorrelation_period, excitation_regions, fit_period, gmm_cdf_remap, rank_uniform, unwrap_phase

__all__ = [
    "CircleClass",
    "CircleCoordinate",
    "CircularCoordinates",
    "PeriodicMotion",
    "PhaseResult",
    "autocorrelation_period",
    "choose_classes",
    "excitation_regions",
    "find_phase",
    "fit_period",
    "gmm_cdf_remap",
    "phase_features",
    "rank_uniform",
    "unwrap_phase",
]
