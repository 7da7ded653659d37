"""Colour classes of the visual compass: a Gaussian mixture over RGB and its lookup table.

Sturm & Visser (section 3.4) reduce every pixel to one of ``c`` colour classes before
building the compass signature. The classes are learned by clustering colour space with
expectation-maximisation (EM) on a Gaussian mixture model; afterwards a pixel is
classified with a single read of a lookup table over quantised colour.

Conventions: colours are RGB in ``0..255``; images are ``uint8`` arrays of shape
``(H, W, 3)`` (see :func:`vc_gym.images.check_image`). The lookup table has
``2**(3 * bits)`` entries, one per quantised colour, indexed as
``(r >> s) << 2 * bits | (g >> s) << bits | (b >> s)`` with ``s = 8 - bits``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping, Sequence

import numpy as np

from vc_gym.images import check_image

__all__ = ["ColorClasses", "MAX_COLOR_VARIANCE", "MAX_LIGHT_LEVEL", "MIN_COLOR_VARIANCE"]

#: Added to every covariance (in ``(0..255)**2`` units) so that flat image regions do not
#: give singular covariances.
_COV_REG = 1.0
#: Smallest pivot of a class covariance's Cholesky factor (its variance along each axis
#: given the ones before, ``(0..255)**2`` units). Fitted classes have at least
#: ``_COV_REG``; far below, the closed-form inverse overflows and the lookup table
#: comes out of NaNs.
MIN_COLOR_VARIANCE = 1e-3
#: Largest variance of a class along a channel: a standard deviation of the whole
#: colour range (fitted classes stay below ``127.5**2 + _COV_REG``).
MAX_COLOR_VARIANCE = 255.0**2
#: Range of a class mean, per channel: the colour range of a ``uint8`` image (a mean
#: outside it only takes colours away from the other classes), give or take rounding
#: (a fitted mean is a weighted average of pixel values).
_COLOR_RANGE = (0.0, 255.0)
_COLOR_RANGE_SLACK = 1e-6
#: Largest mean linear light level (:func:`vc_gym.exposure.mean_linear_level`, 1 for a
#: white frame), give or take the rounding of a float32 mean.
MAX_LIGHT_LEVEL = 1.0 + 1e-6
#: Smallest weight a mixture component keeps; a component that loses all its samples is
#: kept with (about) this weight instead of producing a zero or NaN.
_MIN_WEIGHT = 1e-12
#: A component whose summed responsibility falls below this is "dead": its mean and
#: covariance are frozen at their previous values.
_DEAD_NK = 1e-3
#: Number of Lloyd (k-means) iterations after k-means++ seeding.
_KMEANS_ITER = 20
#: Cells times components evaluated per chunk when building the LUT (cache-sized).
_LUT_CHUNK_ELEMS = 1 << 16
#: Luminance weights (ITU-R BT.601) used to order the classes.
_LUMA = np.array([0.299, 0.587, 0.114])
_KEYS = ("means", "covariances", "weights", "bits", "n_colors")
_PREFIX = "colors_"


# --------------------------------------------------------------------------------------
# small validation helpers
# --------------------------------------------------------------------------------------


def _int_param(name: str, value: object, lo: int, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an int, got {value!r}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        bound = f"{lo}..{hi}" if hi is not None else f">= {lo}"
        raise ValueError(f"{name} must be {bound}, got {v}")
    return v


def _real_array(name: str, value: object, shape: tuple[int | None, ...]) -> np.ndarray:
    """``value`` as a finite float64 array whose shape matches ``shape`` (None = any)."""
    try:
        arr = np.asarray(value)
    except Exception as exc:  # pragma: no cover - exotic array-likes
        raise ValueError(f"{name} could not be converted to an array: {exc}") from None
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"{name} must be a real numeric array, got dtype {arr.dtype}")
    if arr.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(arr.shape, shape, strict=False)
    ):
        want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name} must have shape {want}, got {arr.shape}")
    arr = arr.astype(np.float64)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must contain only finite values")
    return arr


def _int_scalar(name: str, value: object) -> int:
    arr = np.asarray(value)
    if arr.ndim != 0 or arr.dtype.kind not in "iu":
        raise ValueError(
            f"{name} must be a 0-d integer array, got dtype {arr.dtype} and shape {arr.shape}"
        )
    return int(arr)


# --------------------------------------------------------------------------------------
# Gaussian algebra, written with elementwise operations only (3x3, closed form) so that
# the results are bit-for-bit reproducible and independent of LAPACK/BLAS
# --------------------------------------------------------------------------------------


def _cholesky3(cov: np.ndarray) -> np.ndarray | None:
    """Batched lower Cholesky factor of ``(c, 3, 3)`` matrices, or None if not PD."""
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


class _Gaussians:
    """Precomputed quantities for evaluating ``log w_k + log N(x | mu_k, Sigma_k)``."""

    def __init__(self, means: np.ndarray, chol: np.ndarray, weights: np.ndarray) -> None:
        self.means = means
        self.prec_chol = _tri_inv3(chol)  # L^-1, so maha = |L^-1 (x - mu)|^2
        half_logdet = np.log(chol[:, 0, 0]) + np.log(chol[:, 1, 1]) + np.log(chol[:, 2, 2])
        with np.errstate(divide="ignore"):
            log_w = np.log(weights)
        # constant term of log w_k + log N(x | mu_k, Sigma_k), without the 1.5 log 2 pi
        self.offset = log_w - half_logdet

    def weighted_log_density(self, xt: np.ndarray) -> np.ndarray:
        """``(3, N)`` float colours -> ``(c, N)`` of ``log w_k + log N(x_n | k) + 1.5 log 2pi``.

        Component-major layout keeps every numpy inner loop ``N`` long (fast for small c).
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
    covs[:, [0, 1, 2], [0, 1, 2]] += _COV_REG
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
    centres = _kmeans_pp(xt, k, rng)
    labels = np.argmin(_sq_dist(xt, centres), axis=0)
    n = xt.shape[1]
    resp = np.zeros((k, n))
    resp[labels, np.arange(n)] = 1.0
    weights, means, covs = _m_step(
        xt, resp, centres, np.broadcast_to(_COV_REG * np.eye(3), (k, 3, 3))
    )
    prev_ll = -np.inf
    for _ in range(max_iter):
        chol = _cholesky3(covs)
        if chol is None:  # cannot happen with the regularisation; guard against NaN anyway
            raise FloatingPointError("covariance lost positive definiteness during EM")
        log_prob = _Gaussians(means, chol, weights).weighted_log_density(xt)
        log_norm, resp = _logsumexp_cols(log_prob)
        ll = float(log_norm.mean())
        weights, means, covs = _m_step(xt, resp, means, covs)
        if abs(ll - prev_ll) < tol:
            break
        prev_ll = ll
    return weights, means, covs


# --------------------------------------------------------------------------------------
# public class
# --------------------------------------------------------------------------------------


class ColorClasses:
    """Learned colour classes of the visual compass and their lookup table.

    This implements the function ``g`` of paper section 3.4 (eq. 7-8), which maps a
    colour to its colour class. As in the paper, the classes are found by clustering
    colour space with expectation-maximisation on a Gaussian mixture model
    (:meth:`fit`); a colour belongs to the component with the largest posterior,
    ``argmax_k log w_k + log N(x | mu_k, Sigma_k)``. That decision is precomputed for
    the centre ``(q + 0.5) * 2**(8 - bits)`` of every quantised colour cell, so
    classifying a pixel costs one table read (:meth:`classify_pixels`).

    Parameters
    ----------
    means : array_like, shape (c, 3)
        Component means, RGB in ``[0, 255]``; ``1 <= c <= 255``.
    covariances : array_like, shape (c, 3, 3)
        Symmetric positive-definite component covariances (``(0..255)**2`` units):
        variances at most :data:`MAX_COLOR_VARIANCE`, Cholesky pivots at least
        :data:`MIN_COLOR_VARIANCE`.
    weights : array_like, shape (c,)
        Non-negative mixture weights summing to 1 (renormalised exactly).
    bits : int
        Quantisation bits per channel of the lookup table, ``3..7``; the table has
        ``2**(3 * bits)`` entries.

    Attributes
    ----------
    n_colors : int
        Number of classes ``c``.
    bits : int
        Quantisation bits per channel of the lookup table.
    means : numpy.ndarray
        ``(c, 3)`` float64, read-only.
    covariances : numpy.ndarray
        ``(c, 3, 3)`` float64, read-only.
    weights : numpy.ndarray
        ``(c,)`` float64 summing to 1, read-only.
    lut : numpy.ndarray
        ``(2**(3 * bits),)`` uint8 class id of every quantised colour, read-only. It is
        rebuilt deterministically from the mixture parameters (closed-form 3x3
        algebra, no BLAS/LAPACK), so it never needs to be stored.

    Raises
    ------
    ValueError
        If any parameter has the wrong type, shape or value.
    """

    n_colors: int
    bits: int
    means: np.ndarray
    covariances: np.ndarray
    weights: np.ndarray
    lut: np.ndarray

    def __init__(
        self,
        means: np.ndarray,
        covariances: np.ndarray,
        weights: np.ndarray,
        bits: int = 5,
    ) -> None:
        self._init(means, covariances, weights, bits, prefix="")

    def _init(
        self, means: object, covariances: object, weights: object, bits: object, prefix: str
    ) -> None:
        """Validate the parameters (error messages use ``prefix + name``) and build the LUT."""
        self.bits = _int_param(prefix + "bits", bits, 3, 7)
        mu = _real_array(prefix + "means", means, (None, 3))
        c = mu.shape[0]
        if not 1 <= c <= 255:
            raise ValueError(f"{prefix}means must have 1..255 rows (classes), got {c}")
        lo, hi = _COLOR_RANGE
        if np.any(mu < lo - _COLOR_RANGE_SLACK) or np.any(mu > hi + _COLOR_RANGE_SLACK):
            raise ValueError(
                f"{prefix}means must lie in the colour range [{lo:g}, {hi:g}], got values "
                f"{mu.min():g}..{mu.max():g}"
            )
        cov = _real_array(prefix + "covariances", covariances, (c, 3, 3))
        scale = max(1.0, float(np.abs(cov).max()))
        if not np.allclose(cov, cov.transpose(0, 2, 1), rtol=1e-9, atol=1e-9 * scale):
            raise ValueError(f"{prefix}covariances must be symmetric")
        cov = 0.5 * (cov + cov.transpose(0, 2, 1))
        chol = _cholesky3(cov)
        if chol is None:
            raise ValueError(f"{prefix}covariances must be positive definite")
        pivots = chol[:, [0, 1, 2], [0, 1, 2]] ** 2
        if np.any(pivots < MIN_COLOR_VARIANCE):
            raise ValueError(
                f"{prefix}covariances must have Cholesky pivots >= {MIN_COLOR_VARIANCE:g} "
                f"(nearly singular), got {pivots.min():g}"
            )
        variances = cov[:, [0, 1, 2], [0, 1, 2]]
        if np.any(variances > MAX_COLOR_VARIANCE):
            raise ValueError(
                f"{prefix}covariances must have variances <= {MAX_COLOR_VARIANCE:g} "
                f"(a standard deviation of the whole colour range), got {variances.max():g}"
            )
        w = _real_array(prefix + "weights", weights, (c,))
        if np.any(w < 0):
            raise ValueError(f"{prefix}weights must be non-negative")
        if abs(float(w.sum()) - 1.0) > 1e-6:
            raise ValueError(f"{prefix}weights must sum to 1, got {float(w.sum())!r}")
        w = w / w.sum()

        self.n_colors = c
        #: Mean linear light level of the images the classes were fitted on, when they
        #: were fitted with exposure normalisation (0: not); every compass sharing
        #: these classes scales its frames to this level.
        self.exposure_reference = 0.0
        self.means = mu
        self.covariances = cov
        self.weights = w
        self.lut = self._build_lut(_Gaussians(mu, chol, w))
        for arr in (self.means, self.covariances, self.weights, self.lut):
            arr.setflags(write=False)
        self._shift = 8 - self.bits

    def _build_lut(self, gauss: _Gaussians) -> np.ndarray:
        bits = self.bits
        n_side = 1 << bits
        centres_1d = (np.arange(n_side) + 0.5) * float(1 << (8 - bits))
        r, g, b = np.meshgrid(centres_1d, centres_1d, centres_1d, indexing="ij")
        cells = np.stack([r.ravel(), g.ravel(), b.ravel()])  # (3, M), index order r, g, b
        lut = np.empty(cells.shape[1], dtype=np.uint8)
        chunk = max(1, _LUT_CHUNK_ELEMS // self.n_colors)
        for start in range(0, cells.shape[1], chunk):
            stop = start + chunk
            scores = gauss.weighted_log_density(cells[:, start:stop])
            lut[start:stop] = np.argmax(scores, axis=0)
        return lut

    # ---------------------------------------------------------------- learning

    @classmethod
    def fit(
        cls,
        images: Sequence[np.ndarray],
        n_colors: int = 10,
        *,
        rng: np.random.Generator | None = None,
        max_samples: int = 20000,
        bits: int = 5,
        max_iter: int = 100,
        tol: float = 1e-4,
    ) -> ColorClasses:
        """Learn ``n_colors`` colour classes from images with EM on a Gaussian mixture.

        The pixels of all images are pooled and at most ``max_samples`` of them are drawn
        without replacement. The mixture is initialised with k-means++ seeding plus a few
        Lloyd iterations and refined by EM with full covariances; ``1.0 * I`` is added to
        every covariance so that flat colours do not make it singular. A component that
        loses all its samples keeps its previous mean and covariance with a tiny weight.
        Classes are sorted by mean luminance (then R, G, B) so that class ids are stable.

        Parameters
        ----------
        images : sequence of numpy.ndarray
            Non-empty sequence of ``(H, W, 3)`` uint8 RGB images.
        n_colors : int
            Number of classes, ``1..255``.
        rng : numpy.random.Generator or None
            Source of randomness (subsampling and seeding); ``None`` means
            ``numpy.random.default_rng(0)``. The result is deterministic for a given seed.
        max_samples : int
            Largest number of pixels used for fitting, ``>= n_colors``.
        bits : int
            Quantisation bits per channel of the lookup table, ``3..7``.
        max_iter : int
            Largest number of EM iterations, ``>= 1``.
        tol : float
            EM stops when the mean per-sample log-likelihood changes by less than this.

        Returns
        -------
        ColorClasses
            The fitted classes.

        Raises
        ------
        ValueError
            On an empty ``images``, an invalid image (the message names its index) or an
            invalid parameter.
        """
        n_colors = _int_param("n_colors", n_colors, 1, 255)
        bits = _int_param("bits", bits, 3, 7)
        max_samples = _int_param("max_samples", max_samples, n_colors)
        max_iter = _int_param("max_iter", max_iter, 1)
        if isinstance(tol, bool) or not isinstance(tol, numbers.Real):
            raise ValueError(f"tol must be a real number, got {tol!r}")
        if not (math.isfinite(float(tol)) and tol >= 0):
            raise ValueError(f"tol must be finite and >= 0, got {tol!r}")
        if rng is None:
            rng = np.random.default_rng(0)
        elif not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator or None, got {rng!r}")
        if isinstance(images, np.ndarray) and images.ndim == 3:
            raise ValueError(
                "images must be a sequence of (H, W, 3) images; wrap a single image in a list"
            )
        try:
            images = list(images)
        except TypeError:
            raise ValueError(
                f"images must be a sequence of (H, W, 3) uint8 images, got {type(images).__name__}"
            ) from None
        if not images:
            raise ValueError("images must contain at least one image")
        checked = [check_image(im, f"images[{i}]", min_size=1) for i, im in enumerate(images)]
        pixels = np.concatenate([im.reshape(-1, 3) for im in checked])
        if pixels.shape[0] > max_samples:
            pixels = pixels[rng.choice(pixels.shape[0], size=max_samples, replace=False)]
        xt = np.ascontiguousarray(pixels.T, dtype=np.float64)

        weights, means, covs = _em(xt, n_colors, rng, max_iter, float(tol))

        luma = means @ _LUMA
        order = np.lexsort((means[:, 2], means[:, 1], means[:, 0], luma))
        return cls(means[order], covs[order], weights[order], bits=bits)

    # ---------------------------------------------------------------- classification

    def lut_index(self, pixels: np.ndarray) -> np.ndarray:
        """Lookup-table index of every pixel.

        Parameters
        ----------
        pixels : numpy.ndarray
            ``(..., 3)`` uint8 RGB.

        Returns
        -------
        numpy.ndarray
            ``(...)`` intp, ``(r >> s) << 2*bits | (g >> s) << bits | (b >> s)`` with
            ``s = 8 - bits``, in ``[0, 2**(3*bits))``.
        """
        if not isinstance(pixels, np.ndarray) or pixels.dtype != np.uint8:
            raise ValueError(_pixels_error(pixels))
        if pixels.shape[-1:] != (3,):
            raise ValueError(_pixels_error(pixels))
        q = pixels >> self._shift
        r = q[..., 0].astype(np.intp) << (2 * self.bits)
        return r | (q[..., 1].astype(np.intp) << self.bits) | q[..., 2]

    def classify_pixels(self, pixels: np.ndarray) -> np.ndarray:
        """Class id of every pixel with one table read (fast path, minimal validation).

        Parameters
        ----------
        pixels : numpy.ndarray
            ``(..., 3)`` uint8 RGB; only dtype and last dimension are checked.

        Returns
        -------
        numpy.ndarray
            ``(...)`` uint8 class ids in ``0..n_colors-1``.
        """
        return self.lut[self.lut_index(pixels)]

    def classify(self, image: np.ndarray) -> np.ndarray:
        """Class id of every pixel of a validated ``(H, W, 3)`` uint8 RGB image.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` uint8 RGB image.

        Returns
        -------
        numpy.ndarray
            ``(H, W)`` uint8 class ids.
        """
        return self.classify_pixels(check_image(image, min_size=1))

    # ---------------------------------------------------------------- persistence

    def to_arrays(self) -> dict[str, np.ndarray]:
        """Mixture parameters as plain arrays for :func:`numpy.savez`.

        Keys are ``colors_means``, ``colors_covariances``, ``colors_weights``,
        ``colors_bits`` and ``colors_n_colors`` (the last two 0-d int64). The lookup table
        is not stored; :meth:`from_arrays` rebuilds it.
        """
        return {
            _PREFIX + "means": self.means.copy(),
            _PREFIX + "covariances": self.covariances.copy(),
            _PREFIX + "weights": self.weights.copy(),
            _PREFIX + "bits": np.array(self.bits, dtype=np.int64),
            _PREFIX + "n_colors": np.array(self.n_colors, dtype=np.int64),
            _PREFIX + "exposure_reference": np.array(self.exposure_reference, dtype=np.float64),
        }

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> ColorClasses:
        """Rebuild from the output of :meth:`to_arrays` (e.g. an ``np.load`` npz file).

        Every array is validated (presence, shape, dtype, finiteness); extra keys are
        ignored. The lookup table is rebuilt from the mixture parameters.

        Raises
        ------
        ValueError
            Naming the offending key.
        """
        missing = [_PREFIX + k for k in _KEYS if _PREFIX + k not in arrays]
        if missing:
            raise ValueError(f"missing key(s) {', '.join(missing)} in colour-class arrays")
        bits = _int_scalar(_PREFIX + "bits", arrays[_PREFIX + "bits"])
        n_colors = _int_scalar(_PREFIX + "n_colors", arrays[_PREFIX + "n_colors"])
        if not 1 <= n_colors <= 255:
            raise ValueError(f"{_PREFIX}n_colors must be 1..255, got {n_colors}")
        means = _real_array(_PREFIX + "means", arrays[_PREFIX + "means"], (n_colors, 3))
        obj = cls.__new__(cls)
        obj._init(
            means,
            arrays[_PREFIX + "covariances"],
            arrays[_PREFIX + "weights"],
            bits,
            prefix=_PREFIX,
        )
        ref = arrays.get(_PREFIX + "exposure_reference")  # absent in older files
        if ref is not None:
            ref = _real_array(_PREFIX + "exposure_reference", ref, ())
            if not 0 <= ref <= MAX_LIGHT_LEVEL:
                # a mean linear light level: 0 (not fitted with exposure) to 1 (white)
                raise ValueError(f"{_PREFIX}exposure_reference must be in [0, 1], got {float(ref)}")
            obj.exposure_reference = float(ref)
        return obj

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n_colors={self.n_colors}, bits={self.bits})"


def _pixels_error(pixels: object) -> str:
    if not isinstance(pixels, np.ndarray):
        return f"pixels must be a numpy.ndarray of shape (..., 3), got {type(pixels).__name__}"
    return (
        f"pixels must be uint8 with shape (..., 3), got dtype {pixels.dtype} shape {pixels.shape}"
    )
