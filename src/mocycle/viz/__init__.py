"""Plots (matplotlib, no screen needed). Each function writes one PNG atomically."""

from .curves import plot_curves
from .cycle import plot_loop
from .keyframes import plot_projection
from .phase import plot_phase
from .swings import plot_swings

__all__ = ["plot_curves", "plot_loop", "plot_phase", "plot_projection", "plot_swings"]
