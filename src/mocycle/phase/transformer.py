"""``CircularCoordinates``: the circular coordinates of :mod:`.cohomology` as a scikit-learn transformer.

Kept apart from the algorithm (:class:`~mocycle.phase.cohomology.CohomologyFit`) because importing
scikit-learn takes about a second, which ``find_phase`` and the command line do not need.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils.validation import check_array, check_is_fitted

from .cohomology import CohomologyFit

__all__ = ["CircularCoordinates"]

# check_array's keyword for "NaN allowed" was renamed in scikit-learn 1.6 (force_all_finite -> ensure_all_finite)
_ALLOW_NAN = ({"ensure_all_finite": "allow-nan"} if "ensure_all_finite" in check_array.__code__.co_varnames
              else {"force_all_finite": "allow-nan"})


class CircularCoordinates(TransformerMixin, BaseEstimator, CohomologyFit):
    """Circle-valued coordinates of the points of X from persistent cohomology (a scikit-learn transformer).

    Parameters, attributes and the algorithm: :class:`~mocycle.phase.cohomology.CohomologyFit`; this class
    adds scikit-learn's input checks (its messages for sparse, complex, 1-D or empty input, all ValueErrors)
    and its estimator contract (``get_params``, ``clone``, pipelines).

    Examples
    --------
    Four turns around a noisy circle have one circular coordinate that winds four times:

    >>> import numpy as np
    >>> t = np.linspace(0, 4 * 2 * np.pi, 200, endpoint=False)
    >>> X = np.c_[np.cos(t), np.sin(t)] + 0.01 * np.random.default_rng(0).normal(size=(200, 2))
    >>> cc = CircularCoordinates().fit(X)
    >>> cc.coords_.shape
    (200, 1)
    >>> turns = np.unwrap(2 * np.pi * cc.coords_[:, 0]) / (2 * np.pi)
    >>> round(abs(float(turns[-1] - turns[0])))
    4
    """

    def __sklearn_tags__(self):  # scikit-learn >= 1.6
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True  # fit drops columns with NaN or inf (with a warning)
        return tags

    def _more_tags(self):  # scikit-learn < 1.6
        return {"allow_nan": True}

    def _check_X(self, X) -> np.ndarray:
        """X as a dense 2-D float array of at least MIN_FRAMES rows (NaN/inf allowed: fit drops those columns).

        scikit-learn's ``check_array`` makes the messages (sparse, complex, 1-D, empty input): ValueErrors.
        """
        X = check_array(X, dtype=np.float64, ensure_2d=True, ensure_min_samples=1, **_ALLOW_NAN)
        return self._check_frames(X)

    def fit_transform(self, X, y=None, **fit_params) -> np.ndarray:
        return self.fit(X).coords_

    def transform(self, X) -> np.ndarray:
        """Coordinates ``(N, k)`` in ``[0, 1)`` of new points from the fitted landmarks."""
        check_is_fitted(self, "classes_")
        return self._transform(check_array(X, dtype=np.float64, ensure_2d=True, **_ALLOW_NAN))
