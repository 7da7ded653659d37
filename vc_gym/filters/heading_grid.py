"""The orientational belief filter of the paper: a circular grid over headings (3.6).

The belief ``Bel(φ)`` is a probability vector on a circular grid of resolution
``Δφ_filter`` (paper: 1°). The motion update shifts it by the odometry turn (eq. 23)
and blurs it by the motion noise; the sensor update applies either the paper's mixing
rule (eq. 24) or the proper Bayes product; the estimate is the circular mean and
spread of the belief (eq. 25-27).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from vc_gym.angles import MIN_HEADING_STEP_DEG, circular_mean, circular_std, steps_in_circle
from vc_gym.filters.estimates import HeadingEstimate
from vc_gym.filters.sensor_protocol import HeadingSensor, check_log_likelihood
from vc_gym.validation import MAX_ABS_DEG
from vc_gym.validation import finite_float as _finite

__all__ = ["HeadingGridFilter", "mixing_lambda", "RULES", "UNIFORM_SPREAD_DEG"]

#: Sensor update rules of :class:`HeadingGridFilter`.
RULES = ("mixing", "bayes")
#: A blur (spread or motion noise) of this many degrees or more leaves a uniform
#: belief: the wrapped Gaussian's first harmonic, ``exp(-2 π² σ² / 360²)``, is below
#: 1e-300 from 2,130° on, so the blur is computed with at most this width and the
#: result is the same uniform belief to the last bit.
UNIFORM_SPREAD_DEG = 3600.0


def mixing_lambda(half_life_s: float, dt_s: float) -> float:
    """Mixing constant λ such that half the belief is replaced after ``half_life_s``.

    With ``k = half_life_s / dt_s`` updates in a half-life, ``(1 - λ)^k = 1/2``, so
    ``λ = 1 - 2^(-dt / half_life)`` (paper 4.2: half replaced after 0.3 s).
    """
    h = _finite("half_life_s", half_life_s)
    dt = _finite("dt_s", dt_s)
    if h <= 0 or dt <= 0:
        raise ValueError(f"half_life_s and dt_s must be > 0, got {half_life_s}, {dt_s}")
    return 1.0 - 2.0 ** (-dt / h)


def _angle(name: str, value: object) -> float:
    """A finite angle within ``±MAX_ABS_DEG`` (beyond it float64 holds no fraction of a
    degree), else a ``ValueError`` naming ``name`` and the range."""
    v = _finite(name, value)
    if abs(v) > MAX_ABS_DEG:
        raise ValueError(f"{name} must be within ±{MAX_ABS_DEG:g}°, got {value!r}")
    return v


def _spread(name: str, value: object) -> float:
    """A standard deviation in ``[0, MAX_ABS_DEG]`` degrees, else a ``ValueError``
    naming ``name`` and the range."""
    v = _finite(name, value)
    if not 0 <= v <= MAX_ABS_DEG:
        raise ValueError(f"{name} must be in [0, {MAX_ABS_DEG:g}] degrees, got {value!r}")
    return v


class HeadingGridFilter:
    """Histogram filter over the heading on a circular grid (paper 3.6, eq. 23-27).

    Parameters
    ----------
    resolution_deg : float
        Grid resolution ``Δφ_filter`` (paper: 1°); must divide 360.
    rule : {"mixing", "bayes"}
        Sensor update. ``"mixing"`` is the paper's eq. 24,
        ``Bel = λ·normalise(p(z|φ)·Bel⁻) + (1-λ)·Bel⁻``: only a fraction λ of the
        belief is replaced by the Bayes posterior each update, which makes the filter
        robust to single wrong frames and slow to follow. ``"bayes"`` is the proper
        product ``Bel ∝ p(z|φ)·Bel⁻`` (λ = 1), computed in the log domain.
    half_life_s : float
        Time after which half of the belief is replaced by sensor readings in the
        mixing rule (paper: 0.3 s).
    dt_s : float
        Default time between sensor updates (for λ); ``update(..., dt_s=...)``
        overrides it per call.

    Notes
    -----
    The motion update shifts the belief by a fraction of a bin with linear
    interpolation (which itself blurs by up to half a bin) and then convolves it with a
    wrapped Gaussian of standard deviation ``noise_deg`` (via FFT, exact on the circle).
    If a sensor reports ``-inf`` for every heading, the update is skipped with a
    ``RuntimeWarning`` and the belief is kept, rather than becoming undefined.
    """

    def __init__(
        self,
        resolution_deg: float = 1.0,
        rule: str = "mixing",
        half_life_s: float = 0.3,
        dt_s: float = 1.0 / 30.0,
    ):
        res = _finite("resolution_deg", resolution_deg)
        # the finest grid any sensor takes (36,000 bins): finer ones only cost memory
        n_bins = steps_in_circle(res) if MIN_HEADING_STEP_DEG <= res <= 90 else None
        if n_bins is None:
            raise ValueError(
                f"resolution_deg must be in [{MIN_HEADING_STEP_DEG}, 90] and divide 360, got {res}"
            )
        if rule not in RULES:
            raise ValueError(f"rule must be one of {RULES}, got {rule!r}")
        mixing_lambda(half_life_s, dt_s)  # validates both
        self.resolution_deg = res
        self.rule = rule
        self.half_life_s = float(half_life_s)
        self.dt_s = float(dt_s)
        h = np.arange(n_bins, dtype=np.float64) * res
        h.setflags(write=False)
        self._headings = h
        # frequencies of the circular grid, for the FFT blur
        self._freq = np.fft.rfftfreq(n_bins, d=res)  # cycles per degree
        self._belief = np.full(n_bins, 1.0 / n_bins)

    # ------------------------------------------------------------------ state
    @property
    def headings_deg(self) -> np.ndarray:
        """Centres of the grid bins (read-only)."""
        return self._headings

    @property
    def belief(self) -> np.ndarray:
        """The belief (a copy), a probability vector over :attr:`headings_deg`."""
        return self._belief.copy()

    def reset(self, heading_deg: float | None = None, spread_deg: float | None = None) -> None:
        """Uniform belief (no argument) or a wrapped Gaussian around ``heading_deg``.

        Parameters
        ----------
        heading_deg : float, optional
            Centre of the belief, within ``±MAX_ABS_DEG`` (wrapped onto the grid).
        spread_deg : float, optional
            Standard deviation, in ``[0, MAX_ABS_DEG]`` (default: one grid bin); from
            :data:`UNIFORM_SPREAD_DEG` on the belief is uniform.

        Raises
        ------
        ValueError
            On a heading or spread outside those ranges, or not finite.
        """
        n = self._headings.size
        if heading_deg is None:
            self._belief = np.full(n, 1.0 / n)
            return
        mu = _angle("heading_deg", heading_deg)
        sd = _spread("spread_deg", self.resolution_deg if spread_deg is None else spread_deg)
        b = np.zeros(n)
        b[int(round(mu / self.resolution_deg)) % n] = 1.0
        self._belief = b
        self._blur(sd)

    def set_belief(self, belief: np.ndarray) -> None:
        """Replace the belief by a non-negative vector (normalised here)."""
        b = np.asarray(belief, dtype=np.float64)
        if b.shape != self._headings.shape:
            raise ValueError(f"belief must have shape {self._headings.shape}, got {b.shape}")
        if not np.all(np.isfinite(b)) or np.any(b < 0) or b.sum() <= 0:
            raise ValueError("belief must be finite, non-negative and not all zero")
        self._belief = b / b.sum()

    # ------------------------------------------------------------------ motion
    def _blur(self, noise_deg: float) -> None:
        if noise_deg <= 0:
            return
        # Fourier transform of a Gaussian: exp(-2 pi^2 sigma^2 f^2); wrapped on the circle.
        # Wider than UNIFORM_SPREAD_DEG it is 1 at f = 0 and 0 elsewhere: uniform
        sigma = min(noise_deg, UNIFORM_SPREAD_DEG)
        kernel = np.exp(-2.0 * (math.pi * sigma * self._freq) ** 2)
        b = np.fft.irfft(np.fft.rfft(self._belief) * kernel, n=self._belief.size)
        b = np.clip(b, 0.0, None)
        self._belief = b / b.sum()

    def predict(self, dtheta_deg: float, noise_deg: float = 0.0) -> None:
        """Motion update (eq. 23): shift by the odometry turn and blur by its noise.

        Parameters
        ----------
        dtheta_deg : float
            Turn since the last step (degrees, CCW positive), e.g. from odometry,
            within ``±MAX_ABS_DEG``.
        noise_deg : float
            Standard deviation of the turn's error, in ``[0, MAX_ABS_DEG]``; from
            :data:`UNIFORM_SPREAD_DEG` on the belief becomes uniform.

        Raises
        ------
        ValueError
            On a turn or noise outside those ranges, or not finite.
        """
        d = _angle("dtheta_deg", dtheta_deg)
        s = _spread("noise_deg", noise_deg)
        shift = d / self.resolution_deg
        k = math.floor(shift)
        frac = shift - k
        b = np.roll(self._belief, k)
        if frac > 0:
            b = (1.0 - frac) * b + frac * np.roll(b, 1)
        self._belief = b / b.sum()
        self._blur(s)

    # ------------------------------------------------------------------ sensor
    def update(
        self,
        sensor: HeadingSensor,
        observation: Any,
        dt_s: float | None = None,
        rule: str | None = None,
    ) -> bool:
        """Sensor update with ``sensor``'s log-likelihood of ``observation`` (eq. 22, 24).

        Parameters
        ----------
        sensor : HeadingSensor
            Any object with ``heading_log_likelihood(observation, headings_deg)``.
        observation : Any
            What the sensor reads (e.g. a camera image).
        dt_s : float, optional
            Time since the last update, for λ of the mixing rule (default ``self.dt_s``).
        rule : {"mixing", "bayes"}, optional
            Override the filter's rule for this update.

        Returns
        -------
        bool
            ``False`` if the update was skipped because the sensor ruled out every
            heading (all ``-inf``), ``True`` otherwise.
        """
        rule = self.rule if rule is None else rule
        if rule not in RULES:
            raise ValueError(f"rule must be one of {RULES}, got {rule!r}")
        if not hasattr(sensor, "heading_log_likelihood"):
            raise ValueError(
                f"{type(sensor).__name__} is not a HeadingSensor "
                "(it has no heading_log_likelihood(observation, headings_deg) method)"
            )
        ll = check_log_likelihood(
            sensor.heading_log_likelihood(observation, self._headings),
            self._headings.size,
            type(sensor).__name__,
        )
        return self.update_log_likelihood(ll, dt_s=dt_s, rule=rule)

    def update_log_likelihood(
        self, log_likelihood: np.ndarray, dt_s: float | None = None, rule: str | None = None
    ) -> bool:
        """Sensor update from a log-likelihood already evaluated on :attr:`headings_deg`."""
        rule = self.rule if rule is None else rule
        if rule not in RULES:
            raise ValueError(f"rule must be one of {RULES}, got {rule!r}")
        ll = check_log_likelihood(log_likelihood, self._headings.size, "log_likelihood")
        top = ll.max()
        if not np.isfinite(top):
            warnings.warn(
                "sensor gave -inf for every heading; belief kept unchanged",
                RuntimeWarning,
                stacklevel=2,
            )
            return False
        with np.errstate(divide="ignore"):
            log_post = np.log(self._belief) + (ll - top)
        m = log_post.max()
        if not np.isfinite(m):
            # the sensor rules out every heading the belief allows: restart from it
            post = np.exp(ll - top)
        else:
            post = np.exp(log_post - m)
        post /= post.sum()
        if rule == "bayes":
            self._belief = post
        else:
            lam = mixing_lambda(self.half_life_s, self.dt_s if dt_s is None else dt_s)
            b = lam * post + (1.0 - lam) * self._belief
            self._belief = b / b.sum()
        return True

    # ------------------------------------------------------------------ estimate
    def estimate(self) -> HeadingEstimate:
        """Circular mean and spread of the belief (eq. 25-27)."""
        return HeadingEstimate(
            heading_deg=circular_mean(self._headings, self._belief),
            spread_deg=circular_std(self._headings, self._belief),
        )

    def map_heading(self) -> float:
        """The heading of the most probable bin (useful for multi-modal beliefs)."""
        return float(self._headings[int(np.argmax(self._belief))])
