"""From a motion to its periodic motions: input preparation, circular coordinates, periods.

``find_phase(motion)`` is what ``mocycle phase`` and the cycle extraction call:

1. prepare the input (paper 001 §4.1, §5.1; KTH thesis §3.8, ch. 4): root
   position and heading as first differences (``root_features="heading"``: nothing
   depends on where the actor faces), optional joint subset, per-DOF
   normalisation, bone-length weights, PCA to a few dimensions, optional
   delay embedding;
2. circular coordinates with the scale and the number of classes read from
   the barcode (:class:`~mocycle.phase.cohomology.CohomologyFit`);
   when the whole body shows no periodic motion, the natural subsets (legs,
   then arms) are tried before giving up (``joints_used`` says which);
3. per class: excitation regions, the unwrapped phase, the period from a
   least-squares line (thesis Fig. 3.8), and on demand the two remaps of the
   coordinate to time (rank-uniform, eq. 3.20; GMM CDF, eq. 3.21);
4. full gait cycles: when the coordinate wraps once per *step* (the left and
   right legs trade places across one period, :mod:`~mocycle.phase.gait`),
   the phase is halved so one cycle is two steps;
5. the period: the cohomology's line fit, cross-checked by the windowed
   autocorrelation (paper 004) of the class's excited frames and of the
   legs; when they disagree by more than 4 %, the estimate under which the
   take is most like itself one period later wins (``period_source``,
   ``period_candidates``, ``period_reason``).
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field, replace

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError, NoPeriodicMotion
from ..features import delay_embed, pose_matrix
from ..motion import Motion
from ..threads import limit_threads
from .cohomology import MIN_FRAMES, CohomologyFit
from .gait import leg_curves, legs_period, sides_swap
from .period import (
    autocorrelation_period,
    excitation_regions,
    fit_period,
    gmm_cdf_remap,
    rank_uniform,
    repetition_distance,
    self_similarity,
    unwrap_phase,
)

DEFAULT_PCA = 8
#: Joint groups tried, in order, when the whole body shows no periodic motion.
SUBSETS = ("legs", "arms")
#: Period estimates closer than this (relative) agree; farther apart, self-similarity decides.
PERIOD_AGREEMENT = 0.04
#: Weight of the heading-rate column relative to a z-scored joint column of the longest bone.
HEADING_RATE_WEIGHT = 0.5
#: Self-similarity one found period apart above this: the coordinate does not follow the take's rhythm.
UNLIKE = 0.5
#: A found period is one step of a two-step gait only if the legs' own period is this many times as long.
HALF_RATIO = (1.8, 2.25)
#: Default for ``min_periods``: a class must wind at least this often over the take.
MIN_PERIODS = defaults.MIN_PERIODS


def phase_features(motion: Motion, *, joints: str | Iterable[str] | None = None, pca: int | str | None = "auto",
                   delay: int = 0, rep: str = "expmap", root_features: str = "heading", normalize: bool = True,
                   weights: str | None = "bone", root: str | None = None) -> np.ndarray:
    """The point cloud for circular coordinates: ``(T - delay, D)``.

    Defaults: rotation vectors, the root's tilt, its velocity in its heading frame and its heading rate
    (:func:`~mocycle.features.pose_matrix` ``root_features="heading"``; the heading rate at half weight), z-scored
    and
    weighted by
    bone length, projected on the first 8 principal components (``pca="auto"``;
    ``None`` or ``0`` keeps every dimension), no delay embedding here
    (``find_phase`` uses ``delay=2``, as the KTH thesis did: on the shared
    takes it finds 41 of 43 walks and runs against 35 without).
    """
    root_features = _validate.renamed("root", "root_features", root, root_features, "heading")
    X, decoder = pose_matrix(motion, rep=rep, root_features=root_features, joints=joints, weights=weights,
                             normalize=normalize)
    if root_features == "heading":  # one angle whose first difference doubles the capture noise: half weight
        X[:, decoder.columns.index("root:dheading")] *= HEADING_RATE_WEIGHT
    # Constant columns (joints that never move) carry no phase, and LAPACK's SVD
    # takes seconds instead of milliseconds on exactly constant columns.
    moving = np.ptp(X, axis=0) > 1e-12
    if not moving.any():
        raise MocycleError("nothing moves in this take: every pose feature is constant")
    if not moving.all():
        X = X[:, moving]
    if pca == "auto":
        pca = DEFAULT_PCA
    if pca:
        pca = _validate.integer("pca", pca, 1)
        n = min(pca, X.shape[1], X.shape[0])
        X = principal_components(X, n, overwrite=True)  # X is this function's own (pose_matrix made it)
    if delay:
        X = delay_embed(X, int(delay))
    return X


def principal_components(X: np.ndarray, n: int, overwrite: bool = False) -> np.ndarray:
    """The scores ``(T, n)`` of ``X`` ``(T, D)`` on its first ``n`` principal components (``overwrite``: ``X``
    is the caller's to lose and is centred in place, the same numbers without a ``(T, D)`` copy).

    What scikit-learn's ``PCA(n_components=n, svd_solver="full").fit_transform(X)`` returns (centred, the sign
    of each component set by its largest coefficient), without importing scikit-learn, which takes longer than
    a whole ``find_phase``.  The components come from the smaller of the two scatter matrices
    (``numpy.linalg.eigh``): with more frames than columns the eigenvectors ``V`` of the ``(D, D)`` matrix
    ``Xcᵀ Xc``; with fewer (short takes on wide rigs, e.g. 157 frames of a 100-joint rig) the eigenvectors
    ``U`` of the ``(T, T)`` Gram matrix ``Xc Xcᵀ``, whose scores are ``U S`` and components ``Uᵀ Xc / S``.
    Only the ``n`` largest eigenpairs are computed (LAPACK's ``syevr`` through ``scipy.linalg.eigh``).  The
    same scores as the SVD of ``Xc`` within rounding, several times faster.
    """
    from scipy.linalg import eigh

    owned = overwrite and isinstance(X, np.ndarray) and X.dtype == np.float64 and X.flags.writeable
    Xc = np.subtract(X, X.mean(axis=0), out=X) if owned else X - X.mean(axis=0)
    if Xc.shape[0] < Xc.shape[1]:
        G = Xc @ Xc.T
        w, U = eigh(G, subset_by_index=[G.shape[0] - n, G.shape[0] - 1], driver="evr")
        U, S = U[:, ::-1], np.sqrt(np.maximum(w[::-1], 0.0))  # largest first
        Vt = (U.T @ Xc) / np.where(S > 0, S, 1.0)[:, None]
        return U * _component_signs(Vt) * S
    G = Xc.T @ Xc
    _, V = eigh(G, subset_by_index=[G.shape[0] - n, G.shape[0] - 1], driver="evr")
    Vt = V[:, ::-1].T  # largest first
    return Xc @ (Vt * _component_signs(Vt)[:, None]).T


def _component_signs(Vt: np.ndarray) -> np.ndarray:
    """``(n,)``: the sign of each component's (row's) largest coefficient (scikit-learn's ``svd_flip``)."""
    return np.sign(Vt[np.arange(Vt.shape[0]), np.argmax(np.abs(Vt), axis=1)])


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
    joints_used: str = "all"
    period_source: str = "cohomology"
    period_candidates: dict[str, float] = field(default_factory=dict)
    period_reason: str = ""
    legs_period_frames: float = float("nan")
    half_cycle: bool = False

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
        figures = ("birth", "death", "persistence", "period_frames", "period_s", "n_periods")
        return {**{name: getattr(self, name) for name in figures},
                "excitation": [[int(s), int(e)] for s, e in self.excitation], **self.provenance()}

    def provenance(self) -> dict:
        """How the period was decided and on which joints (the JSON fields ``loop`` reports too)."""
        legs = self.legs_period_frames
        return {
            "joints_used": self.joints_used,
            "period_source": self.period_source,
            "period_candidates": {k: float(v) for k, v in self.period_candidates.items()},
            "period_reason": self.period_reason,
            "legs_period_frames": float(legs) if np.isfinite(legs) else None,
            "half_cycle_doubled": self.half_cycle,
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
    joints_used: str = "all"
    legs_period_frames: float = float("nan")

    def to_dict(self) -> dict:
        acf = self.autocorrelation_period_frames
        legs = self.legs_period_frames
        return {
            "classes": [c.to_dict() for c in self.classes],
            "autocorrelation_period_frames": None if not np.isfinite(acf) else float(acf),
            "legs_period_frames": None if not np.isfinite(legs) else float(legs),
            "joints_used": self.joints_used,
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


def _region_period(unwrapped: np.ndarray, regions: list[tuple[int, int]]) -> tuple[float, float]:
    """Period (frames) from the length-weighted mean slope of lines fitted per region, and periods covered."""
    slopes, weights, n_periods = [], [], 0.0
    for s, e in regions:
        fit = fit_period(unwrapped, frames=np.arange(s, e))
        slopes.append(fit.slope_cycles_per_frame)
        weights.append(e - s)
        n_periods += fit.n_periods
    slope = float(np.average(slopes, weights=weights))
    return (1.0 / slope if slope > 0 else float("inf")), n_periods


def _periodic_motion(coords: np.ndarray, cls, frame_time: float, n_frames: int) -> PeriodicMotion:
    unwrapped = unwrap_phase(coords)
    T = coords.size
    window = int(np.clip(round(0.5 * T / max(cls.n_cycles, 1.0)), 5, max(5, T // 4)))
    regions = excitation_regions(coords, window=window) or [(0, T)]
    period, n_periods = _region_period(unwrapped, regions)
    coords = _extend_phase(coords, n_frames, period)
    return PeriodicMotion(birth=cls.birth, death=cls.death, coords=coords, unwrapped=unwrap_phase(coords),
                          excitation=regions, period_frames=period, n_periods=n_periods, frame_time=frame_time,
                          combination=cls.combination)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist(), strict=True))


def _separate(found: list[PeriodicMotion], X: np.ndarray) -> list[PeriodicMotion]:
    """Excitation regions that do not bleed into each other's motion (paper 001 §4.6 made strict).

    The moving average behind :func:`excitation_regions` widens every region, so near the switch from one
    periodic motion to another (a walk turning into a run) a region reaches into the other motion.  Near
    another class's region (within one of its periods) a frame stays with a class only when the take
    repeats better at this class's period than at the other's there (:func:`repetition_distance`), and
    not more than twice as badly as it does over the class's own frames (the transition belongs to
    neither).  Runs shorter than a period are dropped; the periods are refitted on what remains.
    """
    if len(found) < 2:
        return found
    T, n = found[0].coords.size, X.shape[0]

    def padded(d):
        return np.concatenate([d, np.full(T - n, np.nan)]) if T > n else d[:T]

    dist = [padded(repetition_distance(X, c.period_frames, smooth=max(3, int(round(c.period_frames / 4)))))
            for c in found]
    near = []
    for c in found:
        mask = np.zeros(T, dtype=bool)
        for s, e in c.excitation:
            pad = int(np.ceil(c.period_frames))
            mask[max(0, s - pad): min(T, e + pad)] = True
        near.append(mask)
    out = []
    for i, c in enumerate(found):
        own = np.zeros(T, dtype=bool)
        for s, e in c.excitation:
            own[s:e] = True
        keep = own.copy()
        typical = float(np.nanmedian(dist[i][own])) if np.isfinite(dist[i][own]).any() else np.nan
        for j in range(len(found)):
            if j == i:
                continue
            zone = own & near[j] & np.isfinite(dist[i]) & np.isfinite(dist[j])
            keep[zone & (dist[i] > dist[j])] = False
            if np.isfinite(typical):
                keep[zone & (dist[i] > 2.0 * typical)] = False
        runs = [(s, e) for s, e in _runs(keep) if e - s >= c.period_frames]
        if not runs or runs == list(c.excitation):
            out.append(c)
            continue
        period, n_periods = _region_period(c.unwrapped, runs)
        out.append(replace(c, excitation=runs, period_frames=period, n_periods=n_periods))
    return out


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


def _longest(pm: PeriodicMotion, n_rows: int) -> tuple[int, int]:
    s, e = max(pm.excitation, key=lambda r: r[1] - r[0]) if pm.excitation else (0, n_rows)
    return s, min(e, n_rows)


def _full_cycle(pm: PeriodicMotion, curves: np.ndarray, legs: float) -> PeriodicMotion:
    """``pm`` with its phase halved when its period is one step of a two-step gait (module notes, 4)."""
    s, e = _longest(pm, curves.shape[0])
    swap = sides_swap(curves, pm.period_frames, slice(s, e))
    ratio = legs / pm.period_frames if np.isfinite(legs) else float("nan")
    if not swap.swaps or (np.isfinite(ratio) and not HALF_RATIO[0] <= ratio <= HALF_RATIO[1]):
        return pm
    unwrapped = 0.5 * pm.unwrapped
    reason = (f"half cycle doubled: across one period of {pm.period_frames:.2f} frames the left and right legs "
              f"trade places (distance {swap.swapped:.3g} to the other side against {swap.same:.3g} to the same "
              f"side)" + (f", and the legs' autocorrelation period is {ratio:.2f} times as long" if
                          np.isfinite(ratio) else ""))
    return replace(pm, coords=np.mod(unwrapped, 1.0), unwrapped=unwrapped, period_frames=2.0 * pm.period_frames,
                   n_periods=0.5 * pm.n_periods, half_cycle=True, period_reason=reason)


def _choose_period(pm: PeriodicMotion, X: np.ndarray, min_lag: int, legs: float,
                   whole: float | None = None) -> PeriodicMotion:
    """The period of ``pm``: the cohomology's, unless a cross-check disagrees and fits the take better.

    Candidates are the windowed autocorrelation period of the features on the longest excited region and
    the legs' own period, each kept when within 25 % of the cohomology's.  When one differs by more than
    :data:`PERIOD_AGREEMENT`, the candidate with the lowest :func:`self_similarity` of the region wins.
    ``whole``: the autocorrelation period of all of ``X``, if known (used when the region is all of X).
    """
    s, e = _longest(pm, X.shape[0])
    P = pm.period_frames
    cands = {"cohomology": P}
    if (e - s) // 2 >= max(min_lag, 2) + 1:
        acf = whole if whole is not None and (s, e) == (0, X.shape[0]) else \
            autocorrelation_period(X[s:e], min_lag=min_lag)
        if pm.half_cycle and np.isfinite(acf) and abs(2 * acf / P - 1) < abs(acf / P - 1):
            acf *= 2  # the features repeat every step; their autocorrelation says so
        cands["autocorrelation"] = acf
    if np.isfinite(legs):
        cands["legs autocorrelation"] = legs
    near = {k: v for k, v in cands.items() if np.isfinite(v) and 0.8 <= v / P <= 1.25}
    note = "; " + pm.period_reason if pm.period_reason else ""
    if all(abs(v / P - 1) <= PERIOD_AGREEMENT for v in near.values()):
        others = [k for k in near if k != "cohomology"]
        reason = (f"the cohomology's period; {' and '.join(others)} agree{'s' if len(others) == 1 else ''} "
                  f"within {PERIOD_AGREEMENT:.0%}" if others else "the cohomology's period (no cross-check "
                  "applies)")
        return replace(pm, period_candidates=cands, period_reason=reason + note)
    scores = {k: self_similarity(X[s:e], v) for k, v in near.items()}
    best = min(scores, key=lambda k: scores[k] if np.isfinite(scores[k]) else np.inf)
    reason = (f"estimates differ by more than {PERIOD_AGREEMENT:.0%}; {best} makes the take most like itself "
              "one period later (self-similarity " + ", ".join(f"{k} {near[k]:.2f} frames: {v:.3g}"
                                                              for k, v in scores.items()) + ")")
    new = near[best]
    return replace(pm, period_frames=float(new), n_periods=pm.n_periods * P / new, period_source=best,
                   period_candidates=cands, period_reason=reason + note)


def _subsets(motion: Motion, joints) -> list[tuple[str | Iterable[str] | None, str]]:
    """The joint selections to try, with their labels: the given one, or the whole body then legs, arms."""
    if joints is not None:
        return [(joints, joints if isinstance(joints, str) else ",".join(joints))]
    tries: list[tuple[str | Iterable[str] | None, str]] = [(None, "all")]
    for group in SUBSETS:
        try:
            motion.skeleton.select(group)
        except MocycleError:
            continue
        tries.append((group, group))
    return tries


@limit_threads
def find_phase(motion: Motion, *, classes: int | str = "auto", joints: str | Iterable[str] | None = None,
               pca: int | str | None = "auto", delay: int = 2, n_landmarks: int = 120,
               scale: str | float = "auto", min_periods: float = MIN_PERIODS, rep: str = "expmap",
               root_features: str = "heading", normalize: bool = True, weights: str | None = "bone",
               keep_features: bool = False, root: str | None = None) -> PhaseResult:
    """Periodic motions of ``motion`` with their phase per frame and their periods.

    ``classes``: ``"auto"`` or how many; ``joints`` (``None``: the whole body, then legs, then arms until
    one shows a periodic motion), ``pca``, ``delay``, ``rep``, ``root_features`` (``root`` its old name,
    accepted with a DeprecationWarning until the next release), ``normalize`` and ``weights``
    shape the input (:func:`phase_features`); ``n_landmarks``, ``scale`` and ``min_periods`` (how often a
    coordinate must wind over the take to count, >= 1) go to :class:`~.cohomology.CohomologyFit`;
    ``keep_features`` keeps the point cloud in ``result.features`` (for plots; off by default so results
    stay small).  An empty
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
    59.9 frames (1.00 s), 5.0 periods
    >>> gait.coords.shape                           # phase in [0, 1) per frame
    (300,)
    """
    t0 = time.perf_counter()
    if not isinstance(motion, Motion):
        raise MocycleError(f"find_phase needs a Motion; got {type(motion).__name__}")
    min_periods = _validate.real("min_periods", min_periods, 1.0)  # periods over the take
    root_features = _validate.renamed("root", "root_features", root, root_features, "heading")
    if motion.n_frames < MIN_FRAMES + delay:
        # valid input, too short to hold a repeat: the same outcome as no periodic motion (CLI exit 3)
        raise NoPeriodicMotion(f"no periodic motion found: finding a phase needs at least {MIN_FRAMES + delay} "
                               f"frames; the take has {motion.n_frames}")
    # Periods under a quarter of a second are not motions people capture; shorter
    # lags pick up frame-to-frame jitter (e.g. takes resampled by frame doubling).
    min_lag = max(2, int(round(0.25 / motion.frame_time)))
    legs_ids, curves = leg_curves(motion)
    legs = legs_period(motion, curves) if legs_ids.size else float("nan")
    tries, kept = [], None
    for subset, label in _subsets(motion, joints):
        X = phase_features(motion, joints=subset, pca=pca, delay=delay, rep=rep, root_features=root_features,
                           normalize=normalize,
                           weights=weights)
        try:
            estimator = CohomologyFit(n_landmarks=n_landmarks, scale=scale, n_classes=classes,
                                      min_periods=float(min_periods)).fit(X)
        except MocycleError as exc:  # e.g. no prime lifts the class to Z: the next joint selection may do
            tries.append((label, f"the analysis failed ({exc})"))
            continue
        found = _separate(_distinct([_periodic_motion(estimator.coords_[:, k], c, motion.frame_time,
                                                      motion.n_frames) for k, c in enumerate(estimator.classes_)]), X)
        acf = autocorrelation_period(X, min_lag=min_lag)
        checked = []
        for pm in found:
            own = legs
            if legs_ids.size and len(found) > 1:  # several motions: the legs' period over this one's frames
                s, e = _longest(pm, motion.n_frames)
                own = legs_period(motion, curves[s:e])
            pm = replace(pm, joints_used=label, legs_period_frames=own)
            if legs_ids.size:
                pm = _full_cycle(pm, curves, own)
            checked.append(_choose_period(pm, X, min_lag, own, whole=acf))
        doubt = _doubt(checked, acf, legs, X)
        tries.append((label, estimator.reason_ + doubt))
        if kept is None or (checked and not kept[0]):
            kept = (checked, X, estimator, label, acf)
        if checked and not doubt:
            kept = (checked, X, estimator, label, acf)
            break
    if kept is None:  # every joint selection failed: no periodic motion to be found (exit 3, not a crash)
        raise NoPeriodicMotion("no periodic motion found: " + "; ".join(f"{k}: {r}" for k, r in tries))
    checked, X, estimator, label, acf = kept
    if len(tries) == 1:
        reason = tries[0][1]
    else:
        used = next(r for k, r in tries if k == label)
        others = "; ".join(f"{k}: {r}" for k, r in tries if k != label)
        reason = f"{label}: {used} (also tried {others})"
    return PhaseResult(classes=checked, barcode=estimator.barcode_, reason=reason,
                       autocorrelation_period_frames=acf, n_frames=motion.n_frames, frame_time=motion.frame_time,
                       features=X if keep_features else None, seconds=time.perf_counter() - t0,
                       joints_used=label, legs_period_frames=legs)


def _doubt(checked: list[PeriodicMotion], acf: float, legs: float, X: np.ndarray) -> str:
    """Why the periodic motions found on one joint selection are in doubt ('' when they are not).

    They are when none is found, when no period found is within 25 % of an autocorrelation period
    (of the features, of the legs) while at least one of those exists, or when the take is not like
    itself one period of the main class's coordinate later (:func:`self_similarity` above :data:`UNLIKE`).
    """
    if not checked:
        return "; nothing periodic found"
    checks = [v for v in (acf, legs) if np.isfinite(v)]
    periods = [c.period_frames for c in checked]
    if checks and not any(0.8 <= v / p <= 1.25 for v in checks for p in periods):
        return (f"; its period{'s' if len(periods) > 1 else ''} ("
                + ", ".join(f"{p:.2f}" for p in periods) + " frames) disagree with the autocorrelation periods ("
                + ", ".join(f"{v:.2f}" for v in checks) + ")")
    main = max(checked, key=lambda c: len(c.frames()))
    s, e = _longest(main, X.shape[0])
    found = main.period_candidates.get("cohomology", main.period_frames)
    unlike = self_similarity(X[s:e], found)
    if unlike > UNLIKE:
        return (f"; the take is not like itself one found period ({found:.2f} frames) later (self-similarity "
                f"{unlike:.2f} > {UNLIKE:g})")
    return ""


def find_phase_every(motion: Motion, step: int = 1, **options) -> PhaseResult:
    """:func:`find_phase` on every ``step``-th frame only (the thesis plugin's subsampling), brought back to
    every frame: the unwrapped coordinate interpolated linearly, excitation regions and periods scaled by
    ``step``.  ``options``: :func:`find_phase`'s."""
    step = _validate.integer("step", step, 1)
    if step == 1:
        return find_phase(motion, **options)
    result = find_phase(motion[::step], **options)
    n_frames = motion.n_frames
    frames = np.arange(n_frames)
    classes = []
    note = f" (found on one frame in {step}: the frames in this reason are those)"
    for c in result.classes:
        unwrapped = np.interp(frames, np.arange(c.unwrapped.size) * step, c.unwrapped)
        excitation = [(s * step, min(n_frames, (e - 1) * step + 1)) for s, e in c.excitation]
        classes.append(replace(c, coords=np.mod(unwrapped, 1.0), unwrapped=unwrapped, excitation=excitation,
                               period_frames=c.period_frames * step, frame_time=c.frame_time / step,
                               period_candidates={k: v * step for k, v in c.period_candidates.items()},
                               legs_period_frames=c.legs_period_frames * step,
                               period_reason=c.period_reason + note if c.period_reason else c.period_reason))
    return replace(result, classes=classes, n_frames=n_frames, frame_time=result.frame_time / step,
                   autocorrelation_period_frames=result.autocorrelation_period_frames * step,
                   legs_period_frames=result.legs_period_frames * step)

