"""Plots (matplotlib, no screen needed). Each function writes one PNG atomically."""

from .phase import plot_phase

__all__ = ["plot_phase"]
