"""Colour classes of the visual compass: a Gaussian mixture over RGB and its lookup table.

Sturm & Visser (section 3.4) reduce every pixel to one of ``c`` colour classes before
building the compass signature. The classes are learned by clustering colour space with
expectation-maximisation (EM) on a Gaussian mixture model
(:mod:`vc_gym.compass.color_mixture`); afterwards a pixel is classified with a single
read of a lookup table over quantised colour.

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

from vc_gym.compass.color_mixture import WeightedGaussians, cholesky3, fit_gaussian_mixture
from vc_gym.images import check_image

__all__ = ["ColorClasses", "MAX_COLOR_VARIANCE", "MAX_LIGHT_LEVEL", "MIN_COLOR_VARIANCE"]

#: Smallest pivot of a class covariance's Cholesky factor (its variance along each axis
#: given the ones before, ``(0..255)**2`` units). Fitted classes have at least
#: :data:`~vc_gym.compass.color_mixture.COV_REG`; far below, the closed-form inverse
#: overflows and the lookup table comes out of NaNs.
MIN_COLOR_VARIANCE = 1e-3
#: Largest variance of a class along a channel: a standard deviation of the whole
#: colour range (fitted classes stay below ``127.5**2 + COV_REG``).
MAX_COLOR_VARIANCE = 255.0**2
#: Range of a class mean, per channel: the colour range of a ``uint8`` image (a mean
#: outside it only takes colours away from the other classes), give or take rounding
#: (a fitted mean is a weighted average of pixel values).
_COLOR_RANGE = (0.0, 255.0)
_COLOR_RANGE_SLACK = 1e-6
#: Largest mean linear light level (:func:`vc_gym.exposure.mean_linear_level`, 1 for a
#: white frame), give or take the rounding of a float32 mean.
MAX_LIGHT_LEVEL = 1.0 + 1e-6
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
        chol = cholesky3(cov)
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
        self.lut = self._build_lut(WeightedGaussians(mu, chol, w))
        for arr in (self.means, self.covariances, self.weights, self.lut):
            arr.setflags(write=False)
        self._shift = 8 - self.bits

    def _build_lut(self, gauss: WeightedGaussians) -> np.ndarray:
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
        mixture = fit_gaussian_mixture(pixels, n_colors, rng=rng, max_iter=max_iter, tol=tol)

        means = mixture.means
        luma = means @ _LUMA
        order = np.lexsort((means[:, 2], means[:, 1], means[:, 0], luma))
        return cls(means[order], mixture.covariances[order], mixture.weights[order], bits=bits)

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
        ref = arrays.get(_PREFIX + "exposure_reference")  # optional: without it, no reference (0)
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
