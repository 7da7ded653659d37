"""Rotational image difference compass (Zeil, Hofmann & Chahl 2003; Labrosse 2006).

The learned views are kept as one panoramic colour strip over world azimuth. A new
frame is compared with that strip at every heading at once: the mean squared colour
difference between the frame's strip and the panorama turned by the heading (the
*rotational image difference function*) comes from masked circular
cross-correlations along azimuth, computed with FFTs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from vc_gym.angles import wrap360
from vc_gym.compass import Camera
from vc_gym.heading_sensors.base import BaselineCompass, FrameScore
from vc_gym.heading_sensors.strip import StripGrid, angular_strip, strip_offsets
from vc_gym.validation import finite_real, positive_float, positive_float_at_most

__all__ = ["ImageDifferenceCompass", "NORMALIZATIONS"]

#: Photometric normalisations of a strip (see :class:`ImageDifferenceCompass`).
NORMALIZATIONS = ("mean", "none", "local")
#: Largest noise (a multiple of the learned panorama's mean level).
MAX_NOISE_STD = 1e3
#: A mean intensity below this many grey levels is black: it is not divided by.
_DARK = 1e-3
# Rows of the per-row spectra stack: m, m |v|^2, m v_r, m v_g, m v_b (v = q or P).
_M, _M2, _RGB = 0, 1, slice(2, 5)


class ImageDifferenceCompass(BaselineCompass):
    """Heading from the rotational image difference of a frame and a learned panorama.

    The visual compass of Zeil, Hofmann & Chahl (2003, "Catchment areas of panoramic
    snapshots in outdoor scenes", J. Opt. Soc. Am. A 20(3)) and Labrosse (2006, "The
    visual compass: performance and limitations of an appearance-based method",
    J. Field Robotics 23(10)): the heading of a view is the rotation at which it
    differs least, direction by direction, from the views learned at the spot.

    Parameters
    ----------
    heading_step_deg : float
        Step of the heading grid, which is also the azimuth step of the learned
        panorama (degrees); must divide 360 and be at most 45.
    el_min_deg, el_max_deg : float
        Elevation band of the strips (degrees, positive up), ``-90 < min < max < 90``.
    el_step_deg : float
        Elevation step of the strips (degrees).
    normalize : {"mean", "none", "local"}
        Photometric normalisation. ``"none"``: raw RGB values (0-255), as Labrosse.
        ``"mean"``: every strip, learned or queried, is divided by its mean intensity
        over its valid samples before use, so that a dimmer or brighter frame of the
        same place still matches. ``"local"``: frames are learned raw; at every heading
        the frame and the panorama are each divided by their mean intensity over the
        samples they share (two more correlations), so that the gain is judged on the
        directions actually compared, not on a whole frame whose other parts may be
        brighter or darker (a narrow crop, a partly learned view).
    noise_std : float
        ``sigma`` of the Gaussian model (see Notes), relative to the mean intensity of
        the learned panorama, so that one value serves every normalisation.
    min_overlap : float
        Headings at which the frame shares fewer than this fraction of its valid
        samples with the learned panorama are not trusted (see Notes); in ``(0, 1]``.

    Notes
    -----
    **Map.** Per (elevation, azimuth bin) the sum of the learned colour values and the
    number of learned frames that saw the direction; the panorama ``P`` is their mean
    and directions no frame saw are masked. A frame learned with yaw ``Y`` is resampled
    (:func:`~vc_gym.heading_sensors.strip.angular_strip`) exactly at the world azimuth bins
    in its view, at offsets ``k - Y / step`` from its optical axis.

    **Image difference.** A frame's strip ``q(j)`` is sampled at whole offsets ``j``
    (bins, left positive) from its own optical axis; at heading ``h`` (in bins),
    ``SSD(h) = sum |q(j) - P(h + j)|^2`` over the samples valid in both, over elevation
    rows and colour channels, and ``MSD(h) = SSD(h) / overlap(h)`` is the mean squared
    difference per sample and channel. All headings come at once from masked circular
    cross-correlations along azimuth (``sum m_q q^2 m_P``, ``sum m_q m_P P^2``,
    ``sum m_q q m_P P`` and the overlap ``sum m_q m_P``) computed with real FFTs over
    the 360° of the panorama; the panorama's spectra are cached until the next
    :meth:`learn`. Headings where ``overlap(h) < min_overlap`` times the frame's valid
    samples (the frame would look mostly at directions never learned) get the worst
    MSD of the well-overlapped headings: they never win and are not ruled out either.

    **Log-likelihood.** A Gaussian model of the per-sample difference at the true
    heading: ``ll(h) = -n_eff * MSD(h) / (2 sigma^2)`` with
    ``sigma = noise_std * level`` (``level`` is the learned panorama's mean intensity:
    about 1 with ``"mean"``, grey levels with ``"none"``; 1 with ``"local"``, whose
    differences are already relative). ``n_eff`` is the number of azimuth columns the
    frame covers (:attr:`FrameScore.n_terms`), not its number of samples: the rows and
    channels of a column vary together, so counting every sample as an independent
    observation would make the posterior absurdly sharp. ``sigma`` is a tolerance for
    what changes a view at the spot (lighting, small moves, parallax, camera noise),
    not the resampling noise of the learned frames, which in simulation is almost
    nil: learned from a synthetic panorama, the differences between overlapping
    learned frames would give ``sigma`` ~0.01 and a posterior narrower than the
    heading grid. The default 0.45 gives a clear synthetic 57° view at the spot a
    posterior spread of a few degrees (median 1.7° in a synthetic room panorama, 2.4°
    in the ray-cast room, 6° outdoors) and keeps the spread honest for small moves: in
    the ray-cast room, 25-50 cm from where it learned, the heading error (parallax,
    3-5°) is within about twice the spread for 97 % of the views. Narrow crops of real
    photos (17 columns) get spreads of 10-60°.

    **Goodness.** ``-sqrt(min MSD)`` over the well-overlapped headings: minus the
    root-mean-square colour difference at the best heading (higher fits better), in
    the strip's units (relative to the mean intensity with ``"mean"`` and ``"local"``,
    grey levels with ``"none"``); comparable between maps with the same config.

    A frame that sees nothing of the elevation band, or that overlaps the learned
    panorama well at no heading, gets a flat (all-zero) log-likelihood and goodness
    ``-inf``.

    Examples
    --------
    >>> compass = ImageDifferenceCompass()                            # doctest: +SKIP
    >>> for image, yaw in training:                                   # doctest: +SKIP
    ...     compass.learn(image, Camera(yaw_deg=yaw))
    >>> compass.estimate(new_image, Camera()).heading_deg             # doctest: +SKIP
    """

    schema: ClassVar[str] = "vc_gym.ImageDifferenceCompass"
    name: ClassVar[str] = "image_difference"

    def __init__(
        self,
        heading_step_deg: float = 1.0,
        el_min_deg: float = -20.0,
        el_max_deg: float = 20.0,
        el_step_deg: float = 2.0,
        normalize: str = "mean",
        noise_std: float = 0.45,
        min_overlap: float = 0.5,
    ):
        super().__init__(heading_step_deg)
        if self.heading_step_deg > 45.0:
            raise ValueError(
                f"heading_step_deg must be <= 45 (it is the panorama's azimuth step), "
                f"got {self.heading_step_deg}"
            )
        lo = finite_real("el_min_deg", el_min_deg)
        hi = finite_real("el_max_deg", el_max_deg)
        step = positive_float("el_step_deg", el_step_deg)
        self._grid = StripGrid(self.heading_step_deg, lo, hi, step)  # bounds the rows too
        if not isinstance(normalize, str) or normalize not in NORMALIZATIONS:
            raise ValueError(f"normalize must be one of {NORMALIZATIONS}, got {normalize!r}")
        self.normalize = normalize
        # bounded: a saved sensor's noise of 1e300 would flatten every likelihood silently
        self.noise_std = positive_float_at_most("noise_std", noise_std, MAX_NOISE_STD)
        overlap = finite_real("min_overlap", min_overlap)
        if not 0.0 < overlap <= 1.0:
            raise ValueError(f"min_overlap must be in (0, 1], got {min_overlap!r}")
        self.min_overlap = overlap
        n_el, n_az = self._grid.elevations_deg.size, self._grid.n_azimuths
        self._sum = np.zeros((n_el, n_az, 3), dtype=np.float64)
        self._count = np.zeros((n_el, n_az), dtype=np.int64)
        self._spectra: tuple[np.ndarray, float] | None = None

    # ------------------------------------------------------------------ properties
    @property
    def grid(self) -> StripGrid:
        """The directions of the strips (azimuth step = :attr:`heading_step_deg`)."""
        return self._grid

    @property
    def panorama(self) -> tuple[np.ndarray, np.ndarray]:
        """The learned panorama and its mask (copies).

        Returns
        -------
        colors : numpy.ndarray
            ``(n_elevations, n_azimuths, 3)`` mean of the learned (normalised) strips;
            column ``k`` looks at world azimuth ``k * heading_step_deg``, row ``i`` at
            ``grid.elevations_deg[i]``; 0 where masked.
        valid : numpy.ndarray
            ``(n_elevations, n_azimuths)`` bool: some learned frame saw the direction.
        """
        valid = self._count > 0
        colors = np.zeros_like(self._sum)
        colors[valid] = self._sum[valid] / self._count[valid, None]
        return colors, valid

    @property
    def learned_fraction(self) -> float:
        """Fraction of the azimuth bins that some learned frame saw (at any elevation)."""
        return float(np.mean(np.any(self._count > 0, axis=0)))

    # ------------------------------------------------------------------ strips
    def _strip(
        self, image: np.ndarray, camera: Camera, offsets: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The frame's strip at ``offsets`` (float64, 0 where masked, normalised with
        ``"mean"``) and its validity mask."""
        strip, valid, _ = angular_strip(image, camera, self._grid, offsets)
        strip = strip.astype(np.float64)
        if self.normalize == "mean":
            n = int(np.count_nonzero(valid))
            level = float(strip.sum()) / (3.0 * n) if n else 0.0
            if level > _DARK:
                strip /= level
        return strip, valid

    def _offsets(self, camera: Camera, width: int) -> np.ndarray:
        """Whole azimuth offsets (bins) the camera can see, at most one per bin."""
        return strip_offsets(camera, width, self._grid)[: self._grid.n_azimuths]

    def _learn(self, image: np.ndarray, camera: Camera) -> None:
        step = self._grid.az_step_deg
        base = float(wrap360(camera.yaw_deg)) / step
        bins = int(round(base)) + self._offsets(camera, image.shape[1])
        # sample each world azimuth bin k at the (fractional) offset k - Y / step
        strip, valid = self._strip(image, camera, bins - base)
        cols = np.mod(bins, self._grid.n_azimuths)  # distinct
        self._sum[:, cols] += strip
        self._count[:, cols] += valid
        self._spectra = None

    # ------------------------------------------------------------------ scoring
    @staticmethod
    def _stack(values: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """``(n_el, 5, n)``: ``m``, ``m |v|^2`` and ``m v`` per channel (``v`` is 0
        where masked)."""
        out = np.empty((values.shape[0], 5, values.shape[1]))
        out[:, _M] = valid
        out[:, _M2] = np.einsum("eac,eac->ea", values, values)
        out[:, _RGB] = values.transpose(0, 2, 1)
        return out

    def _panorama_spectra(self) -> tuple[np.ndarray, float]:
        """Cached until the next :meth:`learn`: the rFFT along azimuth of the
        panorama's ``m_P |P|^2, m_P, m_P P_r, m_P P_g, m_P P_b, m_P (P_r + P_g + P_b)``
        (``(n_el, 6, n_freq)``; the first two swapped relative to the frame's stack, so
        that one product pairs ``m_q`` with ``m_P |P|^2`` and ``m_q |q|^2`` with ``m_P``)
        and the scale ``level`` of ``sigma`` (see the class notes)."""
        if self._spectra is None:
            colors, valid = self.panorama
            n = int(np.count_nonzero(valid))
            level = float(colors.sum()) / (3.0 * n) if n else 0.0
            if self.normalize == "local" or level <= _DARK:
                level = 1.0
            spec = np.fft.rfft(self._stack(colors, valid), axis=-1)
            spec = np.concatenate(
                [spec[:, [_M2, _M]], spec[:, _RGB], spec[:, _RGB].sum(axis=1, keepdims=True)],
                axis=1,
            )
            self._spectra = (spec, level)
        return self._spectra

    def _score(self, image: np.ndarray, camera: Camera) -> FrameScore:
        n_az = self._grid.n_azimuths
        j = self._offsets(camera, image.shape[1])
        strip, valid = self._strip(image, camera, j)
        n_valid = int(np.count_nonzero(valid))
        n_cols = int(np.count_nonzero(valid.any(axis=0)))
        if n_valid == 0:
            return FrameScore(np.zeros(n_az), -math.inf, 0)
        seen = np.flatnonzero(valid.any(axis=1))
        rows = slice(int(seen[0]), int(seen[-1]) + 1)  # skip rows above/below the view
        # The correlation c(h) = sum_j a(j) b(h + j) is the circular convolution of b
        # with a placed at -j: the offsets j0..j1 are consecutive, so the strip's stack
        # reversed and zero-padded to 360 degrees is a placed at -j shifted by j1, and
        # c = roll(irfft(rfft(reversed) * rfft(b)), -j1); products are summed over rows
        # (and channels) in the frequency domain.
        if j.size != j[-1] - j[0] + 1:
            raise RuntimeError("strip offsets must be consecutive")
        block = self._stack(strip[rows], valid[rows])
        fq = np.fft.rfft(block[..., ::-1], n=n_az, axis=-1)
        spectra, level = self._panorama_spectra()
        fp = spectra[rows]
        prod = (fq * fp[:, :5]).sum(axis=0)  # m_q P^2, q^2 m_P, q_r P_r, q_g P_g, q_b P_b
        specs = [prod[1], prod[0], prod[2:].sum(axis=0), (fq[:, _M] * fp[:, 1]).sum(axis=0)]
        if self.normalize == "local":
            specs.append((fq[:, _RGB].sum(axis=1) * fp[:, 1]).sum(axis=0))  # m_q q m_P
            specs.append((fq[:, _M] * fp[:, 5]).sum(axis=0))  # m_q m_P P
        corr = np.roll(np.fft.irfft(np.stack(specs), n=n_az, axis=-1), -int(j[-1]), axis=-1)
        overlap = np.rint(corr[3])
        good = overlap >= self.min_overlap * n_valid
        if not good.any():  # the map barely overlaps this frame anywhere
            return FrameScore(np.zeros(n_az), -math.inf, n_cols)
        qq, pp, qp, n = corr[0][good], corr[1][good], corr[2][good], 3.0 * overlap[good]
        if self.normalize == "local":
            # divide q and P by their mean intensity over the shared samples
            mq, mp = corr[4][good] / n, corr[5][good] / n
            mq = np.where(mq > _DARK, mq, 1.0)
            mp = np.where(mp > _DARK, mp, 1.0)
            ssd = qq / mq**2 + pp / mp**2 - 2.0 * qp / (mq * mp)
        else:
            ssd = qq + pp - 2.0 * qp
        msd = np.empty(n_az)
        msd[good] = np.maximum(ssd, 0.0) / n
        best = float(msd[good].min())
        msd[~good] = msd[good].max()
        ll = -n_cols * msd / (2.0 * (self.noise_std * level) ** 2)
        return FrameScore(ll, -math.sqrt(best), n_cols)

    # ------------------------------------------------------------------ persistence
    def _config(self) -> dict[str, Any]:
        g = self._grid
        return {
            "heading_step_deg": self.heading_step_deg,
            "el_min_deg": g.el_min_deg,
            "el_max_deg": g.el_max_deg,
            "el_step_deg": g.el_step_deg,
            "normalize": self.normalize,
            "noise_std": self.noise_std,
            "min_overlap": self.min_overlap,
        }

    def _map_arrays(self) -> dict[str, np.ndarray]:
        return {"color_sum": self._sum.copy(), "count": self._count.copy()}

    def _from_map_arrays(self, arrays: Mapping[str, np.ndarray]) -> None:
        for key, ref in (("color_sum", self._sum), ("count", self._count)):
            if key not in arrays:
                raise ValueError(f"entry {key!r} is missing")
            if arrays[key].shape != ref.shape:
                raise ValueError(
                    f"entry {key!r} has shape {arrays[key].shape}, the config needs {ref.shape}"
                )
        s, c = arrays["color_sum"], arrays["count"]
        if s.dtype.kind != "f" or not np.all(np.isfinite(s)) or np.any(s < 0):
            raise ValueError("entry 'color_sum' must hold finite, non-negative reals")
        if c.dtype.kind not in "iu" or np.any(c < 0):
            raise ValueError("entry 'count' must hold non-negative integers")
        if np.any(s[c == 0] != 0):
            raise ValueError("entry 'color_sum' is non-zero where 'count' is zero")
        frames = arrays.get("frames_learned")
        if frames is not None and frames.ndim == 0 and np.any(c > int(frames)):
            raise ValueError("entry 'count' exceeds frames_learned")
        if self.normalize != "mean" and np.any(s > 255.0 * c[..., None]):
            raise ValueError("entry 'color_sum' exceeds 255 per learned frame")
        self._sum = s.astype(np.float64)
        self._count = c.astype(np.int64)
        self._spectra = None
