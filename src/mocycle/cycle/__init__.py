"""Seamless typical cycles from a take: harmonic regression (M1/M2/M3), centroids, cut; loop metrics; the
loop's feet locked across its seam (:func:`lock_cycle`)."""

from .blend import BlendedCycle, Transition, blend_cycles, transition
from .centroid import centroid_cycle
from .cut import cut_cycle
from .extract import METHODS, cycle_phase, extract_cycle
from .foot_lock import lock_cycle
from .harmonic import MODELS, HarmonicRegression, harmonic_basis
from .harmonic_fit import harmonic_cycle
from .metrics import loop_metrics
from .representation import CycleSpace
from .result import ROOT_MODES, Cycle
from .timeaxis import TIME_AXES, TimeAxis, time_axis

__all__ = [
    "METHODS", "MODELS", "ROOT_MODES", "TIME_AXES", "BlendedCycle", "Cycle", "CycleSpace", "HarmonicRegression",
    "TimeAxis", "Transition", "blend_cycles", "transition",
    "centroid_cycle", "cut_cycle", "cycle_phase", "extract_cycle", "harmonic_basis", "harmonic_cycle", "lock_cycle",
    "loop_metrics", "time_axis",
]
