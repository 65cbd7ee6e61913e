"""Projections of every pose to 2-D (thesis sections 2.3 and 3.1).

One-step projectors (``ONE_STEP``), on the eq. 3.2 pose distances where the method
takes distances, else on :func:`~mocycle.keyframes.distance.pose_vectors`:

``pca``      scikit-learn ``PCA`` on the pose vectors (Algorithm 3)
``mds``      classical (Torgerson) MDS of the pose distances (Algorithm 6): the top two
             eigenvectors by ``scipy.sparse.linalg.eigsh`` (scikit-learn's ``ClassicalMDS``,
             1.8+, does a full eigendecomposition: 3.3 s instead of 0.3 s on 2752 frames)
``isomap``   scikit-learn ``Isomap``, 14 neighbours, on the pose distances
``lle``      scikit-learn ``LocallyLinearEmbedding``, 15 neighbours, on the pose vectors
``force``    Force Scheme (Algorithm 7, Tejada et al.), 50 iterations, vectorised: every
             point moves at once by the mean of its pairwise corrections (a Jacobi form
             of the per-pair loop, which makes it a Guttman/SMACOF step)
``tsne``     scikit-learn ``TSNE``, perplexity 50 (at most (n - 1) / 3), on the pose distances, random
             start, 500 iterations (1000 took 9 s instead of 0.3 s on one 409-frame take)

Two-step schemes (control points = keyframes, projected first with a seed projector):

``rbfp``     RBFP (Algorithm 10, Amorim et al.): a multiquadric RBF ``√(1 + r²)`` on the
             pose distances, no polynomial, maps every pose to 2-D; with ROLS selection
             (Algorithm 9) the control points come from the seed projection of up to
             ``max_candidates`` frames, as the thesis does
``lamp``     LAMP (Joia et al.): per pose an orthogonal affine map fitted to the control
             points weighted by ``1 / |x - x_i|²``
"""

from __future__ import annotations

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError
from ..motion import Motion
from .distance import joint_weights, pose_distance_matrix, pose_vectors
from .select import METHODS, keyframe_count, select_pb, select_rols, select_scs, select_uniform

#: the projections (one home: :mod:`mocycle.defaults`)
ONE_STEP = defaults.ONE_STEP_PROJECTIONS
TWO_STEP = defaults.TWO_STEP_PROJECTIONS
PROJECTIONS = defaults.PROJECTIONS


class PoseSpace:
    """The poses of a take with their eq. 3.2 weights; pose distances and vectors computed once, on demand.

    ``quats``: ``(T, J, 4)`` (or a :class:`Motion`); ``weights``: ``(J,)`` (default: eq. 3.2 weights,
    which need the motion).
    """

    def __init__(self, quats: np.ndarray | Motion, weights: np.ndarray | None = None):
        if isinstance(quats, Motion):
            weights = joint_weights(quats.skeleton) if weights is None else weights
            quats = quats.rotations
        if weights is None:
            raise MocycleError("PoseSpace needs joint weights when given bare quaternions")
        self.quats = np.asarray(quats, dtype=np.float64)
        self.weights = np.asarray(weights, dtype=np.float64)
        if self.quats.ndim != 3 or self.quats.shape[2] != 4 or self.weights.shape != (self.quats.shape[1],):
            raise MocycleError(f"PoseSpace needs (T, J, 4) quaternions and (J,) weights; got {self.quats.shape}, "
                               f"{self.weights.shape}")
        self._D: np.ndarray | None = None
        self._X: np.ndarray | None = None

    @property
    def n(self) -> int:
        return self.quats.shape[0]

    @property
    def distances(self) -> np.ndarray:
        """``(T, T)`` eq. 3.2 pose distances."""
        if self._D is None:
            self._D = pose_distance_matrix(self.quats, self.weights)
        return self._D

    @property
    def vectors(self) -> np.ndarray:
        """``(T, 9J)`` weighted rotation-matrix entries."""
        if self._X is None:
            self._X = pose_vectors(self.quats, self.weights)
        return self._X

    def subset(self, rows) -> PoseSpace:
        """The poses ``rows`` (reusing what is already computed)."""
        rows = np.asarray(rows)
        sub = PoseSpace(self.quats[rows], self.weights)
        if self._D is not None:
            sub._D = self._D[np.ix_(rows, rows)]
        if self._X is not None:
            sub._X = self._X[rows]
        return sub


# ---------------------------------------------------------------- one-step projectors


def project_pca(X: np.ndarray, random_state: int = 0) -> np.ndarray:
    from sklearn.decomposition import PCA

    X = np.asarray(X, dtype=np.float64)
    if X.shape[0] < 3:
        return _tiny(X.shape[0])
    Y = PCA(n_components=2, random_state=random_state).fit_transform(X)
    return _pad2(Y)


def project_mds(D: np.ndarray) -> np.ndarray:
    """Classical MDS of a distance matrix ``(n, n)`` → ``(n, 2)``."""
    D = np.asarray(D, dtype=np.float64)
    n = D.shape[0]
    if n < 3:
        return _tiny(n) * (D.max() if n == 2 else 1.0)
    from scipy.sparse.linalg import eigsh

    S = D**2
    B = -0.5 * (S - S.mean(axis=0) - S.mean(axis=1)[:, None] + S.mean())
    if n < 50:
        vals, vecs = np.linalg.eigh(B)
        vals, vecs = vals[-2:], vecs[:, -2:]
    else:
        vals, vecs = eigsh(B, k=2, which="LA", v0=np.ones(n))
    order = np.argsort(vals)[::-1]
    return orient_axes(vecs[:, order] * np.sqrt(np.maximum(vals[order], 0.0)))


def orient_axes(Y: np.ndarray) -> np.ndarray:
    """``Y`` ``(n, d)`` with each column's sign chosen so that its entry of largest magnitude is positive.

    An eigenvector's sign is arbitrary: LAPACK builds (numpy 1.26's OpenBLAS against 2.x's) return the
    same plane mirrored, so a projection is made deterministic here (as scikit-learn's ``svd_flip``)."""
    Y = np.array(Y, dtype=np.float64)
    if Y.size:
        top = Y[np.argmax(np.abs(Y), axis=0), np.arange(Y.shape[1])]
        Y *= np.where(top < 0, -1.0, 1.0)
    return Y


def project_isomap(D: np.ndarray, n_neighbors: int = 14) -> np.ndarray:
    from sklearn.manifold import Isomap

    D = np.asarray(D, dtype=np.float64)
    n = D.shape[0]
    if n < 5:
        return project_mds(D)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # disconnected neighbour graphs are joined by scikit-learn
        Y = Isomap(n_neighbors=min(n_neighbors, n - 1), n_components=2, metric="precomputed").fit_transform(D)
    return _pad2(Y)


def project_lle(X: np.ndarray, n_neighbors: int = 15, random_state: int = 0) -> np.ndarray:
    from sklearn.manifold import LocallyLinearEmbedding

    X = np.asarray(X, dtype=np.float64)
    n = X.shape[0]
    if n < 5:
        return project_pca(X)
    k = min(n_neighbors, n - 1)
    solver = "dense" if n <= 1500 else "arpack"
    try:
        Y = LocallyLinearEmbedding(n_neighbors=k, n_components=2, eigen_solver=solver,
                                   random_state=random_state).fit_transform(X)
    except (ValueError, np.linalg.LinAlgError, RuntimeError):
        Y = LocallyLinearEmbedding(n_neighbors=k, n_components=2, eigen_solver="dense", reg=1e-2,
                                   random_state=random_state).fit_transform(X)
    return orient_axes(_pad2(Y))


def project_force(D: np.ndarray, iterations: int = 50, random_state: int = 0, tol: float = 1e-6) -> np.ndarray:
    """Force Scheme (Algorithm 7), all points at once: ``P_i += mean_j (D_ij - |P_i - P_j|) · (P_i - P_j)/|P_i - P_j|``.

    Starts from a standard normal layout scaled to the distances.
    """
    D = np.asarray(D, dtype=np.float32)  # float32 halves the time of the n × n passes
    n = D.shape[0]
    rng = np.random.default_rng(random_state)
    P = (rng.standard_normal((n, 2)) * (D.mean() if n > 1 else 1.0)).astype(np.float32)
    for _ in range(iterations):
        dx = P[:, 0, None] - P[None, :, 0]
        dy = P[:, 1, None] - P[None, :, 1]
        d = np.sqrt(dx * dx + dy * dy)
        np.maximum(d, tol, out=d)
        f = D / d
        f -= 1.0
        np.fill_diagonal(f, 0.0)
        # sum_j f_ij (P_i - P_j) = P_i sum_j f_ij - (f @ P)_i
        P = P + (P * f.sum(axis=1)[:, None] - f @ P) / n
    P = P.astype(np.float64)
    return P - P.mean(axis=0)


def project_tsne(D: np.ndarray, perplexity: float = 50.0, random_state: int = 0, max_iter: int = 500) -> np.ndarray:
    from sklearn.manifold import TSNE

    D = np.asarray(D, dtype=np.float64)
    n = D.shape[0]
    if n < 5:
        return project_mds(D)
    from threadpoolctl import threadpool_limits

    p = float(min(perplexity, (n - 1) / 3.0))
    tsne = TSNE(n_components=2, perplexity=p, metric="precomputed", init="random", random_state=random_state,
                max_iter=max_iter)
    # One OpenMP thread: on a busy machine scikit-learn's spinning OpenMP threads turned a 0.1 s
    # t-SNE of 117 frames into 28 s; the takes here are small enough for one thread.
    with threadpool_limits(limits=1, user_api="openmp"):
        return tsne.fit_transform(D)


def _tiny(n: int) -> np.ndarray:
    return np.c_[np.linspace(0.0, 1.0, n), np.zeros(n)] if n > 1 else np.zeros((n, 2))


def _pad2(Y: np.ndarray) -> np.ndarray:
    Y = np.asarray(Y, dtype=np.float64)
    if Y.shape[1] < 2:
        Y = np.hstack([Y, np.zeros((len(Y), 2 - Y.shape[1]))])
    return np.nan_to_num(Y)


def project_one_step(name: str, space: PoseSpace, random_state: int = 0) -> np.ndarray:
    """``(T, 2)`` projection of every pose of ``space`` with one of :data:`ONE_STEP`."""
    _validate.choice("projection", name, ONE_STEP)
    if name == "pca":
        return project_pca(space.vectors, random_state)
    if name == "mds":
        return project_mds(space.distances)
    if name == "isomap":
        return project_isomap(space.distances)
    if name == "lle":
        return project_lle(space.vectors, random_state=random_state)
    if name == "force":
        return project_force(space.distances, random_state=random_state)
    return project_tsne(space.distances, random_state=random_state)


# ---------------------------------------------------------------- two-step maps


def multiquadric(r: np.ndarray, eps: float = 1.0) -> np.ndarray:
    """Eq. 2.4: ``√(1 + (εr)²)``."""
    return np.sqrt(1.0 + (eps * np.asarray(r)) ** 2)


def rbfp_map(D_to_keys: np.ndarray, D_keys: np.ndarray, key_points: np.ndarray) -> np.ndarray:
    """Algorithm 10 (RBFP): ``(n, 2)`` points from distances to the control points ``(n, K)``.

    ``D_keys``: ``(K, K)`` distances among the control points; ``key_points``: their ``(K, 2)`` projection.
    """
    from .spatial import rbf_solve

    W = rbf_solve(multiquadric(D_keys), np.asarray(key_points, dtype=np.float64))
    return multiquadric(D_to_keys) @ W


def lamp_map(X: np.ndarray, key_idx, key_points: np.ndarray) -> np.ndarray:
    """LAMP (Joia et al. 2011): ``(n, 2)`` points of the rows of ``X`` ``(n, d)``; control points ``X[key_idx]``."""
    X = np.asarray(X, dtype=np.float64)
    idx = np.asarray(key_idx)
    Xs, Ys = X[idx], np.asarray(key_points, dtype=np.float64)
    n, d = X.shape
    out = np.empty((n, 2))
    outer = np.einsum("kd,ke->kde", Xs, Ys).reshape(len(idx), 2 * d)
    for start in range(0, n, 256):
        x = X[start: start + 256]
        d2 = np.sum((x[:, None, :] - Xs[None]) ** 2, axis=-1)
        alpha = 1.0 / np.maximum(d2, 1e-12)
        sa = alpha.sum(axis=1, keepdims=True)
        xt = alpha @ Xs / sa
        yt = alpha @ Ys / sa
        AB = (alpha @ outer).reshape(-1, d, 2) - sa[:, :, None] * np.einsum("nd,ne->nde", xt, yt)
        U, _, Vt = np.linalg.svd(AB, full_matrices=False)
        M = U @ Vt
        out[start: start + 256] = np.einsum("nd,nde->ne", x - xt, M) + yt
    out[idx] = Ys
    return out


# ---------------------------------------------------------------- selection + projection


def candidates(n: int, max_candidates: int) -> np.ndarray:
    """Evenly strided frames (first and last included), at most ``max_candidates``."""
    if n <= max_candidates:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_candidates)).astype(np.int64))


def select_keyframes(method: str, space: PoseSpace, k: int, points: np.ndarray | None = None,
                     max_candidates: int = 1500, random_state: int = 0) -> np.ndarray:
    """Keyframe indices by ``method`` (:data:`~mocycle.keyframes.select.METHODS`).

    ROLS needs a 2-D projection: ``points`` when given (a spatial scheme's), else PCA.
    """
    _validate.choice("select", method, METHODS)
    n = space.n
    k = keyframe_count(n, count=k)
    if method == "uniform":
        return select_uniform(n, k)
    if method == "scs":
        return select_scs(space.quats, space.weights, k)
    if method == "pb":
        return select_pb(space.quats, space.weights, k)
    cand = candidates(n, max_candidates)  # rols
    sub = space.subset(cand)
    Q = project_pca(sub.vectors, random_state) if points is None else np.asarray(points)[cand]
    return cand[select_rols(sub.distances, Q, min(k, len(cand)))]


def spatial_layout(space: PoseSpace, projection: str, select: str, k: int, seed: str = "mds",
                   random_state: int = 0, max_candidates: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """Keyframes and the 2-D point of every frame for a spatial scheme: ``(key_idx (K,), points (T, 2))``.

    ``projection``: one of :data:`PROJECTIONS`; ``seed``: the first-step projector of ``rbfp``/``lamp``.
    """
    if projection in ONE_STEP:
        points = project_one_step(projection, space, random_state)
        return select_keyframes(select, space, k, points, random_state=random_state), points
    _validate.choice("projection", projection, PROJECTIONS)
    _validate.choice("seed", seed, ONE_STEP)
    n = space.n
    k = keyframe_count(n, count=k)
    if select == "rols":
        cand = candidates(n, max_candidates)
        sub = space.subset(cand)
        Q = project_one_step(seed, sub, random_state)
        chosen = select_rols(sub.distances, Q, min(k, len(cand)))
        key, L = cand[chosen], Q[chosen]
    else:
        key = select_keyframes(select, space, k, random_state=random_state)
        L = project_one_step(seed, space.subset(key), random_state)
    if projection == "rbfp":
        Dk = pose_distance_matrix(space.quats, space.weights, space.quats[key]) if space._D is None \
            else space.distances[:, key]
        points = rbfp_map(Dk, Dk[key], L)
    else:
        points = lamp_map(space.vectors, key, L)
    points[key] = L
    return key, points
