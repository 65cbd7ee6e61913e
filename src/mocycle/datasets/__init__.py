"""Built-in demo data and test ground truth (synthetic takes with exact phase).

The public names are :mod:`.synthetic`'s ``__all__`` and the session builder (:mod:`.sessions`).
"""

from . import synthetic
from .sessions import Session, join_takes
from .synthetic import *  # noqa: F403

__all__ = [*synthetic.__all__, "Session", "join_takes"]
