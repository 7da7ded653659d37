"""Mean colour per azimuth sector: an appearance-feature heading baseline.

In the spirit of Porta & Kröse's appearance-based features for robot localisation
(J. M. Porta, B. J. A. Kröse, "Appearance-based concurrent map building and
localization", Robotics and Autonomous Systems 54(2), 2006): the view is summarised by
a few numbers per azimuth sector (here its mean colour) and a heading is scored by how
well those numbers fit what was learned in each world direction. It is the visual
compass' sector layout (:mod:`vc_gym.compass`) with the colour-transition histograms
replaced by one mean colour per sector.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from vc_gym.angles import steps_in_circle
from vc_gym.compass import Camera
from vc_gym.deprecation import moved_names
from vc_gym.heading_sensors.base import BaselineCompass, FrameScore
from vc_gym.heading_sensors.strip import StripGrid, angular_strip, strip_offsets
from vc_gym.validation import (
    int_in_range,
    nonnegative_float,
    positive_float,
    positive_float_at_most,
)

__all__ = ["SectorColorCompass", "FEATURES", "MODELS"]

#: Feature representations of a sector's mean colour (see :class:`SectorColorCompass`).
FEATURES = ("chroma", "rgb")
#: Per-sector models of the features.
MODELS = ("gaussian", "histogram")
#: Largest feature spread (``min_sigma``, ``prior_sigma``, ``gain_sigma``): the features
#: are chromaticities and levels within about [0, 1].
MAX_SIGMA = 10.0
#: Largest weight of the prior's pseudo-observations, temperature, smoothing and
#: histogram bins a sensor may have.
MAX_PRIOR_WEIGHT = 1e6
MAX_TEMPERATURE = 1e3
MAX_SMOOTHING = 1e4
MAX_BINS = 1024

#: Linear-light offset added before taking logs (about sRGB code 6): keeps the
#: log-colour of near-black sectors finite and stops their noise from dominating.
_EPS = 0.002
#: Range ``(low, high)`` of each feature dimension covered by the histograms; values
#: outside fall into the first or last bin.
_HIST_RANGE = {
    "chroma": ((-2.5, 2.5), (-2.5, 2.5), (-6.3, 0.0)),
    "rgb": ((-6.3, 0.0), (-6.3, 0.0), (-6.3, 0.0)),
}
#: Log-gains of a frame (natural log; ±2.5 is about ±3.6 stops) over which the
#: histogram model integrates the brightness of ``"chroma"`` features, every
#: ``_GAIN_STEPS`` steps of ``_VALUE_STEP``, the resolution at which ``ln I`` is read.
_VALUE_STEP = 0.05
_GAIN_STEPS = 2
_GAIN_MAX = 2.5
_N_GAINS = 2 * int(round(_GAIN_MAX / (_VALUE_STEP * _GAIN_STEPS))) + 1
_GAINS = _VALUE_STEP * _GAIN_STEPS * (np.arange(_N_GAINS) - _N_GAINS // 2)
_N_FEATURES = 3


def _srgb_to_linear(v: np.ndarray) -> np.ndarray:
    """sRGB values in ``[0, 255]`` (any float array) to linear light in ``[0, 1]``."""
    v = v * (1.0 / 255.0)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


class SectorColorCompass(BaselineCompass):
    """Heading from the mean colour of each azimuth sector of the view.

    The full circle of world directions is cut into sectors of ``sector_deg``. A frame
    is resampled (:func:`~vc_gym.heading_sensors.strip.angular_strip`) onto directions every
    ``az_step_deg`` in azimuth and every ``el_step_deg`` in the elevation band
    ``[el_min_deg, el_max_deg]``; a sector's feature vector is computed from the mean
    linear-light colour ``(R, G, B)`` of its samples, and only sectors of which at
    least ``min_valid_fraction`` of the samples were in view count.

    Features (``features``), each three numbers in natural-log units:

    * ``"chroma"`` (default): ``ln(R/G)``, ``ln(B/G)`` (log-chromaticity, unchanged by
      a change of illumination or exposure) and the log-brightness
      ``ln I = ln((R + G + B) / 3)``. A change of light or exposure adds one unknown
      log-gain ``β`` to every ``ln I`` of a frame; the log-likelihood integrates ``β``
      out under the prior ``N(0, gain_sigma²)`` (flat if ``gain_sigma`` is None;
      exactly for the gaussian model, on a grid of log-gains within ±2.5 for the
      histogram model), so mainly the brightness *pattern* across the frame's sectors
      counts. Unlike brightness relative to the frame's own mean, this does not
      depend on what else the frame sees (a crop, a narrower lens). The learned
      frames are assumed to share one exposure.
    * ``"rgb"``: ``ln R``, ``ln G``, ``ln B``: absolute colour; a change of light
      shifts every term and breaks the match.

    Models (``model``), one per sector:

    * ``"gaussian"`` (default): running sums give the mean and per-dimension variance
      of the sector's features. The variance is shrunk towards ``prior_sigma**2`` with
      the weight of ``prior_weight`` frames, ``(M2 + w σ0²) / (n + w)``, and kept above
      ``min_sigma**2``, so a sector learned from one frame is not infinitely sharp.
    * ``"histogram"``: per sector and dimension a histogram of ``n_bins`` bins over a
      fixed range, filled by linear (two-bin) interpolation, with additive smoothing
      ``smoothing``; probabilities are read by linear interpolation between bin
      centres.

    **Log-likelihood.** For a candidate heading ``h`` (every point of
    :attr:`headings_deg` at once), the frame's samples are grouped into the world
    sectors they fall in at ``h``; each complete-enough sector ``s`` whose model has
    learned something contributes ``log p(x_s | model of s) - log p(x_s | pooled
    model)``, where the pooled model is the same kind of model fitted to the features
    of every learned sector together (heading-independent); for ``"chroma"`` the
    brightness part is the log of the gain-integrated likelihood of the frame's
    learned sectors at ``h`` against the same integral under the pooled model. The
    result is ``log p(frame | h)`` up to a term that does not depend on ``h``, except
    that the grouping of samples into sectors changes with ``h`` modulo the sector
    width. Sectors never learned contribute 0: unknown, not impossible, so an
    unlearned direction is neither favoured nor ruled out. The sum treats the sectors
    as independent and is **not tempered** at the default ``temperature=1`` (it is
    divided by ``temperature``): neighbouring sectors are correlated and the models
    are fitted to few frames, so the posterior ``∝ exp(log-likelihood)`` is
    over-confident (on synthetic views learned as in the tests, only 35-85 % of the
    true headings lay within two spreads of :meth:`estimate`); filters may temper it.

    **Goodness** (:attr:`FrameScore.goodness`, ``estimate().score``): the mean over the
    frame's sectors at the best heading of ``log p(x_s | model of s)`` (the pooled
    model standing in for sectors never learned), i.e. a per-sector log-density
    (gaussian; it may be positive) or log-probability (histogram, ``<= 0``), with the
    brightness taken at the most probable log-gain for ``"chroma"``. Higher fits
    better; it is comparable between maps with the same config. ``n_terms`` is the
    number of sectors the frame contributed. A frame that sees no sector fully enough
    gets a flat log-likelihood, goodness ``-inf`` and ``n_terms`` 0.

    Parameters
    ----------
    sector_deg : float
        Sector width (degrees); a whole multiple of ``az_step_deg`` dividing 360.
    model : {"gaussian", "histogram"}
        Per-sector model.
    features : {"chroma", "rgb"}
        Feature representation (see above).
    heading_step_deg : float
        Step of the candidate heading grid; a whole multiple of ``az_step_deg``.
    az_step_deg : float
        Azimuth step of the samples (degrees); must divide 360.
    el_min_deg, el_max_deg, el_step_deg : float
        Elevation band and step of the samples (degrees, positive up). The default
        ±12° stays inside the view of an Aibo camera (±22.6° vertically) pitched by up
        to ±10°: a sector partly out of the band's view is averaged over the part in
        view, which biases its colour (with ±20° a 10° downward pitch lost the sky
        and failed outdoors).
    min_valid_fraction : float
        Fraction of a sector's samples that must be in view for it to count, in
        ``(0, 1]``.
    min_sigma : float
        Floor of the gaussian model's standard deviation (log units).
    prior_sigma : float
        Prior standard deviation of the gaussian model (log units).
    prior_weight : float
        Weight (in frames) of ``prior_sigma``; ``>= 0``.
    n_bins : int
        Histogram bins per feature dimension, ``>= 2``.
    smoothing : float
        Additive smoothing (pseudo-count per bin) of the histograms, ``> 0``.
    temperature : float
        Divides the returned log-likelihood, ``> 0``; 1 is untempered.
    gain_sigma : float or None
        Standard deviation (natural log) of the prior on a frame's log-gain for
        ``"chroma"`` features; ``None`` is a flat prior (brightness then tells only
        through its pattern across sectors). The default 0.5 lets the absolute level
        count a little: on the real rotation crops it was right (within 10°) more
        often than the flat prior, and it still takes a 4-fold change of light.

    Examples
    --------
    >>> sc = SectorColorCompass()                                  # doctest: +SKIP
    >>> for img, yaw in training: sc.learn(img, Camera(yaw_deg=yaw))  # doctest: +SKIP
    >>> sc.estimate(new_image, Camera()).heading_deg                # doctest: +SKIP

    References
    ----------
    J. M. Porta and B. J. A. Kröse, "Appearance-based concurrent map building and
    localization", Robotics and Autonomous Systems 54(2):159-164, 2006.
    """

    schema: ClassVar[str] = "vc_gym.SectorColorCompass"
    legacy_schemas: ClassVar[tuple[str, ...]] = ("vc_gym.SectorColourCompass",)
    name: ClassVar[str] = "sector_color"

    def __init__(
        self,
        sector_deg: float = 4.5,
        *,
        model: str = "gaussian",
        features: str = "chroma",
        heading_step_deg: float = 1.0,
        az_step_deg: float = 0.5,
        el_min_deg: float = -12.0,
        el_max_deg: float = 12.0,
        el_step_deg: float = 2.0,
        min_valid_fraction: float = 0.5,
        min_sigma: float = 0.03,
        prior_sigma: float = 0.15,
        prior_weight: float = 1.0,
        n_bins: int = 32,
        smoothing: float = 0.02,
        temperature: float = 1.0,
        gain_sigma: float | None = 0.5,
    ):
        super().__init__(heading_step_deg)
        if model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {model!r}")
        if features not in FEATURES:
            raise ValueError(f"features must be one of {FEATURES}, got {features!r}")
        self.model = model
        self.features = features
        self.grid = StripGrid(
            az_step_deg=az_step_deg,
            el_min_deg=el_min_deg,
            el_max_deg=el_max_deg,
            el_step_deg=el_step_deg,
        )
        az = self.grid.az_step_deg
        self.sector_deg = positive_float("sector_deg", sector_deg)
        self._m = _whole_multiple("sector_deg", self.sector_deg, "az_step_deg", az)
        self._q = _whole_multiple("heading_step_deg", self.heading_step_deg, "az_step_deg", az)
        n = steps_in_circle(self.sector_deg)
        if n is None or n < 2:
            raise ValueError(f"sector_deg must divide 360 (and be <= 180), got {sector_deg}")
        self.n_sectors = n
        frac = positive_float("min_valid_fraction", min_valid_fraction)
        if frac > 1.0:
            raise ValueError(f"min_valid_fraction must be in (0, 1], got {frac}")
        self.min_valid_fraction = frac
        # upper bounds too: a saved sensor's settings pass these checks, and a sigma or a
        # temperature of 1e300 would flatten every likelihood without a word
        self.min_sigma = positive_float_at_most("min_sigma", min_sigma, MAX_SIGMA)
        self.prior_sigma = positive_float_at_most("prior_sigma", prior_sigma, MAX_SIGMA)
        self.prior_weight = nonnegative_float("prior_weight", prior_weight)
        if self.prior_weight > MAX_PRIOR_WEIGHT:
            raise ValueError(
                f"prior_weight must be in [0, {MAX_PRIOR_WEIGHT:g}], got {prior_weight!r}"
            )
        self.n_bins = int_in_range("n_bins", n_bins, 2, MAX_BINS)
        self.smoothing = positive_float_at_most("smoothing", smoothing, MAX_SMOOTHING)
        self.temperature = positive_float_at_most("temperature", temperature, MAX_TEMPERATURE)
        self.gain_sigma = (
            None
            if gain_sigma is None
            else positive_float_at_most("gain_sigma", gain_sigma, MAX_SIGMA)
        )
        d, b = _N_FEATURES, self.n_bins
        self._count = np.zeros(self.n_sectors, dtype=np.float64)
        if model == "gaussian":
            self._sum = np.zeros((self.n_sectors, d), dtype=np.float64)
            self._sumsq = np.zeros((self.n_sectors, d), dtype=np.float64)
        else:
            self._hist = np.zeros((self.n_sectors, d, b), dtype=np.float64)
        self._hist_range = np.array(_HIST_RANGE[features], dtype=np.float64)
        self._tables: dict[str, np.ndarray] | None = None

    # ------------------------------------------------------------------ properties
    @property
    def sector_observations(self) -> np.ndarray:
        """How many learned frames saw each sector (copy), shape ``(n_sectors,)``."""
        return self._count.astype(np.int64)

    @property
    def learned_fraction(self) -> float:
        """Fraction of the circle's sectors learned from at least one frame."""
        return float(np.mean(self._count > 0))

    # ------------------------------------------------------------------ features
    def _window_features(
        self, image: np.ndarray, camera: Camera, phase: float
    ) -> tuple[np.ndarray, np.ndarray, int]:
        """Features of every window of ``m`` consecutive samples.

        Samples lie at yaw-relative offsets ``(j + 0.5 - phase) * az_step`` for
        integers ``j`` from ``j0``. Returns the ``(n_windows, 3)`` features of the
        windows starting at ``j0, j0 + 1, ...``, their ``(n_windows,)`` validity and
        ``j0``.
        """
        span = strip_offsets(camera, image.shape[1], self.grid)
        j0 = int(span[0]) - 1
        j = np.arange(j0, int(span[-1]) + 1)
        strip, valid, _ = angular_strip(image, camera, self.grid, j + 0.5 - phase)
        lin = _srgb_to_linear(strip.astype(np.float64)) * valid[..., None]
        col_sum = lin.sum(axis=0)  # (J, 3)
        col_n = valid.sum(axis=0).astype(np.float64)  # (J,)
        m = self._m
        n_win = col_n.size - m + 1
        if n_win < 1:
            return np.zeros((0, _N_FEATURES)), np.zeros(0, dtype=bool), j0
        cs = np.concatenate([np.zeros((1, 3)), np.cumsum(col_sum, axis=0)])
        cn = np.concatenate([[0.0], np.cumsum(col_n)])
        win_sum = cs[m:] - cs[:-m]
        win_n = cn[m:] - cn[:-m]
        ok = win_n >= self.min_valid_fraction * (m * valid.shape[0]) - 1e-9
        rgb = win_sum / np.maximum(win_n, 1.0)[:, None] + _EPS
        if self.features == "chroma":
            feats = np.stack(
                [
                    np.log(rgb[:, 0] / rgb[:, 1]),
                    np.log(rgb[:, 2] / rgb[:, 1]),
                    np.log(rgb.mean(axis=1)),
                ],
                axis=1,
            )
        else:
            feats = np.log(rgb)
        return feats, ok, j0

    # ------------------------------------------------------------------ learning
    def _learn(self, image: np.ndarray, camera: Camera) -> None:
        az = self.grid.az_step_deg
        delta = float(camera.yaw_deg) / az  # sample j sits at world index j + base
        base = math.floor(delta)
        feats, ok, j0 = self._window_features(image, camera, delta - base)
        m, n_sec = self._m, self.n_sectors
        # windows whose first sample starts a world sector: (j0 + w + base) % m == 0
        starts = np.arange((-(j0 + base)) % m, ok.size, m)
        starts = starts[ok[starts]]
        if starts.size == 0:
            raise ValueError(
                "the frame sees no sector fully enough (at least "
                f"{self.min_valid_fraction:g} of its samples in the elevation band "
                f"[{self.grid.el_min_deg:g}, {self.grid.el_max_deg:g}] deg)"
            )
        # each sector once, even if a steeply pitched view wraps around the circle
        ssel, once = np.unique(((j0 + base + starts) // m) % n_sec, return_index=True)
        x = feats[starts[once]]
        self._count[ssel] += 1.0
        if self.model == "gaussian":
            self._sum[ssel] += x
            self._sumsq[ssel] += x * x
        else:
            rng = self._hist_range
            b0, frac = self._bin_positions(x, rng[:, 0], rng[:, 1])  # (k, d)
            d_idx = np.broadcast_to(np.arange(_N_FEATURES), b0.shape)
            s_idx = np.broadcast_to(ssel[:, None], b0.shape)
            np.add.at(self._hist, (s_idx, d_idx, b0), 1.0 - frac)
            np.add.at(self._hist, (s_idx, d_idx, b0 + 1), frac)
        self._tables = None

    def _bin_positions(
        self, x: np.ndarray, lo: np.ndarray | float, hi: np.ndarray | float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Lower bin index (``0 .. n_bins - 2``) and interpolation weight of the upper
        one, per value of ``x`` in histograms over ``[lo, hi]`` (linear interpolation
        between bin centres; values beyond the centres of the end bins are clamped)."""
        u = (x - lo) / (np.asarray(hi) - lo) * self.n_bins - 0.5
        u = np.clip(u, 0.0, self.n_bins - 1.0)
        b0 = np.minimum(np.floor(u).astype(np.int64), self.n_bins - 2)
        return b0, u - b0

    # ------------------------------------------------------------------ scoring
    def _model_tables(self) -> dict[str, np.ndarray]:
        """Per-sector and pooled model parameters, rebuilt after learning."""
        if self._tables is not None:
            return self._tables
        n = self._count
        learned = n > 0
        tot = float(n.sum())
        if self.model == "gaussian":
            w, s0, floor = self.prior_weight, self.prior_sigma**2, self.min_sigma**2
            mean = self._sum / np.where(learned, n, 1.0)[:, None]
            m2 = np.maximum(self._sumsq - n[:, None] * mean**2, 0.0)
            var = np.maximum((m2 + w * s0) / np.maximum(n[:, None] + w, 1e-300), floor)
            p_mean = self._sum.sum(axis=0) / tot
            p_m2 = np.maximum(self._sumsq.sum(axis=0) - tot * p_mean**2, 0.0)
            p_var = np.maximum((p_m2 + w * s0) / (tot + w), floor)
            self._tables = {
                "learned": learned,
                "mean": mean,
                "var": var,
                "pool_mean": p_mean,
                "pool_var": p_var,
            }
        else:
            a, b = self.smoothing, self.n_bins
            prob = (self._hist + a) / (n[:, None, None] + a * b)  # (S, d, B)
            pool = (self._hist.sum(axis=0) + a) / (tot + a * b)  # (d, B)
            self._tables = {"learned": learned, "prob": prob, "pool": pool}
            if self.features == "chroma":
                # log-probability of ln I on a grid of step _VALUE_STEP reaching
                # _GAIN_MAX beyond the histogram range; row S (zeros) for unused terms
                lo, hi = self._hist_range[2]
                v = (
                    lo
                    - _GAIN_MAX
                    + _VALUE_STEP
                    * np.arange(int(round((hi - lo + 2 * _GAIN_MAX) / _VALUE_STEP)) + 1)
                )
                b0, frac = self._bin_positions(v, lo, hi)
                rows = np.concatenate([prob[:, 2], pool[2][None]])  # (S + 1, B)
                lv = np.log(rows[:, b0] * (1.0 - frac) + rows[:, b0 + 1] * frac)
                self._tables["bright_v0"] = np.array(v[0])
                self._tables["bright"] = np.concatenate([lv[:-1], np.zeros((1, v.size))])
                self._tables["bright_pool"] = lv[-1]
        return self._tables

    def _log_p(self, x: np.ndarray, sec: np.ndarray | None) -> np.ndarray:
        """Per-dimension ``log p(x | model of sector sec)`` (``sec=None``: the pooled
        model); ``x`` is ``(..., 3)``, ``sec`` broadcasts with ``x[..., 0]``."""
        t = self._model_tables()
        if self.model == "gaussian":
            if sec is None:
                mu, var = t["pool_mean"], t["pool_var"]
            else:
                mu, var = t["mean"][sec], t["var"][sec]
            return -0.5 * ((x - mu) ** 2 / var + np.log(2.0 * np.pi * var))
        rng = self._hist_range
        b0, frac = self._bin_positions(x, rng[:, 0], rng[:, 1])
        d = np.arange(_N_FEATURES)
        if sec is None:
            table = t["pool"]
            p = table[d, b0] * (1.0 - frac) + table[d, b0 + 1] * frac
        else:
            table, s = t["prob"], sec[..., None]
            p = table[s, d, b0] * (1.0 - frac) + table[s, d, b0 + 1] * frac
        return np.log(p)

    def _brightness_terms(
        self, v: np.ndarray, sec: np.ndarray, mask: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Log-brightness terms of every heading with the frame's log-gain integrated
        out under its prior, against the pooled model treated the same way.

        ``v``, ``sec`` and ``mask`` are ``(H, K)``: the windows' ``ln I``, their sectors
        and whether a learned sector is used. Returns the ``(H,)`` log-likelihood ratio
        and the best log-gains ``(H,)`` under the sector models and the pooled one.
        """
        t = self._model_tables()
        n = mask.sum(axis=1)
        # prior N(beta; 0, gain_sigma^2), or flat (precision 0; improper, but its
        # constant cancels in the ratio)
        prec = 0.0 if self.gain_sigma is None else 1.0 / self.gain_sigma**2
        if self.model == "gaussian":
            lm, beta = _gain_integral(v - t["mean"][sec, 2], t["var"][sec, 2], mask, prec)
            vp = np.broadcast_to(t["pool_var"][2], v.shape)
            lmp, bp = _gain_integral(v - t["pool_mean"][2], vp, mask, prec)
            return np.where(n > 0, lm - lmp, 0.0), beta, bp
        # histogram: the integral as a sum over a grid of log-gains, reading ln I - beta
        # from tables sampled every _VALUE_STEP (ln I rounded to that step):
        # ln I - beta_g sits at index i(ln I) + r (G - 1) / 2 - r g, r = _GAIN_STEPS
        lv, lvp, r = t["bright"], t["bright_pool"], _GAIN_STEPS
        i0 = np.rint((v - float(t["bright_v0"])) / _VALUE_STEP).astype(np.int64)
        i0 = np.clip(i0 + r * (_N_GAINS // 2), r * (_N_GAINS - 1), lvp.size - 1)
        i0 = i0 - r * np.arange(_N_GAINS)[:, None, None]
        # i0: (G, H, K); unused terms read the zero row
        rows = np.where(mask, sec, lv.shape[0] - 1)
        lp = lv[rows, i0].sum(axis=2).T  # (H, G)
        lpp = np.where(mask, lvp[i0], 0.0).sum(axis=2).T
        if prec > 0:
            prior = -0.5 * prec * _GAINS**2
            lp, lpp = lp + prior, lpp + prior
        ratio = _logsumexp(lp) - _logsumexp(lpp)
        return ratio, _GAINS[np.argmax(lp, axis=1)], _GAINS[np.argmax(lpp, axis=1)]

    def _score(self, image: np.ndarray, camera: Camera) -> FrameScore:
        n_h = self.headings_deg.size
        feats, ok, j0 = self._window_features(image, camera, 0.0)
        good = np.flatnonzero(ok)
        if good.size == 0:
            return FrameScore(np.zeros(n_h), -math.inf, 0)
        m, q, n_sec = self._m, self._q, self.n_sectors
        # heading i puts sample j at world index j + i q: window w (first sample
        # j0 + w) is a whole sector of heading i when (j0 + w + i q) % m == 0, namely
        # sector (j0 + w + i q) // m. The windows of one heading form one residue
        # class mod m: table[r, k] = the k-th good window whose start is r mod m.
        start = j0 + good  # (G,)
        res = start % m
        order = np.argsort(res, kind="stable")
        counts = np.bincount(res, minlength=m)
        table = np.full((m, int(counts.max())), -1, dtype=np.int64)
        rank = np.arange(good.size) - np.repeat(np.cumsum(counts) - counts, counts)
        table[res[order], rank] = order
        shift = np.arange(n_h, dtype=np.int64) * q  # (H,)
        widx = table[(-shift) % m]  # (H, K)
        used = widx >= 0
        widx = np.where(used, widx, 0)
        sec = ((start[widx] + shift[:, None]) // m) % n_sec
        mask = used & self._model_tables()["learned"][sec]
        x = feats[good][widx]  # (H, K, 3)
        fixed = 2 if self.features == "chroma" else _N_FEATURES
        lp = self._log_p(x, sec)[..., :fixed].sum(axis=-1)
        lpool = self._log_p(x, None)[..., :fixed].sum(axis=-1)
        ll = np.where(mask, lp - lpool, 0.0).sum(axis=1)
        beta = beta_pool = np.zeros(n_h)
        if self.features == "chroma":
            bright, beta, beta_pool = self._brightness_terms(x[..., 2], sec, mask)
            ll = ll + bright
        ll /= self.temperature
        # goodness: every sector of the best heading, gain-corrected where fitted
        b = int(np.argmax(ll))
        k = np.flatnonzero(used[b])
        xb, sb, lb = x[b, k].copy(), sec[b, k], mask[b, k]
        if self.features == "chroma":
            xb[:, 2] -= np.where(lb, beta[b], beta_pool[b])
        own = self._log_p(xb, sb).sum(axis=-1)
        pooled = self._log_p(xb, None).sum(axis=-1)
        goodness = float(np.where(lb, own, pooled).mean())
        return FrameScore(ll, goodness, int(k.size))

    # ------------------------------------------------------------------ persistence
    def _config(self) -> dict[str, Any]:
        return {
            "sector_deg": self.sector_deg,
            "model": self.model,
            "features": self.features,
            "heading_step_deg": self.heading_step_deg,
            "az_step_deg": self.grid.az_step_deg,
            "el_min_deg": self.grid.el_min_deg,
            "el_max_deg": self.grid.el_max_deg,
            "el_step_deg": self.grid.el_step_deg,
            "min_valid_fraction": self.min_valid_fraction,
            "min_sigma": self.min_sigma,
            "prior_sigma": self.prior_sigma,
            "prior_weight": self.prior_weight,
            "n_bins": self.n_bins,
            "smoothing": self.smoothing,
            "temperature": self.temperature,
            "gain_sigma": self.gain_sigma,
        }

    def _map_arrays(self) -> dict[str, np.ndarray]:
        arrays = {"count": self._count.copy()}
        if self.model == "gaussian":
            arrays["sum"] = self._sum.copy()
            arrays["sumsq"] = self._sumsq.copy()
        else:
            arrays["hist"] = self._hist.copy()
        return arrays

    def _from_map_arrays(self, arrays: Mapping[str, np.ndarray]) -> None:
        s, d, b = self.n_sectors, _N_FEATURES, self.n_bins
        count = _float_entry(arrays, "count", (s,))
        if np.any(count < 0) or np.any(count != np.round(count)):
            raise ValueError("entry 'count' must hold whole numbers >= 0")
        if not np.any(count > 0):
            raise ValueError("entry 'count' is all zero: the map has learned nothing")
        if self.model == "gaussian":
            total = _float_entry(arrays, "sum", (s, d))
            sumsq = _float_entry(arrays, "sumsq", (s, d))
            if np.any(sumsq < 0):
                raise ValueError("entry 'sumsq' has negative values")
            nn = np.maximum(count, 1e-300)[:, None]
            m2 = sumsq - total**2 / nn
            tol = 1e-9 * np.maximum(sumsq, 1.0)
            if np.any((count == 0)[:, None] & ((total != 0) | (sumsq != 0))):
                raise ValueError("entries 'sum'/'sumsq' are non-zero for a sector with count 0")
            if np.any(m2 < -tol):
                raise ValueError("entries 'sum' and 'sumsq' are inconsistent (negative variance)")
            self._count, self._sum, self._sumsq = count, total, sumsq
        else:
            hist = _float_entry(arrays, "hist", (s, d, b))
            if np.any(hist < 0):
                raise ValueError("entry 'hist' has negative values")
            if not np.allclose(hist.sum(axis=2), count[:, None], rtol=1e-9, atol=1e-9):
                raise ValueError("entry 'hist' does not sum to 'count' in every sector")
            self._count, self._hist = count, hist
        self._tables = None


def _gain_integral(
    r: np.ndarray, var: np.ndarray, mask: np.ndarray, prec: float
) -> tuple[np.ndarray, np.ndarray]:
    """``log ∫ N(beta; 0, 1/prec) prod_k N(r_k; beta, var_k) d beta`` per row, over the
    terms where ``mask``, and the posterior mean of ``beta``; ``prec = 0`` is a flat
    prior (the improper density 1).

    In closed form, with ``A = prec + Σ 1/var_k``, ``B = Σ r_k/var_k`` and
    ``C = Σ r_k²/var_k``: ``-0.5 [Σ log(2π var_k) + log(A / prec) + C - B² / A]``
    (flat prior: ``log(A / 2π)`` in place of ``log(A / prec)``); the mean is ``B / A``.
    A row without terms gives 0 under a proper prior.
    """
    iv = np.where(mask, 1.0 / var, 0.0)
    a = np.maximum(prec + iv.sum(axis=1), 1e-300)
    b = (r * iv).sum(axis=1)
    c = (r * r * iv).sum(axis=1)
    logdet = np.where(mask, np.log(2.0 * np.pi * var), 0.0).sum(axis=1)
    norm = np.log(a / prec) if prec > 0 else np.log(a / (2.0 * np.pi))
    return -0.5 * (logdet + norm + c - b * b / a), b / a


def _logsumexp(a: np.ndarray) -> np.ndarray:
    """``log(sum(exp(a), axis=1))`` of a finite 2-D array, without overflow."""
    top = a.max(axis=1, keepdims=True)
    return top[:, 0] + np.log(np.exp(a - top).sum(axis=1))


def _whole_multiple(name: str, value: float, unit_name: str, unit: float) -> int:
    """``value / unit`` as an int >= 1, or a ``ValueError``."""
    r = value / unit
    k = int(round(r))
    if k < 1 or abs(r - k) > 1e-9 * max(1.0, r):
        raise ValueError(f"{name} ({value:g}) must be a whole multiple of {unit_name} ({unit:g})")
    return k


def _float_entry(arrays: Mapping[str, np.ndarray], key: str, shape: tuple[int, ...]) -> np.ndarray:
    """``arrays[key]`` as a finite float64 array of ``shape``, or a ``ValueError``."""
    if key not in arrays:
        raise ValueError(f"entry {key!r} is missing")
    a = np.asarray(arrays[key])
    if a.dtype.kind != "f":
        raise ValueError(f"entry {key!r} must be floating point, got {a.dtype}")
    if a.shape != shape:
        raise ValueError(f"entry {key!r} has shape {a.shape}, expected {shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"entry {key!r} has non-finite values")
    return a.astype(np.float64)


# deprecated: SectorColourCompass, the British spelling of SectorColorCompass, served for
# one release
__getattr__ = moved_names(
    __name__, {"SectorColourCompass": (sys.modules[__name__], "SectorColorCompass")}
)
