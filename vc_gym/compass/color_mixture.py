"""A Gaussian mixture over RGB colours, fitted by expectation-maximisation (EM).

The colour classes of the visual compass (:class:`vc_gym.compass.colors.ColorClasses`,
paper section 3.4) are the components of such a mixture. :func:`fit_gaussian_mixture`
seeds the components with k-means++ plus a few Lloyd iterations, then refines weights,
means and full covariances by EM; :class:`WeightedGaussians` scores colours under the
fitted components.

The 3x3 algebra (Cholesky factor, triangular inverse, Mahalanobis distances) is written
in closed form with elementwise numpy operations only, so that the results are
bit-for-bit reproducible and independent of LAPACK/BLAS. Colours are RGB in ``0..255``;
internally samples are kept channel-major, ``xt`` of shape ``(3, N)``, and per-sample
quantities have shape ``(c, N)``.
"""

from __future__ import annotations

import math
import numbers
from typing import NamedTuple

import numpy as np

from vc_gym.validation import int_at_least

__all__ = [
    "COV_REG",
    "GaussianMixture",
    "WeightedGaussians",
    "cholesky3",
    "fit_gaussian_mixture",
]

#: Added to every fitted covariance (in ``(0..255)**2`` units) so that flat image regions
#: do not give singular covariances.
COV_REG = 1.0
#: Smallest weight a mixture component keeps; a component that loses all its samples is
#: kept with (about) this weight instead of producing a zero or NaN.
_MIN_WEIGHT = 1e-12
#: A component whose summed responsibility falls below this is "dead": its mean and
#: covariance are frozen at their previous values.
_DEAD_NK = 1e-3
#: Number of Lloyd (k-means) iterations after k-means++ seeding.
_KMEANS_ITER = 20


class GaussianMixture(NamedTuple):
    """A fitted mixture of ``c`` Gaussians in RGB.

    Attributes
    ----------
    weights : numpy.ndarray
        ``(c,)`` float64 mixture weights, positive, summing to 1.
    means : numpy.ndarray
        ``(c, 3)`` float64 component means.
    covariances : numpy.ndarray
        ``(c, 3, 3)`` float64 symmetric positive-definite covariances, each including
        :data:`COV_REG` on its diagonal.
    """

    weights: np.ndarray
    means: np.ndarray
    covariances: np.ndarray


# --------------------------------------------------------------------------------------
# Gaussian algebra, written with elementwise operations only (3x3, closed form)
# --------------------------------------------------------------------------------------


def cholesky3(cov: np.ndarray) -> np.ndarray | None:
    """Batched lower Cholesky factor of 3x3 matrices, in closed form.

    Parameters
    ----------
    cov : numpy.ndarray
        ``(c, 3, 3)`` float64 symmetric matrices (only the lower triangle is read).

    Returns
    -------
    numpy.ndarray or None
        ``(c, 3, 3)`` lower-triangular factors ``L`` with ``L @ L.T == cov``, or ``None``
        if any matrix is not positive definite (a pivot is not finite or not > 0).
    """
    a = cov
    with np.errstate(invalid="ignore", divide="ignore"):
        p0 = a[:, 0, 0]
        l00 = np.sqrt(p0)
        l10 = a[:, 1, 0] / l00
        l20 = a[:, 2, 0] / l00
        p1 = a[:, 1, 1] - l10 * l10
        l11 = np.sqrt(p1)
        l21 = (a[:, 2, 1] - l20 * l10) / l11
        p2 = a[:, 2, 2] - l20 * l20 - l21 * l21
        l22 = np.sqrt(p2)
    pivots = np.stack([p0, p1, p2], axis=1)
    if not np.all(np.isfinite(pivots)) or not np.all(pivots > 0):
        return None
    zero = np.zeros_like(l00)
    return np.stack(
        [
            np.stack([l00, zero, zero], axis=1),
            np.stack([l10, l11, zero], axis=1),
            np.stack([l20, l21, l22], axis=1),
        ],
        axis=1,
    )


def _tri_inv3(chol: np.ndarray) -> np.ndarray:
    """Batched inverse of lower-triangular ``(c, 3, 3)`` matrices (closed form)."""
    l00, l11, l22 = chol[:, 0, 0], chol[:, 1, 1], chol[:, 2, 2]
    l10, l20, l21 = chol[:, 1, 0], chol[:, 2, 0], chol[:, 2, 1]
    inv = np.zeros_like(chol)
    inv[:, 0, 0] = 1.0 / l00
    inv[:, 1, 1] = 1.0 / l11
    inv[:, 2, 2] = 1.0 / l22
    inv[:, 1, 0] = -l10 / (l00 * l11)
    inv[:, 2, 1] = -l21 / (l11 * l22)
    inv[:, 2, 0] = (l10 * l21 - l11 * l20) / (l00 * l11 * l22)
    return inv


class WeightedGaussians:
    """Weighted Gaussian components, ready to score colours.

    Precomputes what :meth:`weighted_log_density` needs to evaluate
    ``log w_k + log N(x | mu_k, Sigma_k)`` for every component ``k``.

    Parameters
    ----------
    means : numpy.ndarray
        ``(c, 3)`` float64 component means.
    chol : numpy.ndarray
        ``(c, 3, 3)`` lower Cholesky factors of the covariances (:func:`cholesky3`).
    weights : numpy.ndarray
        ``(c,)`` mixture weights; a zero weight scores ``-inf``.
    """

    def __init__(self, means: np.ndarray, chol: np.ndarray, weights: np.ndarray) -> None:
        self.means = means
        self.prec_chol = _tri_inv3(chol)  # L^-1, so maha = |L^-1 (x - mu)|^2
        half_logdet = np.log(chol[:, 0, 0]) + np.log(chol[:, 1, 1]) + np.log(chol[:, 2, 2])
        with np.errstate(divide="ignore"):
            log_w = np.log(weights)
        # constant term of log w_k + log N(x | mu_k, Sigma_k), without the 1.5 log 2 pi
        self.offset = log_w - half_logdet

    def weighted_log_density(self, xt: np.ndarray) -> np.ndarray:
        """Score every colour under every component.

        Component-major layout keeps every numpy inner loop ``N`` long (fast for small c).

        Parameters
        ----------
        xt : numpy.ndarray
            ``(3, N)`` float colours, channel-major.

        Returns
        -------
        numpy.ndarray
            ``(c, N)`` float64 ``log w_k + log N(x_n | mu_k, Sigma_k) + 1.5 log(2 pi)``:
            the log joint density up to a constant shared by all components, so its
            argmax over ``k`` is the most probable component.
        """
        m, a = self.means[:, :, None], self.prec_chol[:, :, :, None]
        d0 = xt[0] - m[:, 0]
        d1 = xt[1] - m[:, 1]
        d2 = xt[2] - m[:, 2]
        y0 = a[:, 0, 0] * d0
        y1 = a[:, 1, 0] * d0 + a[:, 1, 1] * d1
        y2 = a[:, 2, 0] * d0 + a[:, 2, 1] * d1 + a[:, 2, 2] * d2
        maha = y0 * y0 + y1 * y1 + y2 * y2
        return self.offset[:, None] - 0.5 * maha


# --------------------------------------------------------------------------------------
# fitting: k-means++ initialisation and EM for a full-covariance GMM. Samples are kept
# channel-major, ``xt`` of shape (3, N); per-sample quantities are (c, N).
# --------------------------------------------------------------------------------------


def _sq_dist(xt: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """Squared Euclidean distances ``(3, N) x (k, 3) -> (k, N)``."""
    d = xt[0] - centres[:, 0:1]
    out = d * d
    for j in (1, 2):
        d = xt[j] - centres[:, j : j + 1]
        out += d * d
    return out


def _kmeans_pp(xt: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """k-means++ seeding followed by a few Lloyd iterations; returns ``(k, 3)`` centres."""
    n = xt.shape[1]
    centres = np.empty((k, 3))
    centres[0] = xt[:, rng.integers(n)]
    closest = _sq_dist(xt, centres[0:1])[0]
    for i in range(1, k):
        total = closest.sum()
        if total > 0:
            idx = rng.choice(n, p=closest / total)
        else:  # every sample already coincides with a centre (few distinct colours)
            idx = rng.integers(n)
        centres[i] = xt[:, idx]
        np.minimum(closest, _sq_dist(xt, centres[i : i + 1])[0], out=closest)
    for _ in range(_KMEANS_ITER):
        labels = np.argmin(_sq_dist(xt, centres), axis=0)
        counts = np.bincount(labels, minlength=k)
        sums = np.stack([np.bincount(labels, weights=xt[j], minlength=k) for j in range(3)], 1)
        alive = counts > 0
        new = centres.copy()  # an empty cluster keeps its centre
        new[alive] = sums[alive] / counts[alive, None]
        if np.array_equal(new, centres):
            break
        centres = new
    return centres


def _m_step(
    xt: np.ndarray, resp: np.ndarray, old_means: np.ndarray, old_covs: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights, means and regularised covariances from responsibilities ``(c, N)``.

    A component with (almost) no responsibility keeps ``old_means``/``old_covs``.
    """
    c, n = resp.shape
    nk = resp.sum(axis=1)
    dead = nk < _DEAD_NK
    safe_nk = np.where(dead, 1.0, nk)
    means = (resp @ xt.T) / safe_nk[:, None]
    covs = np.empty((c, 3, 3))
    d = [xt[j] - means[:, j : j + 1] for j in range(3)]
    rd = [resp * dj for dj in d]
    for i in range(3):
        for j in range(i + 1):
            v = np.einsum("kn,kn->k", rd[i], d[j]) / safe_nk
            covs[:, i, j] = v
            covs[:, j, i] = v
    covs[:, [0, 1, 2], [0, 1, 2]] += COV_REG
    means[dead] = old_means[dead]
    covs[dead] = old_covs[dead]
    weights = np.maximum(nk / n, _MIN_WEIGHT)
    weights /= weights.sum()
    return weights, means, covs


def _logsumexp_cols(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Log-sum-exp over components of ``(c, N)`` and the normalised responsibilities."""
    amax = a.max(axis=0)
    e = np.exp(a - amax)
    s = e.sum(axis=0)
    return np.log(s) + amax, e / s


def _em(
    xt: np.ndarray, k: int, rng: np.random.Generator, max_iter: int, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """k-means++ centres, a hard-assignment M-step, then EM; ``(weights, means, covs)``."""
    centres = _kmeans_pp(xt, k, rng)
    labels = np.argmin(_sq_dist(xt, centres), axis=0)
    n = xt.shape[1]
    resp = np.zeros((k, n))
    resp[labels, np.arange(n)] = 1.0
    weights, means, covs = _m_step(
        xt, resp, centres, np.broadcast_to(COV_REG * np.eye(3), (k, 3, 3))
    )
    prev_ll = -np.inf
    for _ in range(max_iter):
        chol = cholesky3(covs)
        if chol is None:  # cannot happen with the regularisation; guard against NaN anyway
            raise FloatingPointError("covariance lost positive definiteness during EM")
        log_prob = WeightedGaussians(means, chol, weights).weighted_log_density(xt)
        log_norm, resp = _logsumexp_cols(log_prob)
        ll = float(log_norm.mean())
        weights, means, covs = _m_step(xt, resp, means, covs)
        if abs(ll - prev_ll) < tol:
            break
        prev_ll = ll
    return weights, means, covs


# --------------------------------------------------------------------------------------
# public entry point
# --------------------------------------------------------------------------------------


def fit_gaussian_mixture(
    samples: np.ndarray,
    n_components: int,
    *,
    rng: np.random.Generator,
    max_iter: int = 100,
    tol: float = 1e-4,
) -> GaussianMixture:
    """Fit a full-covariance Gaussian mixture to colours with EM.

    The components are seeded with k-means++ (the first centre uniformly, each next one
    with probability proportional to its squared distance to the nearest centre so far)
    followed by at most 20 Lloyd iterations; an empty cluster keeps its centre. EM then
    alternates responsibilities and weighted means and covariances, adding
    :data:`COV_REG` ``* I`` to every covariance so that flat colours do not make it
    singular. A component whose summed responsibility falls below ``1e-3`` keeps its
    previous mean and covariance and a weight of about ``1e-12``. Every operation and
    random draw happens in a fixed order, so the result is the same for the same
    samples and generator state.

    Parameters
    ----------
    samples : numpy.ndarray
        ``(N, 3)`` real colours (e.g. uint8 RGB pixels), ``N >= 1``, all finite. ``N``
        may be smaller than ``n_components``; components then share colours.
    n_components : int
        Number of components ``c >= 1``.
    rng : numpy.random.Generator
        Source of the k-means++ draws.
    max_iter : int
        Largest number of EM iterations, ``>= 1``.
    tol : float
        EM stops when the mean per-sample log-likelihood changes by less than this
        (finite, ``>= 0``).

    Returns
    -------
    GaussianMixture
        Weights, means and covariances of the ``c`` components, in the order of their
        k-means++ seeds.

    Raises
    ------
    ValueError
        If ``samples`` is not an ``(N, 3)`` finite real array with ``N >= 1``, or any
        other argument is invalid.
    FloatingPointError
        If a covariance loses positive definiteness during EM (the regularisation
        prevents it for finite samples).
    """
    arr = np.asarray(samples)
    if arr.ndim != 2 or arr.shape[1] != 3 or arr.shape[0] < 1:
        raise ValueError(f"samples must have shape (N, 3) with N >= 1, got {arr.shape}")
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"samples must be a real numeric array, got dtype {arr.dtype}")
    if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
        raise ValueError("samples must contain only finite values")
    n_components = int_at_least("n_components", n_components, 1)
    max_iter = int_at_least("max_iter", max_iter, 1)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {rng!r}")
    if isinstance(tol, bool) or not isinstance(tol, numbers.Real):
        raise ValueError(f"tol must be a real number, got {tol!r}")
    if not (math.isfinite(float(tol)) and tol >= 0):
        raise ValueError(f"tol must be finite and >= 0, got {tol!r}")
    xt = np.ascontiguousarray(arr.T, dtype=np.float64)
    weights, means, covs = _em(xt, n_components, rng, max_iter, float(tol))
    return GaussianMixture(weights, means, covs)
