"""``search``: rank the takes of a folder by how alike their swings are to an example (paper 003)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from . import fields
from .options import Integer, Real, Text, option
from .options import Options as _Options
from .report import Recorder, Report, is_motion, label_of, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``search``."""

    top: int = option(10, "How many matches to print.", Integer(1))
    pattern: str = option("*.bvh", "File pattern in the folder.", Text(optional=False))
    threshold: float = fields.threshold()
    window_s: float = option(1.0, "Sliding window length, seconds.", Real(0, low_open=True), flag="--window")
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def run(query, folder: str | os.PathLike, options: Options | None = None) -> Report:
    """Index the takes of ``folder`` and rank them against ``query`` (a Motion or a motion file)."""
    from ..swings import SwingIndex, build_index
    from ..swings.search import check_index_options

    o = options or Options()
    with Recorder() as rec:
        check_index_options(folder, o.window_s)
        # the query's signature first, with the index's settings: its take is let go before the folder is read
        signature = SwingIndex([], [], threshold=o.threshold, window_s=o.window_s).signature_of(
            load(query, o.amc_fps, o.take))
        index = build_index(folder, pattern=o.pattern, threshold=o.threshold, window_s=o.window_s)
        exclude = None if is_motion(query) else Path(query)
        hits = index.query(signature, top=o.top, exclude=exclude)
        facts = {"query": label_of(query), "indexed": len(index),
                 "results": [{"rank": k + 1, "path": str(h.path), "score": h.score, "offset_s": h.offset_s}
                             for k, h in enumerate(hits)]}
    return rec.report("search", facts, result=index)
