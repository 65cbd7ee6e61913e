"""Built-in demo data and test ground truth (synthetic takes with exact phase).

The public names are :mod:`.synthetic`'s ``__all__`` (listed there once).
"""

from . import synthetic
from .synthetic import *  # noqa: F403

__all__ = synthetic.__all__
