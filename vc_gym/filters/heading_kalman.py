"""A heading (yaw) Kalman filter on filterpy's unscented Kalman filter.

The paper tracks the heading with a circular belief grid (section 3.6, eq. 23-27).
:class:`KalmanHeadingFilter` is vc_gym's Gaussian variant of that filter, for
benchmarks: the belief is the Gaussian of eq. 25 from the start, the odometry turn of
the motion model (eq. 19-21) shifts its mean as eq. 23 shifts the grid, and a compass
reading enters as a measurement ``z = heading`` with variance ``R = spread²`` (the
Gaussian summary, eq. 26-27, of the sensor model of eq. 22). The Kalman gain takes the
place of the paper's mixing constant ``λ`` (eq. 24).

Headings live on a circle, so the filter gives filterpy angle-aware hooks:

* ``residual_x`` and ``residual_z`` wrap the heading difference with
  :func:`~vc_gym.angles.wrap180` (359° vs 1° is a 2° residual, not 358°);
* ``x_mean_fn`` and ``z_mean_fn`` average the heading of the sigma points as
  ``anchor + Σ wᵢ · wrap180(θᵢ - anchor)`` with the central sigma point as the anchor,
  and the turn rate (if any) as a plain weighted sum.

Why not ``atan2(Σ w sin θ, Σ w cos θ)``: the scaled sigma points have a large negative
central weight (``Wm[0] = 1 - 1/(α²(n+κ)) ≈ -32`` here), and once the heading spread
exceeds about 80° the weighted cosine sum turns negative and ``atan2`` returns the
*opposite* heading. The anchored mean is exact for the symmetric sigma points of a linear
motion model and stays right for any spread up to :attr:`KalmanHeadingFilter.MAX_SPREAD_DEG`,
including the "no idea" default of 180°.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter

from vc_gym.angles import (
    MIN_HEADING_STEP_DEG,
    circular_mean,
    circular_std,
    steps_in_circle,
    wrap180,
    wrap360,
)
from vc_gym.filters.estimates import HeadingEstimate
from vc_gym.filters.sensor_protocol import HeadingSensor, check_log_likelihood
from vc_gym.validation import MAX_ABS_DEG, positive_float
from vc_gym.validation import finite_float as _finite

__all__ = ["MAX_DT_S", "MAX_RATE_DEG_PER_S", "MIN_SPREAD_DEG", "KalmanHeadingFilter"]

#: Smallest measurement spread :meth:`KalmanHeadingFilter.update` takes (degrees).
MIN_SPREAD_DEG = 1e-6
#: Largest turn-rate spread and random-walk noise (deg/s) the rate state takes: far
#: beyond any robot's turn rate (a billion degrees a second), and their squares times
#: :data:`MAX_DT_S` stay far from overflowing the covariance.
MAX_RATE_DEG_PER_S = MAX_ABS_DEG
#: Longest prediction step (seconds, a million: eleven days): ``rate · dt`` and the
#: rate variance's growth ``noise² · dt`` stay finite.
MAX_DT_S = 1e6

#: Sigma-point parameters (Van der Merwe). A small α keeps the sigma points within
#: ``0.17 σ`` of the mean, so they never wrap around the circle; β = 2 is optimal for
#: Gaussians; κ = 3 - n is Julier's choice.
_ALPHA = 0.1
_BETA = 2.0


# --------------------------------------------------------------------------- helpers


def _residual(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a - b`` with the first (heading) component wrapped to ``[-180, 180)``."""
    y = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    y[0] = wrap180(y[0])
    return y


def _mean(sigmas: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted mean of sigma points whose first column is a heading in degrees.

    The heading is averaged in the tangent space at the central sigma point
    (``sigmas[0]``, the mean the points were drawn around): ``anchor + Σ wᵢ
    wrap180(θᵢ - anchor)``, wrapped to ``[0, 360)``. This is linear in the weights, so
    the negative central weight of the scaled unscented transform is harmless. Other
    columns (the turn rate) are a plain weighted sum.
    """
    s = np.asarray(sigmas, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    out = w @ s
    anchor = s[0, 0]
    out[0] = wrap360(anchor + w @ wrap180(s[:, 0] - anchor))
    return out


def _hx(x: np.ndarray) -> np.ndarray:
    """Measurement function: the compass measures the heading."""
    return x[:1].copy()


# --------------------------------------------------------------------------- filter


class KalmanHeadingFilter:
    """Heading filter: an unscented Kalman filter with angle-aware hooks.

    The state is ``x = [heading_deg]`` or, with ``turn_rate_state=True``,
    ``x = [heading_deg, turn_rate_deg_per_s]`` (constant-rate model). The heading is
    kept in ``[0, 360)`` after every step.

    This is not the paper's filter: the paper uses a circular belief grid (eq. 23-27).
    Here the belief is the Gaussian of eq. 25 throughout, which is cheaper but cannot
    hold two hypotheses at once; use it as a benchmark variant.

    Parameters
    ----------
    heading_deg : float
        Initial heading (any finite value; wrapped to ``[0, 360)``).
    spread_deg : float
        Initial standard deviation of the heading, in ``(0, MAX_SPREAD_DEG]``. The
        default 180° means "no idea": the first informative measurement takes over.
    turn_rate_state : bool
        Also estimate a constant turn rate (deg/s). The motion model is then
        ``heading += dtheta + rate · dt``. Use it when there is no odometry (pass
        ``dtheta=0``) or to absorb a constant odometry bias.
    rate_spread_deg_per_s : float
        Initial standard deviation of the turn rate (only with ``turn_rate_state``).
    rate_noise_deg_per_s : float
        Random-walk noise of the turn rate: its variance grows by
        ``rate_noise_deg_per_s² · dt`` per prediction (only with ``turn_rate_state``).

    Raises
    ------
    ValueError
        On a non-finite heading, a spread outside ``(0, MAX_SPREAD_DEG]``, or a rate
        spread outside ``(0, MAX_RATE_DEG_PER_S]`` or rate noise outside
        ``[0, MAX_RATE_DEG_PER_S]``.

    Examples
    --------
    >>> f = KalmanHeadingFilter()            # no idea where we look
    >>> f.update(350.0, 5.0)                 # a compass reading
    >>> f.predict(dtheta_deg=20.0, noise_deg=2.0)  # odometry: turned 20° left
    >>> round(f.estimate().heading_deg)
    10
    """

    #: Largest heading spread the state may have. A Gaussian this wide on a circle is
    #: uninformative anyway; keeping it bounded keeps the sigma points within ±62° of
    #: the mean, where wrapped residuals are exact. ``predict`` caps the heading
    #: variance at ``MAX_SPREAD_DEG²`` (keeping the heading/rate correlation).
    MAX_SPREAD_DEG: float = 360.0

    def __init__(
        self,
        heading_deg: float = 0.0,
        spread_deg: float = 180.0,
        *,
        turn_rate_state: bool = False,
        rate_spread_deg_per_s: float = 30.0,
        rate_noise_deg_per_s: float = 1.0,
    ) -> None:
        self._with_rate = bool(turn_rate_state)
        self._rate_spread = positive_float("rate_spread_deg_per_s", rate_spread_deg_per_s)
        if self._rate_spread > MAX_RATE_DEG_PER_S:
            raise ValueError(
                f"rate_spread_deg_per_s must be in (0, {MAX_RATE_DEG_PER_S:g}], "
                f"got {rate_spread_deg_per_s!r}"
            )
        self._rate_noise = _finite("rate_noise_deg_per_s", rate_noise_deg_per_s)
        if not 0.0 <= self._rate_noise <= MAX_RATE_DEG_PER_S:
            raise ValueError(
                f"rate_noise_deg_per_s must be in [0, {MAX_RATE_DEG_PER_S:g}], "
                f"got {rate_noise_deg_per_s!r}"
            )
        n = 2 if self._with_rate else 1
        self._points = MerweScaledSigmaPoints(n, alpha=_ALPHA, beta=_BETA, kappa=3.0 - n)
        self._ukf = UnscentedKalmanFilter(
            dim_x=n,
            dim_z=1,
            dt=1.0,
            hx=_hx,
            fx=self._fx,
            points=self._points,
            x_mean_fn=_mean,
            z_mean_fn=_mean,
            residual_x=_residual,
            residual_z=_residual,
        )
        self.reset(heading_deg, spread_deg)

    # ------------------------------------------------------------------ internals

    def _fx(self, x: np.ndarray, dt: float, dtheta_deg: float = 0.0) -> np.ndarray:
        """Motion model (eq. 19-21, 23): ``heading += dtheta (+ rate · dt)``."""
        out = np.array(x, dtype=np.float64)
        out[0] += dtheta_deg
        if self._with_rate:
            out[0] += x[1] * dt
        return out

    def _sync(self) -> None:
        """Wrap the heading to ``[0, 360)`` and symmetrise P."""
        ukf = self._ukf
        ukf.x = np.asarray(ukf.x, dtype=np.float64).copy()
        ukf.x[0] = wrap360(ukf.x[0])
        ukf.P = 0.5 * (ukf.P + ukf.P.T)

    def _cap_heading_variance(self) -> None:
        P = self._ukf.P
        cap = self.MAX_SPREAD_DEG**2
        if P[0, 0] > cap:
            s = math.sqrt(cap / P[0, 0])
            P[0, :] *= s
            P[:, 0] *= s

    # ------------------------------------------------------------------ public API

    @property
    def ukf(self) -> UnscentedKalmanFilter:
        """The underlying :class:`filterpy.kalman.UnscentedKalmanFilter`.

        For inspection (``ukf.P``, ``ukf.K``, ``ukf.y``, ``ukf.log_likelihood``,
        ``ukf.mahalanobis``). Writing to it bypasses this class's validation and
        wrapping.
        """
        return self._ukf

    @property
    def turn_rate_state(self) -> bool:
        """Whether the state includes a turn rate."""
        return self._with_rate

    @property
    def turn_rate_deg_per_s(self) -> float | None:
        """Estimated turn rate, or ``None`` without the rate state."""
        return float(self._ukf.x[1]) if self._with_rate else None

    def reset(self, heading_deg: float = 0.0, spread_deg: float = 180.0) -> None:
        """Restart from a Gaussian belief around ``heading_deg`` (eq. 25).

        The turn rate (if estimated) restarts at 0 with ``rate_spread_deg_per_s``.

        Parameters
        ----------
        heading_deg : float
            Initial heading, any finite value (wrapped to ``[0, 360)``).
        spread_deg : float
            Initial standard deviation, in ``(0, MAX_SPREAD_DEG]``; 180 = no idea.

        Raises
        ------
        ValueError
            On a non-finite heading or a spread outside ``(0, MAX_SPREAD_DEG]``.
        """
        h = _finite("heading_deg", heading_deg)
        s = positive_float("spread_deg", spread_deg)
        if s > self.MAX_SPREAD_DEG:
            raise ValueError(
                f"spread_deg must be <= {self.MAX_SPREAD_DEG} (use 180 for 'no idea'), "
                f"got {spread_deg!r}"
            )
        ukf = self._ukf
        if self._with_rate:
            ukf.x = np.array([h, 0.0])
            ukf.P = np.diag([s * s, self._rate_spread**2])
        else:
            ukf.x = np.array([h])
            ukf.P = np.array([[s * s]])
        ukf.Q = np.zeros_like(ukf.P)
        ukf.R = np.array([[1.0]])
        self._sync()
        ukf.x_prior, ukf.P_prior = ukf.x.copy(), ukf.P.copy()
        ukf.x_post, ukf.P_post = ukf.x.copy(), ukf.P.copy()

    def predict(self, dtheta_deg: float = 0.0, noise_deg: float = 1.0, dt: float = 1.0) -> None:
        """Motion update (eq. 19-21): shift the belief by the odometry turn (eq. 23).

        ``heading += dtheta_deg`` (plus ``rate · dt`` with the rate state); the heading
        variance grows by ``noise_deg²`` (and the rate variance by
        ``rate_noise_deg_per_s² · dt``). The heading variance is capped at
        ``MAX_SPREAD_DEG²``.

        Parameters
        ----------
        dtheta_deg : float
            Turn since the last step, CCW positive (odometry), degrees.
        noise_deg : float
            Standard deviation of the turn's error over this step, ``>= 0``.
        dt : float
            Duration of the step in seconds, in ``(0, MAX_DT_S]`` (only the rate state
            uses it).

        Raises
        ------
        ValueError
            On non-finite input, ``noise_deg`` outside ``[0, MAX_ABS_DEG]``,
            ``|dtheta_deg| > MAX_ABS_DEG`` or ``dt`` outside ``(0, MAX_DT_S]``.
        """
        d = _finite("dtheta_deg", dtheta_deg)
        q = _finite("noise_deg", noise_deg)
        if q < 0.0:
            raise ValueError(f"noise_deg must be >= 0, got {noise_deg!r}")
        if abs(d) > MAX_ABS_DEG or q > MAX_ABS_DEG:
            # larger values overflow the variance and break every later call
            raise ValueError(
                f"dtheta_deg and noise_deg must be within ±{MAX_ABS_DEG:g}, got "
                f"{dtheta_deg!r}, {noise_deg!r}"
            )
        step = positive_float("dt", dt)
        if step > MAX_DT_S:
            raise ValueError(f"dt must be in (0, {MAX_DT_S:g}] seconds, got {dt!r}")
        ukf = self._ukf
        if self._with_rate:
            ukf.Q = np.diag([q * q, self._rate_noise**2 * step])
        else:
            ukf.Q = np.array([[q * q]])
        ukf.predict(dt=step, dtheta_deg=d)
        self._cap_heading_variance()
        self._sync()
        ukf.x_prior, ukf.P_prior = ukf.x.copy(), ukf.P.copy()

    def update(self, heading_deg: float, spread_deg: float) -> None:
        """Sensor update with a heading measurement (the Kalman form of eq. 24).

        ``z = heading_deg``, ``R = spread_deg²``; the innovation is
        ``wrap180(z - predicted heading)``, so a reading of 1° against an estimate of
        359° is a +2° innovation.

        A measurement with ``spread_deg = inf`` (or so large that its variance
        overflows) carries no information and is skipped: the belief is unchanged. Large
        finite spreads are applied normally and move the belief very little.

        Parameters
        ----------
        heading_deg : float
            Measured heading, any finite value, degrees.
        spread_deg : float
            Standard deviation of the measurement, ``> 0`` (``inf`` = no information).

        Raises
        ------
        ValueError
            On a non-finite heading, or a spread that is NaN or below
            :data:`MIN_SPREAD_DEG` (a millionth of a degree).
        """
        z = _finite("heading_deg", heading_deg)
        if abs(z) > MAX_ABS_DEG:
            raise ValueError(f"heading_deg must be within ±{MAX_ABS_DEG:g}, got {heading_deg!r}")
        s = float(spread_deg)
        if math.isnan(s) or s <= 0.0:
            raise ValueError(f"spread_deg must be > 0, got {spread_deg!r}")
        var = s * s
        if not math.isfinite(var):
            return  # uninformative measurement: documented no-op
        if s < MIN_SPREAD_DEG:
            # a near-zero variance collapses the belief and breaks every later call
            raise ValueError(f"spread_deg must be >= {MIN_SPREAD_DEG:g}, got {spread_deg!r}")
        ukf = self._ukf
        # sigma points of the current belief (filterpy reuses those of the last predict),
        # so an update right after reset or a second update without predict is consistent
        ukf.sigmas_f = self._points.sigma_points(ukf.x, ukf.P)
        ukf.update(np.array([z]), R=np.array([[var]]))
        self._sync()
        ukf.x_post, ukf.P_post = ukf.x.copy(), ukf.P.copy()

    def update_from_sensor(
        self, sensor: HeadingSensor, observation: Any, grid_step_deg: float = 1.0
    ) -> HeadingEstimate:
        """Sensor update from any :class:`~vc_gym.filters.sensor_protocol.HeadingSensor`.

        The sensor's log-likelihood (eq. 22) is evaluated on a circular grid of headings
        ``0, step, ..., 360 - step``, normalised into a distribution (softmax, i.e. a
        uniform prior), and summarised as a Gaussian (eq. 25) by its circular mean
        (eq. 26) and circular standard deviation (eq. 27). These are the measurement
        ``z`` and ``sqrt(R)`` passed to :meth:`update`. The spread is floored at
        ``grid_step_deg / sqrt(12)`` (the spread of one grid bin), so a likelihood
        sharper than the grid cannot collapse the filter.

        A multi-modal likelihood is summarised by one Gaussian: its mean may lie between
        the modes, with a correspondingly large spread. A flat likelihood gives an
        infinite spread and no update.

        Parameters
        ----------
        sensor : HeadingSensor
            Anything with ``heading_log_likelihood(observation, headings_deg)``.
        observation : Any
            What the sensor reads, passed through unchanged.
        grid_step_deg : float
            Grid resolution in ``[MIN_HEADING_STEP_DEG, 90]``, must divide 360 (e.g.
            0.5, 1, 2, 4.5).

        Returns
        -------
        HeadingEstimate
            The measurement used. If every log-likelihood is ``-inf`` (the sensor rules
            out every heading) the filter is not updated, a :class:`RuntimeWarning` is
            issued, and the returned measurement is the current heading estimate with
            ``spread_deg = inf`` (which :meth:`update` would also ignore).

        Raises
        ------
        TypeError
            If ``sensor`` has no ``heading_log_likelihood`` method.
        ValueError
            On a bad grid step, or a likelihood of the wrong shape, with NaN or ``+inf``
            (see :func:`~vc_gym.filters.sensor_protocol.check_log_likelihood`).
        """
        if not isinstance(sensor, HeadingSensor):
            raise TypeError(
                f"sensor must have a heading_log_likelihood method, got {type(sensor).__name__}"
            )
        step = positive_float("grid_step_deg", grid_step_deg)
        # the finest grid any sensor takes: finer ones only cost memory and time
        n = steps_in_circle(step) if MIN_HEADING_STEP_DEG <= step <= 90.0 else None
        if n is None:
            raise ValueError(
                f"grid_step_deg must be in [{MIN_HEADING_STEP_DEG}, 90] and divide 360, "
                f"got {grid_step_deg!r}"
            )
        headings = np.arange(n, dtype=np.float64) * step
        who = type(sensor).__name__
        ll = check_log_likelihood(sensor.heading_log_likelihood(observation, headings), n, who)
        top = ll.max()
        if not np.isfinite(top):  # all -inf
            warnings.warn(
                f"{who} gave -inf log-likelihood for every heading; the Kalman filter "
                "was not updated",
                RuntimeWarning,
                stacklevel=2,
            )
            return HeadingEstimate(self.estimate().heading_deg, math.inf)
        p = np.exp(ll - top)  # -inf -> 0
        p /= p.sum()
        z = circular_mean(headings, p)
        spread = max(circular_std(headings, p), step / math.sqrt(12.0))
        self.update(z, spread)
        return HeadingEstimate(z, spread)

    def estimate(self) -> HeadingEstimate:
        """Current belief as heading and spread (eq. 25-27).

        Returns
        -------
        HeadingEstimate
            ``heading_deg`` in ``[0, 360)`` and ``spread_deg = sqrt(P[0, 0])``.
        """
        return HeadingEstimate(
            float(wrap360(self._ukf.x[0])), float(math.sqrt(max(self._ukf.P[0, 0], 0.0)))
        )

    def __repr__(self) -> str:
        e = self.estimate()
        rate = f", rate={self._ukf.x[1]:.3g} deg/s" if self._with_rate else ""
        return f"KalmanHeadingFilter(heading={e.heading_deg:.2f}, spread={e.spread_deg:.2f}{rate})"
