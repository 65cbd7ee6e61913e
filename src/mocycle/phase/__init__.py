"""Periodic structure: circular coordinates by persistent cohomology, periods, phase remaps."""

from .analysis import PeriodicMotion, PhaseResult, find_phase, phase_features
from .cohomology import CircleClass, CircleCoordinate, CohomologyFit, choose_classes
from .period import autocorrelation_period, excitation_regions, fit_period, gmm_cdf_remap, rank_uniform, unwrap_phase


def __getattr__(name: str):
    if name == "CircularCoordinates":  # the scikit-learn transformer: scikit-learn is imported on first use
        from .transformer import CircularCoordinates

        return CircularCoordinates
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "CircleClass",
    "CircleCoordinate",
    "CircularCoordinates",
    "CohomologyFit",
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
