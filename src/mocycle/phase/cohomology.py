"""Circular coordinates from persistent cohomology (paper 001, sections 3-4).

Every frame is a point; the Vietoris-Rips filtration of a greedy-permutation
subsample (the *landmarks*, :func:`greedy_permutation`, picked among at most
:data:`LANDMARK_POOL` rows) is built by ripser from the landmark distance
matrix with Z/p cocycles.  For each
chosen H1 class:

1. the Z/p cocycle is lifted to Z (values above p/2 become negative) and the
   lift is checked on every triangle at the chosen scale; when it fails, the
   next prime is tried (KTH thesis, section 2.2);
2. the L2-smoothest representative ``z̄ = z + δw`` is found by least squares
   (the graph Laplacian's normal equations, :func:`_smooth`); ``w mod 1`` is the
   coordinate of each landmark;
3. every frame gets a coordinate from the landmarks around it by the
   partition-of-unity formula of sparse circular coordinates (Perea 2018):
   ``θ(x) = w_j + Σ_k φ_k(x) z̄(j, k)`` with ``j`` the landmark nearest ``x``
   (blocks of rows against the landmarks: linear in the frames);
4. with several classes, the integer basis is changed (a class replaced by its
   sum or difference with another) while that makes a class wind less in
   total: ripser may return "walk + run" and "run" for a walk-then-run take,
   the reduced basis is "walk" and "run" (paper 001 §7 suggests such
   combinations of coclasses);
5. a class must wind at least ``min_periods`` times over the take (rows are
   frames in time order) to count as a periodic motion: a single loop in a
   non-periodic take winds about once.  When no class does, but several wind
   about once each, their signed sum is tried: a gait whose cycles do not
   overlap closely makes one loop per cycle (CMU 07_10), and the sum winds
   once per cycle.  It is kept only when its cycle count agrees (within 25 %)
   with the windowed autocorrelation period of X, which a non-periodic take
   does not have;
6. the direction is chosen so that the coordinate increases with time.

The scale is taken late in the class's lifetime (paper 001 §4.3), and the
number of classes can be read from the barcode (a gap between long bars and
the rest), with the reason recorded.

:class:`CohomologyFit` is the algorithm; :class:`~mocycle.phase.transformer.CircularCoordinates` (import it
from there or from :mod:`mocycle.phase`; this module does not name it) is the same as a scikit-learn
transformer.  ``find_phase`` uses the former, so that
finding a phase loads neither scikit-learn nor ripser's Python wrapper (which imports scikit-learn): about a
second of start-up (``docs/performance.md``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _validate
from ..errors import DataError, MocycleError, MocycleWarning
from .period import autocorrelation_period

PRIMES = (47, 43, 41, 37, 31, 29, 23, 19, 17, 13)
MIN_FRAMES = 20
#: Up to this many rows the greedy permutation measures every pair at once (2 MB), then only picks (faster
#: than 120 matrix-vector products below about 500 rows, slower above).
FULL_MATRIX_ROWS = 512


def rips_h1(dist: np.ndarray, prime: int) -> tuple[np.ndarray, Sequence[np.ndarray]]:
    """H1 of the Vietoris-Rips filtration of a distance matrix with Z/p coefficients, by ripser's compiled core.

    ``dist``: ``(L, L)`` symmetric, zero diagonal.  Returns the bars ``(n, 2)`` (birth, death) and one cocycle
    per bar, rows ``[i, j, value mod p]`` (landmark indices): what ``ripser.ripser(dist, distance_matrix=True,
    maxdim=1, coeff=prime, do_cocycles=True)`` returns as ``dgms[1]`` and ``cocycles[1]``, from the same
    compiled function (``pyRipser.doRipsFiltrationDM``) called the same way, without the wrapper's import of
    scikit-learn.  Falls back to the wrapper when the core is not importable on its own or the diagonal is not
    zero (the wrapper then goes through its sparse path).
    """
    try:
        from pyRipser import doRipsFiltrationDM
    except ImportError:  # pragma: no cover - a ripser build without the top-level extension
        doRipsFiltrationDM = None
    if doRipsFiltrationDM is None or np.any(np.diagonal(dist) != 0):  # pragma: no cover - see above
        from ripser import ripser

        result = ripser(dist, distance_matrix=True, maxdim=1, coeff=prime, do_cocycles=True)
        return np.asarray(result["dgms"][1], dtype=float).reshape(-1, 2), list(result["cocycles"][1])
    n = dist.shape[0]
    row_grid, col_grid = np.meshgrid(np.arange(n), np.arange(n))
    res = doRipsFiltrationDM(np.array(dist[row_grid > col_grid], dtype=np.float32), 1, np.inf, prime, True)
    births_deaths = res["births_and_deaths_by_dim"]
    bars = np.reshape(np.array(births_deaths[1]), [len(births_deaths[1]) // 2, 2]) if len(births_deaths) > 1 \
        else np.zeros((0, 2))
    cocycles = _Cocycles(res["cocycles_by_dim"][1] if len(res["cocycles_by_dim"]) > 1 else [], prime)
    return np.asarray(bars, dtype=float).reshape(-1, 2), cocycles


class _Cocycles(Sequence[np.ndarray]):
    """ripser's flat cocycle lists as ``(n, 3)`` integer arrays ``[i, j, value mod p]``, each converted when it is
    first read (a fit reads the chosen bars' only, 1 or 2 of some 70)."""

    def __init__(self, flat: list, prime: int):
        self._flat, self._prime = flat, prime
        self._done: dict[int, np.ndarray] = {}

    def __len__(self) -> int:
        return len(self._flat)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(len(self))[i]]
        i = range(len(self))[i]  # negative indices, IndexError
        if i not in self._done:
            ccl = self._flat[i]
            ccl = np.reshape(np.array(ccl, dtype=np.int64), [len(ccl) // 3, 3])
            ccl[:, -1] = np.mod(ccl[:, -1], self._prime)
            self._done[i] = ccl
        return self._done[i]


@dataclass(frozen=True)
class CircleClass:
    """One H1 class turned into a landmark coordinate.

    ``bar`` is the index into ``barcode_``; ``scale`` the filtration value α
    used; ``w`` the landmark coordinates ``(L,)``; ``zbar`` the smoothed
    cocycle as an antisymmetric ``(L, L)`` matrix; ``prime`` the coefficient
    field the lift to Z succeeded with.
    """

    bar: int
    birth: float
    death: float
    scale: float
    prime: int
    w: np.ndarray
    zbar: np.ndarray

    @property
    def persistence(self) -> float:
        return self.death - self.birth


@dataclass(frozen=True)
class CircleCoordinate:
    """A reported circular coordinate: an integer combination of :class:`CircleClass` es.

    ``combination`` has one integer per fitted class (usually a single 1);
    ``bar``/``birth``/``death`` are those of the longest bar in the
    combination; ``sign`` makes the coordinate increase with time;
    ``n_cycles`` is its net winding over the fitted frames.
    """

    bar: int
    birth: float
    death: float
    combination: tuple[int, ...]
    sign: float
    n_cycles: float

    @property
    def persistence(self) -> float:
        return self.death - self.birth


def choose_classes(barcode: np.ndarray, n_classes: int | str = "auto", min_ratio: float = 1.5,
                   max_classes: int = 5) -> tuple[list[int], str]:
    """Pick H1 bars: the ``n_classes`` longest, or with ``"auto"`` the long bars before the largest gap.

    A bar is *long* when ``death / birth >= min_ratio`` (multiplicative
    persistence: noise bars die soon after they are born at any scale).
    Among the long bars, sorted by persistence, ``"auto"`` keeps the first
    ``k`` where the ratio ``persistence_k / persistence_{k+1}`` is largest
    (``k <= max_classes``; bar ``k+1`` may be a short one).
    Returns the bar indices (longest first) and the reason in words.
    """
    barcode = np.asarray(barcode, dtype=float).reshape(-1, 2)
    if barcode.shape[0] == 0:
        return [], "the H1 barcode is empty: the poses form no loop at any scale"
    pers = barcode[:, 1] - barcode[:, 0]
    order = [int(i) for i in np.argsort(-pers, kind="stable")]
    ratio = barcode[:, 1] / np.maximum(barcode[:, 0], 1e-12)

    def bar(i):
        return f"[{barcode[i, 0]:.3g}, {barcode[i, 1]:.3g})"

    if n_classes != "auto":
        n = _validate.integer("n_classes", n_classes, 1, words={"auto": "auto"})
        chosen = order[:n]
        reason = f"the {len(chosen)} longest H1 bar(s) as asked: " + ", ".join(bar(i) for i in chosen)
        if len(chosen) < n:
            reason += f" (only {len(chosen)} bar(s) exist)"
        return chosen, reason
    long_bars = [i for i in order if ratio[i] >= min_ratio]
    if not long_bars:
        top = order[0]
        return [], (f"no long H1 bar: the longest is {bar(top)} with death/birth = {ratio[top]:.2f} "
                    f"< {min_ratio:g}")
    cands = long_bars[:max_classes]
    rest = [i for i in order if i not in cands]
    nxt = [pers[i] for i in cands[1:]] + [pers[rest[0]] if rest else 0.0]
    gaps = [pers[i] / max(n, 1e-12 * pers[cands[0]]) for i, n in zip(cands, nxt, strict=True)]
    k = int(np.argmax(gaps)) + 1
    chosen = cands[:k]
    after = f"the next bar {bar(cands[k] if k < len(cands) else rest[0])}" if (k < len(cands) or rest) \
        else "no further bar"
    reason = (f"{k} long H1 bar(s) {', '.join(bar(i) for i in chosen)} (death/birth >= {min_ratio:g}); "
              f"largest persistence gap ({gaps[k - 1]:.1f}x) before {after}")
    return chosen, reason


def greedy_permutation(X: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Farthest-point (greedy permutation) landmarks, starting at row 0.

    Returns the landmark row indices ``(n,)`` and the landmark-to-row
    distances ``(n, N)`` (to about 1e-7 of the rows' spread near zero; a landmark's distance to itself is 0).
    ripser's ``n_perm`` does the same but calls
    scikit-learn's ``pairwise_distances`` (with its input checks) once per
    landmark, which was 85 % of the time of a whole fit.
    """
    idx, dist, _ = _greedy(X, n)
    return idx, dist


def _greedy(X: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, float]:
    """:func:`greedy_permutation` and the largest distance from a row to its nearest landmark.

    Each pass is one matrix-vector product of the centred rows (up to :data:`FULL_MATRIX_ROWS` rows, one
    matrix product for all pairs first), ``|x|² - 2 x·l + |l|²`` (a third of the
    time of the passes over ``X - l``).  Its rounding could pick another of two rows that are equally far
    to within 1e-13, so the next landmark is chosen by :func:`_farthest` among the rows within that
    rounding of the farthest, on ``|x - l|`` row by row: the landmarks of the plain algorithm, to the bit.
    """
    N = X.shape[0]
    Xc = X - X.mean(axis=0)  # centred: |x|² stays of the order of the distances, so does the rounding
    sq = np.einsum("nd,nd->n", Xc, Xc)
    # a bound on the rounding of the squared distances below: a few ulps of the largest term, per column
    tol = 8.0 * (X.shape[1] + 2) * np.finfo(np.float64).eps * (2.0 * float(sq.max()) + 1e-300)
    idx = np.zeros(n, dtype=np.int64)
    nearest = np.full(N, np.inf)
    groups: list = []  # the rows' duplicate groups, found when first needed (_farthest)
    full = None
    if N <= FULL_MATRIX_ROWS:  # a short take: every pair by one matrix product, then only the loop's choices
        full = Xc @ Xc.T
        full *= -2.0
        full += sq[:, None]
        full += sq[None, :]
    else:
        dist = np.empty((n, N))
    for i in range(n):
        if full is not None:
            row = full[idx[i]]
        else:
            row = dist[i]
            np.dot(Xc, Xc[idx[i]], out=row)
            row *= -2.0
            row += sq
            row += sq[idx[i]]
        np.minimum(nearest, row, out=nearest)
        if i + 1 < n:
            far = int(nearest.argmax())
            level = nearest[far] - 2.0 * tol
            idx[i + 1] = far if np.count_nonzero(nearest >= level) == 1 else \
                _farthest(X, idx[: i + 1], nearest, tol, groups)[0]
    radius = _farthest(X, idx, nearest, tol, groups)[1]
    if full is not None:
        dist = full[idx]
    np.maximum(dist, 0.0, out=dist)
    np.sqrt(dist, out=dist)
    dist[np.arange(n), idx] = 0.0
    return idx, dist, radius


def _farthest(X: np.ndarray, landmarks: np.ndarray, nearest2: np.ndarray, tol: float,
              groups: list | None = None) -> tuple[int, float]:
    """The row of ``X`` farthest from its nearest landmark (the first of equals) and that distance, measured
    as ``|x - l|`` on the rows whose rounded squared distance ``nearest2`` ``(N,)`` is within ``2 tol`` of
    the largest (``tol``: the rounding bound), so the one the exact distances pick is among them.

    Many such rows are copies of a few (a held pose, a constant input): then each distinct row is measured
    once, at its first copy (copies are as far, and the first of equals wins); ``groups`` keeps
    ``np.unique``'s first copies and inverse for the next call (an empty list: not known yet)."""
    cand = np.flatnonzero(nearest2 >= nearest2.max() - 2.0 * tol)
    if cand.size > _DEDUPLICATE and groups is not None:
        if not groups:
            groups.extend(np.unique(X, axis=0, return_index=True, return_inverse=True)[1:])
        first, inverse = groups
        cand = np.sort(first[np.unique(inverse.ravel()[cand])])
    exact = _nearest_exact(X[cand], X[landmarks])
    k = int(np.argmax(exact))
    return int(cand[k]), float(exact[k])


#: Above this many tied rows, :func:`_farthest` measures each distinct row once.
_DEDUPLICATE = 64


def _nearest_exact(rows: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(c,)``: each row's distance ``|x - l|`` to the nearest of ``points`` ``(L, D)``, by blocks of points
    (temporaries of at most about 2^20 values)."""
    out = np.full(rows.shape[0], np.inf)
    step = max(1, (1 << 20) // max(1, rows.shape[0] * rows.shape[1]))
    for a in range(0, points.shape[0], step):
        diff = rows[:, None, :] - points[None, a: a + step, :]
        np.minimum(out, np.sqrt(np.einsum("cld,cld->cl", diff, diff)).min(axis=1), out=out)
    return out


def landmark_distances(points: np.ndarray) -> np.ndarray:
    """``(L, L)`` Euclidean distances between the rows of ``points`` ``(L, D)``, exact to rounding (zero
    diagonal, symmetric): the matrix ripser gets."""
    diff = points[:, None, :] - points[None, :, :]
    return np.sqrt(np.einsum("ijd,ijd->ij", diff, diff))


def _lift(cocycle: np.ndarray, prime: int, L: int) -> np.ndarray:
    """Z/p cocycle rows ``[i, j, v]`` (landmark indices) -> antisymmetric integer ``(L, L)`` matrix."""
    Z = np.zeros((L, L))
    if cocycle.size == 0:
        return Z
    a = cocycle[:, 0].astype(int)
    b = cocycle[:, 1].astype(int)
    v = np.mod(cocycle[:, 2], prime)
    v = np.where(v > (prime - 1) / 2, v - prime, v)
    Z[a, b] = v
    Z[b, a] = -v
    return Z


def _is_cocycle(Z: np.ndarray, adjacent: np.ndarray) -> bool:
    """True when ``Z`` sums to zero around every triangle of the graph ``adjacent``.

    ``Z`` holds small integers, so the sum over every triangle ``a-b-c`` of ``(z_ab + z_bc + z_ca)²``,
    one entry per edge ``a-c``, is exact in floating point: expanded, it is a few matrix products.
    """
    # Every partial sum is an integer below L (3 max|z|)²: single precision is exact while that stays under
    # 2^24 (120 landmarks, |z| <= 23: 571 000), and its matrix products take half the time.
    exact32 = Z.shape[0] * (3.0 * float(np.abs(Z).max(initial=0.0))) ** 2 < 2.0**24
    dtype = np.float32 if exact32 else np.float64
    Z = Z.astype(dtype)
    A: np.ndarray = adjacent.astype(dtype)
    B: np.ndarray = A * Z  # z on the edges
    B2 = B * Z
    Zca = Z.T  # z(c, a) at [a, c]
    # Σ_b A_ab A_bc (z_ab + z_bc + z_ca)² at [a, c]
    S = B2 @ A + A @ B2 + (A @ A) * Zca**2 + 2.0 * (B @ B) + 2.0 * (B @ A + A @ B) * Zca
    return not np.any(S[adjacent] != 0)


def _smooth(Z: np.ndarray, adjacent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Harmonic representative: ``w = argmin ||z + δw||`` on the edges of ``adjacent``.

    Returns ``w`` ``(L,)`` (the least-norm solution: mean zero on each connected part) and ``z̄ = z + δw`` as an
    antisymmetric ``(L, L)`` matrix.  The normal equations are the graph Laplacian's, ``(D - A) w = -δᵀz`` with
    ``δᵀz`` the column sums of ``A ∘ Z``, an ``(L, L)`` system: on a connected graph ``(D - A + 11ᵀ/L) w = -δᵀz``
    (whose solution has mean zero), else LAPACK's least-norm least squares.  On 120 landmarks 10-20× faster
    than ``scipy.sparse.linalg.lsqr`` on the ``(E, L)`` coboundary, with the same ``w`` within 1e-10.
    """
    A = adjacent.astype(np.float64)
    np.fill_diagonal(A, 0.0)
    L = A.shape[0]
    laplacian = np.diag(A.sum(axis=0)) - A
    rhs = -(A * Z).sum(axis=0)
    if _connected(adjacent):
        w = np.linalg.solve(laplacian + 1.0 / L, rhs)
    else:
        w = np.linalg.lstsq(laplacian, rhs, rcond=None)[0]
    zbar = A * (Z + w[None, :] - w[:, None])
    return w, zbar


def _connected(adjacent: np.ndarray) -> bool:
    """Whether the graph ``adjacent`` ``(L, L)`` (boolean, symmetric) is connected (breadth-first from vertex 0)."""
    reach = np.zeros(adjacent.shape[0], dtype=bool)
    reach[0] = True
    front = reach.copy()
    while front.any():
        front = adjacent[front].any(axis=0) & ~reach
        reach |= front
    return bool(reach.all())


#: Landmarks are picked among at most this many rows: all of them up to this size, else row 0 and a seeded
#: random sample (the paper's landmark subsample: the greedy permutation's L passes over the rows would
#: otherwise grow with the take, 1.3 s of a 100 000-frame walk).  Every row still gets its coordinate.
LANDMARK_POOL = 4000
#: Rows per block when measuring every row against the landmarks: (rows, L) temporaries of about 4 MB.
BLOCK = 4096


def landmark_pool(N: int, size: int = LANDMARK_POOL) -> np.ndarray:
    """The rows ``(M,)`` landmarks are picked among: ``arange(N)`` when ``N <= size``, else row 0 and
    ``size - 1`` other rows drawn at random (seed 0, so a take always gets the same), in order."""
    if N <= size:
        return np.arange(N)
    rest = np.random.default_rng(0).choice(np.arange(1, N), size - 1, replace=False)
    return np.r_[0, np.sort(rest)]


def _landmark_blocks(X: np.ndarray, landmarks: np.ndarray, dtype=np.float64):
    """``(start, d2)`` per block of :data:`BLOCK` rows of ``X`` ``(N, D)``: ``d2`` ``(n, L)`` the squared distances
    of the block's rows to the ``landmarks`` ``(L, D)``, ``|x|² - 2 x·l + |l|²`` as one matrix product of the
    rows and the landmarks each with two columns appended (``[x, 1, |x|²] @ [-2 l, |l|², 1]ᵀ``), in ``dtype``."""
    L = landmarks.shape[0]
    right = np.concatenate([-2.0 * landmarks, np.einsum("ld,ld->l", landmarks, landmarks)[:, None],
                            np.ones((L, 1))], axis=1).T.astype(dtype)
    for start in range(0, X.shape[0], BLOCK):
        x = X[start: start + BLOCK]
        left = np.concatenate([x, np.ones((x.shape[0], 1)), np.einsum("nd,nd->n", x, x)[:, None]], axis=1)
        d2 = left.astype(dtype, copy=False) @ right
        yield start, np.maximum(d2, 0.0, out=d2)


def cover_radius(X: np.ndarray, landmarks: np.ndarray) -> float:
    """The largest distance from a row of ``X`` ``(N, D)`` to its nearest landmark (``(L, D)``), to about 1e-6
    (single precision: it only sets how far the scale is raised, :class:`CohomologyFit`)."""
    return float(np.sqrt(max(float(d2.min(axis=1).max()) for _, d2 in _landmark_blocks(X, landmarks, np.float32))))


def _extend(X: np.ndarray, landmarks: np.ndarray, classes: list[CircleClass]) -> np.ndarray:
    """Partition-of-unity extension from landmarks to points: ``(N, k)`` raw coordinates, one column per class.

    ``X``: ``(N, D)`` points; ``landmarks``: ``(L, D)``.  A point ``x`` takes
    ``w_j + Σ_k φ_k z̄(j, k) / Σ_k φ_k`` with ``j`` its nearest landmark and ``φ_k = max(r - d(x, l_k), 0)``
    (``r``: half the class's scale); a point farther than ``r`` from every landmark takes ``w_j``.  By blocks
    of rows (:func:`_landmark_blocks`): time and memory linear in N, no ``(L, N)`` matrix.
    """
    out = np.empty((X.shape[0], len(classes)))
    for start, d in _landmark_blocks(X, landmarks):
        np.sqrt(d, out=d)
        nearest = np.argmin(d, axis=1)
        for k, c in enumerate(classes):
            phi = np.maximum(c.scale / 2 - d, 0.0)
            total = phi.sum(axis=1)
            theta = c.w[nearest]
            ok = total > 0
            moved = np.einsum("nl,nl->n", phi, c.zbar[nearest])
            theta[ok] += moved[ok] / total[ok]
            out[start: start + d.shape[0], k] = theta
    return out


def _wrap(x: np.ndarray) -> np.ndarray:
    """Circle differences (cycles) wrapped into [-0.5, 0.5)."""
    return x - np.round(x)


def _reduce_basis(coords: np.ndarray, max_rounds: int = 10) -> np.ndarray:
    """Integer unimodular basis change ``(k, k)`` that makes each coordinate wind as little as it can.

    A column is replaced by its sum or difference with another while that
    lowers its total variation (sum of |wrapped frame-to-frame steps|) by at
    least 5 %.  ``coords``: ``(T, k)`` raw coordinates in time order.
    """
    k = coords.shape[1]
    basis = np.eye(k, dtype=np.int64)
    if k < 2:
        return basis
    steps = _wrap(np.diff(coords, axis=0))

    def variation(col):
        return np.abs(_wrap(steps @ col)).sum()

    for _ in range(max_rounds):
        changed = False
        for i in range(k):
            for j in range(k):
                if i == j:
                    continue
                for s in (1, -1):
                    cand = basis[:, i] + s * basis[:, j]
                    if variation(cand) < 0.95 * variation(basis[:, i]):
                        basis[:, i] = cand
                        changed = True
        if not changed:
            break
    return basis


class CohomologyFit:
    """Circle-valued coordinates of the points of X from persistent cohomology (numpy, scipy and ripser only).

    The parameters, ``fit``, ``transform`` and the fitted attributes of
    :class:`~mocycle.phase.transformer.CircularCoordinates`, which adds scikit-learn's input checks and
    estimator contract; ``fit`` here takes a 2-D float array of finite or NaN values as is.

    Parameters
    ----------
    n_landmarks : landmarks taken by greedy permutation (ripser ``n_perm``);
        all points are used when there are fewer.
    prime : first coefficient field Z/p tried; others from ``PRIMES`` follow
        when the lift to Z fails.
    scale : ``"auto"`` (``scale_fraction`` of the way through each class's
        lifetime, raised if needed so the landmark balls cover every point) or
        a filtration value α that every chosen class must be alive at.
    n_classes : ``"auto"`` (read from the barcode, see :func:`choose_classes`)
        or how many of the longest H1 bars to use.
    scale_fraction : where in ``[birth, death)`` the auto scale lies (paper 001:
        late in the lifetime works best).
    min_ratio : death/birth a bar needs to count as long ("auto").
    max_classes : at most this many classes with ``"auto"``.
    min_periods : net windings over the frames a coordinate needs to count as a
        periodic motion (rows of X must be frames in time order); ``None``
        keeps every chosen class.

    Attributes (after ``fit``)
    --------------------------
    barcode_ : ``(n, 2)`` H1 bars (birth, death) of the landmark filtration.
    cocycle_classes_ : the fitted :class:`CircleClass` es (chosen bars).
    classes_ : the reported :class:`CircleCoordinate` s, longest bar first.
    coords_ : ``(T, k)`` coordinates in ``[0, 1)`` (k = len(classes_), may be 0).
    reason_ : why these classes (which bars, which gap).
    landmarks_ : ``(L,)`` indices of the landmark points; ``cover_radius_`` their covering radius.
    """

    def __init__(self, n_landmarks: int = 120, prime: int = 47, scale: str | float = "auto",
                 n_classes: int | str = 1, scale_fraction: float = 0.75, min_ratio: float = 1.5,
                 max_classes: int = 5, min_periods: float | None = 1.25):
        self.n_landmarks = n_landmarks
        self.prime = prime
        self.scale = scale
        self.n_classes = n_classes
        self.scale_fraction = scale_fraction
        self.min_ratio = min_ratio
        self.max_classes = max_classes
        self.min_periods = min_periods

    # -- validation ----------------------------------------------------------
    def _check_X(self, X) -> np.ndarray:
        """X as a 2-D float array of at least MIN_FRAMES rows (NaN/inf allowed: fit drops those columns)."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2:
            raise DataError(f"X must be a 2-D array (frames, features); got shape {X.shape}")
        return self._check_frames(X)

    @staticmethod
    def _check_frames(X: np.ndarray) -> np.ndarray:
        if X.shape[0] < MIN_FRAMES:
            raise DataError(f"X must hold at least {MIN_FRAMES} frames (rows) for circular coordinates; "
                            f"got {X.shape[0]} sample(s)")
        return X

    def _check_params(self):
        _validate.integer("n_landmarks", self.n_landmarks, 3)
        _validate.real("scale_fraction", self.scale_fraction, 0, 1, low_open=True, high_open=True)
        if self.scale != "auto":
            _validate.positive("scale", self.scale)

    # -- fitting ---------------------------------------------------------------
    def fit(self, X, y=None):
        """Compute the barcode, choose classes and the coordinate of every row of X."""
        self._check_params()
        X = self._check_X(X)
        self.n_features_in_ = X.shape[1]
        self.columns_used_ = np.all(np.isfinite(X), axis=0)
        if not self.columns_used_.any():
            raise DataError("X has NaN or infinite values in every column")
        if not self.columns_used_.all():
            warnings.warn(f"dropping {int((~self.columns_used_).sum())} column(s) of X with NaN or infinite "
                          "values", MocycleWarning, stacklevel=2)
            X = X[:, self.columns_used_]
        N = X.shape[0]
        L = int(min(self.n_landmarks, N))
        pool = landmark_pool(N)
        picked, _, radius = _greedy(X[pool] if pool.size < N else X, L)  # (L,), (L, M), pool's cover radius
        idx = pool[picked]
        dist_ll = landmark_distances(X[idx])
        r_cover = radius if pool.size == N else cover_radius(X, X[idx])
        primes = [self.prime] + [p for p in PRIMES if p != self.prime]
        for prime in primes:
            barcode, cocycles = rips_h1(dist_ll, prime)
            finite = np.isfinite(barcode[:, 1])
            chosen, reason = choose_classes(barcode[finite], self.n_classes, self.min_ratio, self.max_classes)
            bars = np.flatnonzero(finite)[chosen]
            classes, failed = self._make_classes(barcode, cocycles, bars, prime, dist_ll, r_cover)
            if not failed:
                break
        else:  # pragma: no cover - every prime failed
            raise MocycleError("could not lift the cohomology class to integer coefficients with any prime tried")
        self.barcode_ = barcode
        self.cocycle_classes_ = classes
        self.landmarks_ = idx
        self.landmark_points_ = X[idx]
        self.cover_radius_ = r_cover
        raw = self._coords(X, classes)
        self.basis_ = _reduce_basis(raw)
        self.basis_, joined = self._join_single_loops(raw, X)
        self.classes_, keep, notes = self._report(raw @ self.basis_, classes)
        self.basis_ = self.basis_[:, keep]
        self.reason_ = reason + joined + "".join(notes)
        self.coords_ = self._combine(raw)
        return self

    def _join_single_loops(self, raw: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, str]:
        """The basis with the signed sum of classes that wind about once each appended, if it is
        periodic (module notes), and a note saying so ('' when nothing was joined)."""
        if self.min_periods is None or raw.shape[1] < 2:
            return self.basis_, ""
        nets = _wrap(np.diff(raw @ self.basis_, axis=0)).sum(axis=0)
        if np.any(np.abs(nets) >= self.min_periods):
            return self.basis_, ""
        single = np.flatnonzero(np.abs(nets) >= 0.5)
        if single.size < 2:
            return self.basis_, ""
        total = self.basis_[:, single] @ np.sign(nets[single]).astype(np.int64)
        cycles = abs(_wrap(np.diff(raw @ total)).sum())
        period = autocorrelation_period(X)
        expected = X.shape[0] / period if np.isfinite(period) else np.nan
        if cycles >= self.min_periods and abs(cycles / expected - 1) <= 0.25:
            note = (f"; {single.size} classes that wind about once each were joined into one that "
                    f"winds {cycles:.2f} times (the autocorrelation expects {expected:.2f})")
            return np.c_[self.basis_, total], note
        return self.basis_, ""

    def _report(self, combined: np.ndarray, classes: list[CircleClass]):
        """Orientation, winding and the kept columns of the reduced basis."""
        out, keep, notes = [], [], []
        for k in range(combined.shape[1]):
            steps = _wrap(np.diff(combined[:, k]))
            net = float(steps.sum())
            members = [i for i in range(len(classes)) if self.basis_[i, k] != 0]
            main = max(members, key=lambda i: classes[i].persistence)
            c = classes[main]
            sign = -1.0 if net < 0 else 1.0
            if self.min_periods is not None and abs(net) < self.min_periods:
                notes.append(f"; the class of bar [{c.birth:.3g}, {c.death:.3g}) winds only {abs(net):.2f} "
                             f"times over the take (< {self.min_periods:g}), so it is not a periodic motion")
                continue
            keep.append(k)
            out.append(CircleCoordinate(c.bar, c.birth, c.death, tuple(int(v) for v in self.basis_[:, k]),
                                        sign, abs(net)))
        return out, keep, notes

    def _combine(self, raw: np.ndarray) -> np.ndarray:
        if not self.classes_:
            return np.zeros((raw.shape[0], 0))
        signs = np.array([c.sign for c in self.classes_])
        return np.mod((raw @ self.basis_) * signs, 1.0)

    def _make_classes(self, barcode, cocycles, bars, prime, dist_ll, r_cover):
        classes = []
        for bar in bars:
            birth, death = barcode[bar]
            if self.scale == "auto":
                alpha = birth + self.scale_fraction * (death - birth)
                if alpha < 2 * r_cover:  # make the landmark balls cover every point, if the class allows
                    alpha = min(2 * r_cover * 1.001, birth + 0.99 * (death - birth))
            else:
                alpha = float(self.scale)
                if not birth <= alpha < death:
                    raise MocycleError(f"scale {alpha:g} is outside the lifetime [{birth:.4g}, {death:.4g}) "
                                       "of a chosen class")
            adjacent = dist_ll <= alpha
            np.fill_diagonal(adjacent, False)
            Z = _lift(np.asarray(cocycles[bar]), prime, dist_ll.shape[0])
            if not _is_cocycle(Z, adjacent):
                return classes, True
            w, zbar = _smooth(Z, adjacent)
            classes.append(CircleClass(int(bar), float(birth), float(death), float(alpha), prime, w, zbar))
        return classes, False

    def _coords(self, X, classes) -> np.ndarray:
        if not classes:
            return np.zeros((X.shape[0], 0))
        return _extend(X, self.landmark_points_, classes)

    def fit_transform(self, X, y=None, **fit_params) -> np.ndarray:
        return self.fit(X).coords_

    def transform(self, X) -> np.ndarray:
        """Coordinates ``(N, k)`` in ``[0, 1)`` of new points from the fitted landmarks."""
        if not hasattr(self, "classes_"):
            raise MocycleError("this CohomologyFit is not fitted yet: call fit first")
        return self._transform(np.asarray(X, dtype=np.float64))

    def _transform(self, X: np.ndarray) -> np.ndarray:
        if X.ndim != 2 or X.shape[1] != self.n_features_in_:
            raise DataError(f"X must have {self.n_features_in_} columns, as in fit; got shape {X.shape}")
        X = X[:, self.columns_used_]
        if not np.all(np.isfinite(X)):
            raise DataError("X contains NaN or infinite values in the columns used for fitting")
        return self._combine(self._coords(X, self.cocycle_classes_))
