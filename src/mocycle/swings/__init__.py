"""Joint swings (paper 003): segmentation, playback, a compact codec, retrieval and editing.

``segment(motion)`` → :class:`Segmentation` (swings and holds per joint) →
``playback`` (a Motion again), ``encode``/``write_swings`` (the ``.mosw`` file, :mod:`mocycle.io.mosw`; the
records themselves are :mod:`mocycle.segmentation`'s),
``signature``/``build_index`` (retrieval), ``edit_swing`` (angle and duration edits).
"""

from ..io.mosw import decode, encode, read_swings, size_report, write_swings
from .edit import edit_swing
from .playback import geodesic_errors, playback, playback_errors, segmentation_error
from .search import SearchHit, Signature, SwingIndex, bandai_content, build_index, compare, precision_at_k, signature
from .segment import DEFAULT_THRESHOLD, PAPER_WINDOW_S, Hold, Segmentation, Swing, choose_joints, segment

__all__ = [
    "DEFAULT_THRESHOLD", "PAPER_WINDOW_S", "Hold", "SearchHit", "Segmentation", "Signature", "Swing", "SwingIndex",
    "bandai_content", "build_index", "choose_joints", "compare", "decode", "edit_swing", "encode",
    "geodesic_errors", "playback", "playback_errors", "precision_at_k", "read_swings", "segment",
    "segmentation_error", "signature", "size_report", "write_swings",
]

