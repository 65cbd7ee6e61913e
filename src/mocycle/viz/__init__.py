"""Plots (matplotlib, no screen needed). Each function writes one PNG atomically."""

from .cycle import plot_loop
from .phase import plot_phase

__all__ = ["plot_loop", "plot_phase"]
