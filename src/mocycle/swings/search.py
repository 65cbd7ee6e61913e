"""Retrieval by swing signatures (paper 003, section 5.2).

A take's **signature** is its segmentation sampled in time: at ``rate_hz``
samples per second, for each joint, the swing's angular velocity (axis × mean
angular speed, rad/s) while a swing runs and zero during holds.  Two takes are
compared **by sliding windows**: each window of the query (``window_s`` long,
half-overlapping) slides over the candidate and keeps its best match, which
absorbs differences in timing; the score is the mean of the windows' best
similarities, ``1 - ‖Q - C‖ / (‖Q‖ + ‖C‖)`` (1 = identical, 0 = unrelated).
A query of more than :data:`MAX_QUERY_WINDOWS` windows (a minute or more at the default 1 s windows) is
measured on that many windows spread evenly over it: each window costs a pass over the whole candidate, so
the search stays linear in the takes' length.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.signal import fftconvolve

from ..errors import MocycleError, MocycleWarning
from ..io import read_motion as read
from ..motion import Motion
from ..threads import limit_threads
from .segment import DEFAULT_THRESHOLD, Segmentation, segment


@dataclass
class Signature:
    """Per joint name, ``(L, 3)`` swing angular velocity (rad/s) sampled at ``rate_hz``."""

    tracks: dict[str, np.ndarray]
    rate_hz: float
    n_samples: int


#: The most windows of a query that slide over each candidate (evenly spread over a longer query).
MAX_QUERY_WINDOWS = 128
#: The longest sliding window of a search (seconds): an hour, longer than any take.
MAX_WINDOW_S = 3600.0

def signature(seg: Segmentation, rate_hz: float = 30.0) -> Signature:
    """The swing signature of a segmentation (see the module docstring)."""
    if not rate_hz > 0:
        raise MocycleError(f"rate_hz must be > 0; got {rate_hz}")
    duration = (seg.n_frames - 1) * seg.frame_time
    L = int(np.floor(duration * rate_hz + 1e-9)) + 1
    t = np.arange(L) / rate_hz
    tracks: dict[str, np.ndarray] = {}
    for s in seg.swings:
        t0, t1 = s.start * seg.frame_time, s.end * seg.frame_time
        rate = (s.end_angle - s.start_angle) / max(t1 - t0, 1e-12)
        track = tracks.setdefault(s.name, np.zeros((L, 3)))
        inside = slice(*np.searchsorted(t, (t0, t1)))  # the samples t0 <= t < t1 (t increases)
        track[inside] = np.asarray(s.axis) * rate
    return Signature(tracks, float(rate_hz), L)


def _stack(a: Signature, b: Signature) -> tuple[np.ndarray, np.ndarray]:
    names = sorted(set(a.tracks) | set(b.tracks))
    za, zb = np.zeros((a.n_samples, 3)), np.zeros((b.n_samples, 3))
    A = np.concatenate([a.tracks.get(n, za) for n in names], axis=1) if names else za
    B = np.concatenate([b.tracks.get(n, zb) for n in names], axis=1) if names else zb
    return A, B


def compare(query: Signature, cand: Signature, window_s: float = 1.0) -> tuple[float, float]:
    """Similarity (0-1) of two signatures by sliding windows, and the candidate time (s) matching the query start."""
    Q, C = _stack(query, cand)
    if C.shape[0] < Q.shape[0] and C.shape[0] < round(window_s * query.rate_hz):
        Q, C = C, Q  # a candidate shorter than a window slides over the query instead
        swapped = True
    else:
        swapped = False
    w = max(1, min(int(round(window_s * query.rate_hz)), Q.shape[0], C.shape[0]))
    hop = max(1, w // 2)
    c2 = np.concatenate([[0.0], np.cumsum(np.sum(C**2, axis=1))])
    win_c2 = c2[w:] - c2[:-w]  # ‖C[o:o+w]‖² for every offset o
    scores, offsets = [], []
    starts = np.arange(0, Q.shape[0] - w + 1, hop)
    if starts.size > MAX_QUERY_WINDOWS:  # a long query: windows spread evenly over it
        starts = np.unique(np.linspace(0, Q.shape[0] - w, MAX_QUERY_WINDOWS).round().astype(int))
    for s in starts.tolist():
        Qw = Q[s:s + w]
        q2 = float(np.sum(Qw**2))
        corr = fftconvolve(C, Qw[::-1], mode="valid", axes=0).sum(axis=1)  # Σ C[o+k]·Q[k]
        d = np.sqrt(np.maximum(win_c2 + q2 - 2 * corr, 0.0))
        norm = np.sqrt(win_c2) + np.sqrt(q2)
        sim = np.where(norm > 1e-12, 1.0 - d / np.maximum(norm, 1e-12), 1.0)
        o = int(np.argmax(sim))
        scores.append(float(sim[o]))
        offsets.append(o - s)
    best = int(np.argmax(scores))
    off = offsets[best] / query.rate_hz
    return float(np.mean(scores)), (-off if swapped else off)


@dataclass
class SearchHit:
    path: Path
    score: float
    offset_s: float


@dataclass
class SwingIndex:
    """Signatures of a folder of takes; :meth:`query` ranks them against an example."""

    paths: list[Path]
    signatures: list[Signature]
    threshold: float = DEFAULT_THRESHOLD
    joints: str | None = None
    rate_hz: float = 30.0
    window_s: float = 1.0
    skipped: list[tuple[Path, str]] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.paths)

    def signature_of(self, motion: Motion | str | os.PathLike) -> Signature:
        m = motion if isinstance(motion, Motion) else read(motion)
        return signature(segment(m, threshold=self.threshold, joints=self.joints), self.rate_hz)

    def query(self, example: Motion | str | os.PathLike | Signature, top: int = 10,
              exclude: str | os.PathLike | None = None) -> list[SearchHit]:
        """The ``top`` best matches of ``example`` (a motion, a file or a signature), best first.

        ``exclude``: a path left out of the ranking (the query file itself).
        """
        if top < 1:
            raise MocycleError(f"top must be >= 1; got {top}")
        sig = example if isinstance(example, Signature) else self.signature_of(example)
        skip = Path(exclude).resolve() if exclude is not None else None
        hits = []
        for p, s in zip(self.paths, self.signatures, strict=True):
            if skip is not None and p.resolve() == skip:
                continue
            score, off = compare(sig, s, self.window_s)
            hits.append(SearchHit(p, score, off))
        hits.sort(key=lambda h: -h.score)
        return hits[:top]


def check_index_options(folder: str | os.PathLike, window_s: float) -> Path:
    """The folder :func:`build_index` would read, checked with its window (before any take is read)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise MocycleError(f"{folder}: not a folder of takes")
    if not 0 < window_s <= MAX_WINDOW_S:
        raise MocycleError(f"the window must be a number of seconds in (0, {MAX_WINDOW_S:g}]; got {window_s}")
    return folder


@limit_threads
def build_index(folder: str | os.PathLike, pattern: str = "*.bvh", threshold: float = DEFAULT_THRESHOLD,
                joints: str | None = None, rate_hz: float = 30.0, window_s: float = 1.0) -> SwingIndex:
    """Segment every take matching ``pattern`` in ``folder`` and keep its signature.

    Files that cannot be read are skipped with a warning (listed in ``skipped``).
    """
    folder = check_index_options(folder, window_s)
    paths, sigs, skipped = [], [], []
    for p in sorted(folder.glob(pattern)):
        try:
            sigs.append(signature(segment(read(p), threshold=threshold, joints=joints), rate_hz))
            paths.append(p)
        except MocycleError as exc:
            skipped.append((p, str(exc)))
            warnings.warn(f"{p}: skipped ({exc})", MocycleWarning, stacklevel=2)
    if not paths:
        raise MocycleError(f"{folder}: no readable take matches {pattern!r}")
    return SwingIndex(paths, sigs, float(threshold), joints, float(rate_hz), float(window_s), skipped)


def bandai_content(path: str | os.PathLike) -> str:
    """Content label of a Bandai Namco file name, ``dataset-1_{content}_{style}_NNN.bvh`` → content."""
    parts = Path(path).stem.split("_")
    return parts[1] if len(parts) > 2 else Path(path).stem


def precision_at_k(index: SwingIndex, label: Callable[[Path], str] = bandai_content, k: int = 5) -> dict:
    """Leave-one-out retrieval: each take queries the others; the share of its top ``k`` with its label.

    Returns the mean ``precision`` and the per-label means.
    """
    if len(index) < 2:
        raise MocycleError("precision@k needs an index of at least two takes")
    per: dict[str, list[float]] = {}
    for p, s in zip(index.paths, index.signatures, strict=True):
        hits = index.query(s, top=k, exclude=p)
        mine = label(p)
        per.setdefault(mine, []).append(float(np.mean([label(h.path) == mine for h in hits])))
    allp = [x for v in per.values() for x in v]
    return dict(precision=float(np.mean(allp)), k=k, by_label={lab: float(np.mean(v)) for lab, v in per.items()},
                n_queries=len(allp))
