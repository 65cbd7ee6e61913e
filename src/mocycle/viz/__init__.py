"""Plots (matplotlib, no screen needed). Each function writes one PNG atomically."""

from .contacts import plot_contacts
from .cycle import plot_loop
from .keyframes import plot_projection
from .phase import plot_phase
from .swings import plot_swings

__all__ = ["plot_contacts", "plot_loop", "plot_phase", "plot_projection", "plot_swings"]
