"""Plots: the data of each figure (:mod:`.data`, no matplotlib) and its drawing (matplotlib, ``[plot]`` extra).

``*_plot_data`` functions return plain arrays and dicts; ``plot_*`` functions draw them on a
:class:`matplotlib.figure.Figure` (no pyplot, no backend chosen) and write one PNG atomically.
Importing this package does not import matplotlib; the ``plot_*`` names do on first use.
"""

from .data import curves_plot_data, loop_plot_data, phase_plot_data, projection_plot_data, swings_plot_data

_PLOTS = {"plot_contacts": "contacts", "plot_curves": "curves", "plot_loop": "cycle", "plot_phase": "phase",
          "plot_projection": "keyframes", "plot_swings": "swings"}

__all__ = ["curves_plot_data", "loop_plot_data", "phase_plot_data", "plot_contacts", "plot_curves", "plot_loop",
           "plot_phase", "plot_projection", "plot_swings", "projection_plot_data", "swings_plot_data"]


def __getattr__(name: str):
    if name in _PLOTS:
        from importlib import import_module

        return getattr(import_module(f".{_PLOTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
