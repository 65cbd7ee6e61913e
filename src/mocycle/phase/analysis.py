"""From a motion to its periodic motions: input preparation, circular coordinates, periods.

``find_phase(motion)`` is what ``mocycle phase`` and the cycle extraction call:

1. prepare the input (paper 001 §4.1, §5.1; KTH thesis §3.8, ch. 4): root
   translation as velocity, optional joint subset, per-DOF normalisation,
   bone-length weights, PCA to a few dimensions, optional delay embedding;
2. circular coordinates with the scale and the number of classes read from
   the barcode (:class:`~mocycle.phase.cohomology.CircularCoordinates`);
3. per class: excitation regions, the unwrapped phase, the period from a
   least-squares line (thesis Fig. 3.8), and on demand the two remaps of the
   coordinate to time (rank-uniform, eq. 3.20; GMM CDF, eq. 3.21);
4. the windowed-autocorrelation period of paper 004 as a cross-check.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from sklearn.decomposition import PCA

from .. import _validate
from ..errors import MocycleError
from ..features import delay_embed, pose_matrix
from ..motion import Motion
from .cohomology import MIN_FRAMES, CircularCoordinates
from .period import autocorrelation_period, excitation_regions, fit_period, gmm_cdf_remap, rank_uniform, unwrap_phase

DEFAULT_PCA = 8


def phase_features(motion: Motion, joints: str | Iterable[str] | None = None, pca: int | str | None = "auto",
                   delay: int = 0, rep: str = "expmap", root: str = "velocity", normalize: bool = True,
                   weights: str | None = "bone") -> np.ndarray:
    """The point cloud for circular coordinates: ``(T - delay, D)``.

    Defaults: rotation vectors plus root velocity, z-scored and weighted by
    bone length, projected on the first 8 principal components (``pca="auto"``;
    ``None`` or ``0`` keeps every dimension), no delay embedding here
    (``find_phase`` uses ``delay=2``, as the KTH thesis did: on the shared
    takes it finds 41 of 43 walks and runs against 35 without).
    """
    X, _ = pose_matrix(motion, rep=rep, root=root, joints=joints, weights=weights, normalize=normalize)
    # Constant columns (joints that never move) carry no phase, and LAPACK's SVD
    # takes seconds instead of milliseconds on exactly constant columns.
    moving = np.ptp(X, axis=0) > 1e-12
    if not moving.any():
        raise MocycleError("nothing moves in this take: every pose feature is constant")
    X = X[:, moving]
    if pca == "auto":
        pca = DEFAULT_PCA
    if pca:
        pca = _validate.integer("pca", pca, 1)
        n = min(pca, X.shape[1], X.shape[0])
        X = PCA(n_components=n, svd_solver="full").fit_transform(X)
    if delay:
        X = delay_embed(X, int(delay))
    return X


@dataclass(kw_only=True)
class PeriodicMotion:
    """One periodic motion found in a take.

    ``coords``: ``(T,)`` circular coordinate in [0, 1) per frame, following
    the geometry of the poses, not the clock; ``unwrapped``: ``(T,)`` in
    cycles; ``excitation``: frame ranges ``[start, end)`` where it winds.
    """

    birth: float
    death: float
    coords: np.ndarray
    unwrapped: np.ndarray
    excitation: list[tuple[int, int]]
    period_frames: float
    n_periods: float
    frame_time: float
    combination: tuple[int, ...] = (1,)

    @property
    def persistence(self) -> float:
        return self.death - self.birth

    @property
    def period_s(self) -> float:
        return self.period_frames * self.frame_time

    def frames(self) -> np.ndarray:
        """Indices of the excited frames, in order."""
        return np.concatenate([np.arange(s, e) for s, e in self.excitation]) if self.excitation else \
            np.arange(0)

    def rank_uniform(self) -> np.ndarray:
        """Rank-uniform remap of the coordinate (KTH thesis eq. 3.20), ``(T,)`` in [0, 1)."""
        return rank_uniform(self.coords)

    def gmm_cdf(self, n_components: int = 30, random_state: int = 0) -> np.ndarray:
        """GMM-CDF remap (eq. 3.21; GMM on three shifted copies as in paper 001), ``(T,)``."""
        return gmm_cdf_remap(self.coords, n_components=n_components, random_state=random_state)

    def to_dict(self) -> dict:
        return {
            "birth": self.birth,
            "death": self.death,
            "persistence": self.persistence,
            "period_frames": self.period_frames,
            "period_s": self.period_s,
            "n_periods": self.n_periods,
            "excitation": [[int(s), int(e)] for s, e in self.excitation],
        }


@dataclass(kw_only=True)
class PhaseResult:
    """What ``find_phase`` found: zero or more periodic motions and how it decided.

    ``barcode``: ``(B, 2)`` H1 bars (birth, death); ``features``: the point cloud the coordinates were
    computed on, ``(T - delay, D)``, only when ``find_phase(keep_features=True)`` asked for it (``None``
    otherwise: a result stays about the size of its own per-frame numbers).
    """

    classes: list[PeriodicMotion]
    barcode: np.ndarray
    reason: str
    autocorrelation_period_frames: float
    n_frames: int
    frame_time: float
    features: np.ndarray | None = field(default=None, repr=False)
    seconds: float = 0.0

    def to_dict(self) -> dict:
        acf = self.autocorrelation_period_frames
        return {
            "classes": [c.to_dict() for c in self.classes],
            "autocorrelation_period_frames": None if not np.isfinite(acf) else float(acf),
            "reason": self.reason,
            "frames": self.n_frames,
            "fps": 1.0 / self.frame_time,
            "seconds": self.seconds,
        }


def _extend_phase(coords: np.ndarray, n_frames: int, period: float) -> np.ndarray:
    """Pad the last frames lost to delay embedding by continuing at the fitted rate."""
    missing = n_frames - coords.size
    if missing <= 0:
        return coords
    rate = 1.0 / period if np.isfinite(period) and period > 0 else 0.0
    tail = coords[-1] + rate * np.arange(1, missing + 1)
    return np.mod(np.concatenate([coords, tail]), 1.0)


def _periodic_motion(coords: np.ndarray, cls, frame_time: float, n_frames: int) -> PeriodicMotion:
    unwrapped = unwrap_phase(coords)
    T = coords.size
    window = int(np.clip(round(0.5 * T / max(cls.n_cycles, 1.0)), 5, max(5, T // 4)))
    regions = excitation_regions(coords, window=window) or [(0, T)]
    slopes, weights, n_periods = [], [], 0.0
    for s, e in regions:
        fit = fit_period(unwrapped, frames=np.arange(s, e))
        slopes.append(fit.slope_cycles_per_frame)
        weights.append(e - s)
        n_periods += fit.n_periods
    slope = float(np.average(slopes, weights=weights))
    period = 1.0 / slope if slope > 0 else float("inf")
    coords = _extend_phase(coords, n_frames, period)
    return PeriodicMotion(birth=cls.birth, death=cls.death, coords=coords, unwrapped=unwrap_phase(coords),
                          excitation=regions, period_frames=period, n_periods=n_periods, frame_time=frame_time,
                          combination=cls.combination)


def _distinct(found: list[PeriodicMotion]) -> list[PeriodicMotion]:
    """Drop classes that describe a motion another class already describes.

    Two classes are the same motion when their excited frames overlap by more
    than half and their numbers of periods differ by less than 20 %; the one
    whose excitation covers more frames is kept (paper 001 §7: several
    coordinates for one motion).  The result is ordered by first excited frame.
    """
    order = sorted(found, key=lambda c: -len(c.frames()))
    kept: list[PeriodicMotion] = []
    for c in order:
        frames = set(c.frames().tolist())
        same = any(
            len(frames & set(k.frames().tolist())) > 0.5 * min(len(frames), len(k.frames()))
            and abs(c.n_periods - k.n_periods) < 0.2 * max(c.n_periods, k.n_periods)
            for k in kept
        )
        if not same:
            kept.append(c)
    return sorted(kept, key=lambda c: c.excitation[0][0] if c.excitation else 0)


def find_phase(motion: Motion, classes: int | str = "auto", joints: str | Iterable[str] | None = None,
               pca: int | str | None = "auto", delay: int = 2, n_landmarks: int = 120,
               scale: str | float = "auto", min_cycles: float = 1.25, keep_features: bool = False,
               **feature_options) -> PhaseResult:
    """Periodic motions of ``motion`` with their phase per frame and their periods.

    ``classes``: ``"auto"`` or how many; ``joints``, ``pca``, ``delay`` and
    ``feature_options`` (``rep``, ``root``, ``normalize``, ``weights``) shape the
    input (:func:`phase_features`); ``n_landmarks``, ``scale`` and
    ``min_cycles`` go to :class:`CircularCoordinates`; ``keep_features`` keeps the point cloud in
    ``result.features`` (for plots; off by default so results stay small).  An empty
    ``result.classes`` means no periodic motion; ``result.reason`` says why.

    Returns
    -------
    PhaseResult
        ``classes``: the :class:`PeriodicMotion` s found (coordinate per frame, excitation regions,
        period in frames and seconds), the H1 ``barcode``, the ``reason``, and the windowed-autocorrelation
        period as a cross-check.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=300, fps=60, period_s=1.0).motion
    >>> result = find_phase(walk)
    >>> gait = result.classes[0]
    >>> print(f"{gait.period_frames:.1f} frames ({gait.period_s:.2f} s), {gait.n_periods:.1f} periods")
    60.0 frames (1.00 s), 4.9 periods
    >>> gait.coords.shape                           # phase in [0, 1) per frame
    (300,)
    """
    t0 = time.perf_counter()
    if not isinstance(motion, Motion):
        raise MocycleError(f"find_phase needs a Motion; got {type(motion).__name__}")
    if motion.n_frames < MIN_FRAMES + delay:
        raise MocycleError(f"finding a phase needs at least {MIN_FRAMES + delay} frames; the take has "
                           f"{motion.n_frames}")
    X = phase_features(motion, joints=joints, pca=pca, delay=delay, **feature_options)
    estimator = CircularCoordinates(n_landmarks=n_landmarks, scale=scale, n_classes=classes,
                                    min_cycles=min_cycles).fit(X)
    found = _distinct([_periodic_motion(estimator.coords_[:, k], c, motion.frame_time, motion.n_frames)
                       for k, c in enumerate(estimator.classes_)])
    # Periods under a quarter of a second are not motions people capture; shorter
    # lags pick up frame-to-frame jitter (e.g. takes resampled by frame doubling).
    acf = autocorrelation_period(X, min_lag=max(2, int(round(0.25 / motion.frame_time))))
    return PhaseResult(classes=found, barcode=estimator.barcode_, reason=estimator.reason_,
                       autocorrelation_period_frames=acf, n_frames=motion.n_frames, frame_time=motion.frame_time,
                       features=X if keep_features else None, seconds=time.perf_counter() - t0)
