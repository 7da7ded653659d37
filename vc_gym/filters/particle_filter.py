"""A particle filter over planar poses ``(x, y, θ)`` (paper 3.5, eq. 17-21).

The paper states localisation as the Bayes filter of eq. 17-18,

* eq. 17, sensor update: ``p(x_t | u_t, z_t) ∝ p(z_t | x_t) p(x_t | u_t)``;
* eq. 18, prediction: ``p(x_t | u_t) = ∫ p(x_t | u_t, x_{t-1}) p(x_{t-1} | ...) dx_{t-1}``,

and notes that the integral is "typically approximated (for example using a probability
grid, a Kalman filter or Monte-Carlo methods)". This module is the Monte-Carlo
approximation: the belief is a set of ``N`` weighted poses (particles). The motion
model is eq. 19-21, ``x_t = x_{t-1} + Δx_t`` split into rotation ``φ_t = φ_{t-1} + u^φ_t``
and translation ``τ_t = τ_{t-1} + u^τ_t``, where the odometry ``Δx_t`` is measured in
the robot frame and therefore rotated by each particle's own heading before it is
added. The sensor model is any :class:`~vc_gym.filters.sensor_protocol.PoseSensor` (for the
visual compass, eq. 22 through the adapters).

Conventions: ``x`` east and ``y`` north in metres, ``θ`` in degrees counter-clockwise
from the ``x`` axis, stored wrapped to ``[0, 360)``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from vc_gym.angles import circular_mean, circular_std, wrap360
from vc_gym.filters.sensor_protocol import PoseSensor, check_log_likelihood
from vc_gym.validation import MAX_ABS_DEG, MAX_ABS_METRES

__all__ = ["MAX_PARTICLES", "ParticleFilter", "PoseEstimate", "check_particle_count"]

#: Most particles a filter holds. A step allocates about 120 bytes a particle (poses,
#: log-weights, noise draws, the sensor's answer; measured with tracemalloc): 120 MB
#: and about 0.1 s a step at a million, already far more than a planar pose needs,
#: while 10**9 would ask for 120 GB.
MAX_PARTICLES = 1_000_000


def check_particle_count(n_particles: object) -> int:
    """``n_particles`` as an int in ``[1, MAX_PARTICLES]``, else a ``ValueError``."""
    if (
        isinstance(n_particles, bool)
        or not isinstance(n_particles, (int, np.integer))
        or not 1 <= n_particles <= MAX_PARTICLES
    ):
        raise ValueError(
            f"n_particles must be an integer in [1, {MAX_PARTICLES:_}], got {n_particles!r}"
        )
    return int(n_particles)


@dataclass(frozen=True)
class PoseEstimate:
    """A particle belief summarised by its weighted moments.

    Attributes
    ----------
    x, y : float
        Weighted mean position in metres.
    heading_deg : float
        Weighted circular mean of the headings, in ``[0, 360)`` (never an arithmetic
        mean of angles).
    std_xy : tuple of float
        Weighted standard deviations of ``x`` and ``y`` in metres.
    spread_deg : float
        Weighted circular standard deviation ``sqrt(-2 ln R)`` of the headings in
        degrees; ``inf`` if the headings cancel out exactly.
    ess : float
        Effective sample size ``1 / Σ w_i²`` of the weights, in ``[1, N]``.
    """

    x: float
    y: float
    heading_deg: float
    std_xy: tuple[float, float]
    spread_deg: float
    ess: float


def _motion(name: str, value: object, *, nonneg: bool = False) -> np.ndarray:
    """:func:`_triple` within the physical limits of one input (metres, metres,
    degrees): beyond them positions overflow to inf and the estimate becomes NaN."""
    a = _triple(name, value, nonneg=nonneg)
    if max(abs(a[0]), abs(a[1])) > MAX_ABS_METRES or abs(a[2]) > MAX_ABS_DEG:
        raise ValueError(
            f"{name} must be within ±{MAX_ABS_METRES:g} m and ±{MAX_ABS_DEG:g}°, got {value!r}"
        )
    return a


def _triple(name: str, value: object, *, nonneg: bool = False) -> np.ndarray:
    """``value`` as a finite float64 array of shape ``(3,)`` (optionally all >= 0)."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be three real numbers, got {value!r}") from None
    if a.shape != (3,):
        raise ValueError(f"{name} must have three entries, got shape {a.shape}: {value!r}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if nonneg and np.any(a < 0):
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return a


def _check_rng(rng: object) -> np.random.Generator:
    if not isinstance(rng, np.random.Generator):
        raise ValueError(
            f"rng must be a numpy.random.Generator (e.g. np.random.default_rng(seed)), "
            f"got {type(rng).__name__}"
        )
    return rng


def _fraction(name: str, value: object, *, upper_open: bool) -> float:
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    ok = 0.0 <= v < 1.0 if upper_open else 0.0 <= v <= 1.0
    if not ok:
        interval = "[0, 1)" if upper_open else "[0, 1]"
        raise ValueError(f"{name} must be in {interval}, got {value!r}")
    return v


class ParticleFilter:
    """Monte-Carlo localisation over planar poses (paper 3.5, eq. 17-21).

    Parameters
    ----------
    n_particles : int
        Number of particles ``N``, in ``[1, MAX_PARTICLES]``.
    bounds : tuple of float or None
        ``(xmin, xmax, ymin, ymax)`` of the field in metres. Used only to draw uniform
        poses (global initialisation and injection); particles are never clipped to
        it, the robot may leave the field.
    rng : numpy.random.Generator or None
        Source of all randomness (motion noise, resampling, injection, uniform
        initialisation). ``None`` means ``np.random.default_rng(0)``: the filter is
        reproducible by default; pass your own Generator for independent runs.
    resample_threshold : float
        :meth:`update` resamples automatically when the effective sample size falls
        below ``resample_threshold * N``. In ``[0, 1]``; ``0`` never resamples
        automatically.
    inject_fraction : float
        Fraction of particles replaced by uniform random poses in ``bounds`` at every
        resampling (recovery from kidnapping). In ``[0, 1)``; ``> 0`` requires
        ``bounds``.

    Raises
    ------
    ValueError
        On any invalid argument (see the parameter descriptions).

    Notes
    -----
    The weights are kept as float64 log-weights normalised to ``logsumexp = 0``, so
    long runs of sharp likelihoods do not underflow. Every operation is vectorised
    over the particles.

    Initially the particles are uniform over ``bounds`` with uniform heading, or, if
    there are no bounds, all at the origin with heading 0: call :meth:`reset` with a
    mean then.

    If a sensor reports ``-inf`` for every particle that still has weight, the update
    is skipped with a ``RuntimeWarning`` and the belief is kept unchanged (an
    "everything is impossible" answer carries no usable information about where the
    robot is, and would otherwise leave the weights undefined).

    Examples
    --------
    >>> from vc_gym.filters.synthetic_sensors import GaussianPoseSensor
    >>> pf = ParticleFilter(500, bounds=(-3, 3, -2, 2), rng=np.random.default_rng(1))
    >>> pf.predict((0.1, 0.0, 5.0))
    >>> ess = pf.update(GaussianPoseSensor(0.2, 10.0), np.array([0.5, 0.5, 90.0]))
    >>> est = pf.estimate()
    """

    def __init__(
        self,
        n_particles: int = 1000,
        *,
        bounds: tuple[float, float, float, float] | None = None,
        rng: np.random.Generator | None = None,
        resample_threshold: float = 0.5,
        inject_fraction: float = 0.0,
    ) -> None:
        self._n = check_particle_count(n_particles)
        self._bounds = None if bounds is None else self._check_bounds(bounds)
        self._rng = np.random.default_rng(0) if rng is None else _check_rng(rng)
        self._threshold = _fraction("resample_threshold", resample_threshold, upper_open=False)
        self._inject = _fraction("inject_fraction", inject_fraction, upper_open=True)
        if self._inject > 0 and self._bounds is None:
            raise ValueError("inject_fraction > 0 needs bounds to draw the injected poses from")
        self._logw = np.full(self._n, -math.log(self._n))
        if self._bounds is not None:
            self._particles = self._uniform_poses(self._n)
        else:
            self._particles = np.zeros((self._n, 3))

    # ------------------------------------------------------------------ properties

    @staticmethod
    def _check_bounds(bounds: object) -> tuple[float, float, float, float]:
        try:
            b = np.asarray(bounds, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"bounds must be (xmin, xmax, ymin, ymax), got {bounds!r}") from None
        if b.shape != (4,) or not np.all(np.isfinite(b)):
            raise ValueError(f"bounds must be four finite numbers, got {bounds!r}")
        if np.any(np.abs(b) > MAX_ABS_METRES):
            raise ValueError(f"bounds must lie within ±{MAX_ABS_METRES:g} m, got {bounds!r}")
        if not (b[0] < b[1] and b[2] < b[3]):
            raise ValueError(f"bounds need xmin < xmax and ymin < ymax, got {bounds!r}")
        return (float(b[0]), float(b[1]), float(b[2]), float(b[3]))

    @property
    def n_particles(self) -> int:
        """Number of particles ``N`` (constant)."""
        return self._n

    @property
    def bounds(self) -> tuple[float, float, float, float] | None:
        """``(xmin, xmax, ymin, ymax)`` or ``None``."""
        return self._bounds

    @property
    def resample_threshold(self) -> float:
        """Automatic resampling when ``ESS < resample_threshold * N``."""
        return self._threshold

    @property
    def inject_fraction(self) -> float:
        """Fraction of particles replaced by uniform poses at every resampling."""
        return self._inject

    @property
    def particles(self) -> np.ndarray:
        """A copy of the ``(N, 3)`` particle poses ``x`` (m), ``y`` (m), ``θ`` (deg)."""
        return self._particles.copy()

    @property
    def weights(self) -> np.ndarray:
        """A copy of the ``(N,)`` normalised weights (sum 1)."""
        w = np.exp(self._logw)
        return w / w.sum()

    @property
    def log_weights(self) -> np.ndarray:
        """A copy of the ``(N,)`` normalised log-weights (``logsumexp = 0``)."""
        return self._logw.copy()

    @property
    def ess(self) -> float:
        """Effective sample size ``1 / Σ w_i²`` of the current weights, in ``[1, N]``."""
        return self._ess(self.weights)

    def _ess(self, w: np.ndarray) -> float:
        # clipped: with uniform weights round-off can give N(1 + 1e-16)
        return min(max(float(1.0 / np.dot(w, w)), 1.0), float(self._n))

    # ------------------------------------------------------------------ set-up

    def _uniform_poses(self, k: int) -> np.ndarray:
        """``k`` poses uniform in ``bounds`` with uniform heading in ``[0, 360)``."""
        assert self._bounds is not None
        xmin, xmax, ymin, ymax = self._bounds
        out = np.empty((k, 3))
        out[:, 0] = self._rng.uniform(xmin, xmax, k)
        out[:, 1] = self._rng.uniform(ymin, ymax, k)
        out[:, 2] = self._rng.uniform(0.0, 360.0, k)
        return out

    def reset(
        self,
        mean: tuple[float, float, float] | None = None,
        std: tuple[float, float, float] | None = None,
        *,
        rng: np.random.Generator | None = None,
    ) -> None:
        """Re-initialise the belief; weights become uniform.

        Parameters
        ----------
        mean : tuple of float or None
            ``(x, y, θ)``: draw the particles from a Gaussian around it (θ wrapped to
            ``[0, 360)``). ``None``: uniform over ``bounds`` with uniform heading
            (global localisation); needs ``bounds``.
        std : tuple of float or None
            Standard deviations ``(σx m, σy m, σθ deg)``, all finite and >= 0. ``None``
            means zero (all particles exactly at ``mean``). Only allowed with a mean.
            Mean and std lie within a million metres and a billion degrees.
        rng : numpy.random.Generator or None
            If given, it replaces the filter's Generator (before drawing), which makes
            ``reset(rng=np.random.default_rng(seed))`` a full re-seed.

        Raises
        ------
        ValueError
            Non-finite mean/std, negative std, either beyond a million metres or a
            billion degrees, ``std`` without ``mean``, uniform initialisation without
            ``bounds``, or an ``rng`` that is not a Generator.
        """
        if rng is not None:
            self._rng = _check_rng(rng)
        if mean is None:
            if std is not None:
                raise ValueError("std given without mean; a uniform reset has no std")
            if self._bounds is None:
                raise ValueError("reset() without a mean draws uniform poses and needs bounds")
            self._particles = self._uniform_poses(self._n)
        else:
            m = _motion("mean", mean)
            s = np.zeros(3) if std is None else _motion("std", std, nonneg=True)
            p = m + self._rng.standard_normal((self._n, 3)) * s
            p[:, 2] = wrap360(p[:, 2])
            self._particles = p
        self._logw = np.full(self._n, -math.log(self._n))

    # ------------------------------------------------------------------ filter steps

    def predict(
        self,
        odometry: tuple[float, float, float],
        noise: tuple[float, float, float] = (0.02, 0.02, 2.0),
    ) -> None:
        """Motion update with robot-frame odometry (paper eq. 18-21).

        Every particle ``i`` draws its own noisy odometry
        ``(f + ε_f, l + ε_l, Δθ + ε_θ)`` with ``ε ~ N(0, noise)`` and applies it in its
        own frame (eq. 19, ``x_t = x_{t-1} + Δx_t``; the translation ``u^τ`` of eq. 21
        is the robot-frame displacement rotated by the particle's previous heading,
        the rotation ``u^φ`` of eq. 20 is added to it)::

            x += f' cos θ - l' sin θ
            y += f' sin θ + l' cos θ
            θ  = wrap360(θ + Δθ')

        Positions are not clipped to ``bounds``.

        Parameters
        ----------
        odometry : tuple of float
            ``(forward m, left m, dθ deg)`` travelled since the last step, in the robot
            frame at the previous pose.
        noise : tuple of float
            Standard deviations ``(σ_forward m, σ_left m, σ_dθ deg)`` of the additive
            Gaussian motion noise; finite and >= 0.

        Raises
        ------
        ValueError
            Non-finite odometry, or negative / non-finite noise, or either beyond a
            million metres or a billion degrees.
        """
        u = _motion("odometry", odometry)
        s = _motion("noise", noise, nonneg=True)
        d = u + self._rng.standard_normal((self._n, 3)) * s
        th = np.radians(self._particles[:, 2])
        c, sn = np.cos(th), np.sin(th)
        p = self._particles
        p[:, 0] += d[:, 0] * c - d[:, 1] * sn
        p[:, 1] += d[:, 0] * sn + d[:, 1] * c
        p[:, 2] = wrap360(p[:, 2] + d[:, 2])

    def update(
        self,
        sensor: PoseSensor,
        observation: Any,
        inject: Callable[[int], np.ndarray] | None = None,
    ) -> float:
        """Sensor update, ``w_i ∝ w_i · p(z | x_i)`` in the log domain (paper eq. 17).

        The log-likelihoods are validated with
        :func:`~vc_gym.filters.sensor_protocol.check_log_likelihood`, added to the
        log-weights and normalised with log-sum-exp. If the effective sample size then
        falls below ``resample_threshold * N``, :meth:`resample` runs.

        Parameters
        ----------
        sensor : PoseSensor
            Anything with ``pose_log_likelihood(observation, poses)``; it receives a
            read-only ``(N, 3)`` view of the particles.
        observation : Any
            Passed through to the sensor.
        inject : callable, optional
            Passed to :meth:`resample` if this update resamples.

        Returns
        -------
        float
            The effective sample size right after the weight update, i.e. *before* a
            possible automatic resampling (afterwards it is always ``N``). If the
            update was skipped (see below), the unchanged current ESS.

        Raises
        ------
        ValueError
            If the sensor returns a wrong shape, ``NaN`` or ``+inf``.

        Warns
        -----
        RuntimeWarning
            If every particle that has weight gets log-likelihood ``-inf``; the update
            is then skipped and the belief kept.
        """
        view = self._particles.view()
        view.flags.writeable = False
        ll = check_log_likelihood(
            sensor.pose_log_likelihood(observation, view), self._n, type(sensor).__name__
        )
        logw = self._logw + ll
        top = float(np.max(logw))
        if top == -math.inf:
            warnings.warn(
                f"{type(sensor).__name__} gave log-likelihood -inf to every particle; "
                "update skipped, belief kept",
                RuntimeWarning,
                stacklevel=2,
            )
            return self.ess
        logw -= top + math.log(float(np.sum(np.exp(logw - top))))
        self._logw = logw
        ess = self.ess
        if ess < self._threshold * self._n:
            self.resample(inject)
        return ess

    def resample(self, inject: Callable[[int], np.ndarray] | None = None) -> None:
        """Systematic resampling, then optional injection of uniform poses.

        One offset ``u ~ U[0, 1/N)`` is drawn from the filter's Generator and the
        particles at the positions ``u + k/N``, ``k = 0 … N-1``, of the cumulative
        weights are copied (low variance; a particle of weight ``w`` is copied
        ``floor(Nw)`` or ``ceil(Nw)`` times; zero-weight particles never survive).
        Weights become uniform. Then, if ``inject_fraction > 0``,
        ``round(inject_fraction * N)`` particles chosen at random (without
        replacement) are replaced by uniform poses in ``bounds`` with uniform heading,
        so that the filter can recover when the robot was kidnapped. ``inject(k)``,
        if given, draws the ``k`` injected poses instead (e.g. from the current
        measurement: "sensor resetting", Lenser & Veloso 2000); it must return a
        finite ``(k, 3)`` array.

        filterpy's resampling helpers are deliberately not used: they draw from
        NumPy's global random state, which would break reproducibility.

        Notes
        -----
        Injected particles carry the same weight ``1/N`` as the others until the next
        :meth:`update` weighs them, so an :meth:`estimate` taken right after an
        injecting resampling (including the automatic one inside :meth:`update`) is
        pulled towards the middle of ``bounds`` by about ``inject_fraction`` times the
        distance between the belief and the field centre (e.g. 5% of 2 m = 0.1 m),
        and its spread is inflated accordingly.
        """
        w = self.weights
        alive = np.flatnonzero(w > 0)
        cum = np.cumsum(w[alive])
        cum /= cum[-1]
        cum[-1] = 1.0  # guard against round-off: every position < 1 finds a particle
        positions = (self._rng.random() + np.arange(self._n)) / self._n
        idx = np.searchsorted(cum, positions, side="right")
        np.minimum(idx, alive.size - 1, out=idx)
        self._particles = self._particles[alive[idx]]
        self._logw = np.full(self._n, -math.log(self._n))
        k = int(round(self._inject * self._n))
        if k > 0:
            replace = self._rng.choice(self._n, size=k, replace=False)
            if inject is None:
                self._particles[replace] = self._uniform_poses(k)
            else:
                self.replace(replace, inject(k))

    def replace(self, indices: np.ndarray, poses: np.ndarray) -> None:
        """Overwrite the particles at ``indices`` with ``poses``; weights are unchanged.

        For trackers that inject particles drawn from a sensor ("sensor resetting",
        Lenser & Veloso 2000) instead of uniformly. Headings are wrapped to ``[0, 360)``.

        Raises
        ------
        ValueError
            Indices out of range or repeated, or poses that are not a finite
            ``(len(indices), 3)`` array within a million metres and a billion degrees.
        """
        idx = np.asarray(indices)
        if idx.ndim != 1 or idx.dtype.kind not in "iu":
            raise ValueError(f"indices must be a 1-d integer array, got {indices!r}")
        if idx.size and (idx.min() < 0 or idx.max() >= self._n):
            raise ValueError(f"indices must lie in [0, {self._n}), got {idx.min()}..{idx.max()}")
        if np.unique(idx).size != idx.size:
            raise ValueError("indices must not repeat")
        p = np.asarray(poses, dtype=np.float64)
        if p.shape != (idx.size, 3) or not np.all(np.isfinite(p)):
            raise ValueError(f"poses must be a finite ({idx.size}, 3) array, got shape {p.shape}")
        if np.any(np.abs(p[:, :2]) > MAX_ABS_METRES) or np.any(np.abs(p[:, 2]) > MAX_ABS_DEG):
            raise ValueError(f"poses must lie within ±{MAX_ABS_METRES:g} m and ±{MAX_ABS_DEG:g}°")
        p = p.copy()
        p[:, 2] = wrap360(p[:, 2])
        self._particles[idx] = p

    def estimate(self) -> PoseEstimate:
        """Weighted mean and spread of the belief.

        Returns
        -------
        PoseEstimate
            Weighted mean and standard deviation of ``x`` and ``y``, circular mean and
            circular standard deviation of ``θ`` (as paper eq. 26-27 for the heading
            filter) and the effective sample size.
        """
        w = self.weights
        xy = self._particles[:, :2]
        mean = w @ xy
        var = w @ (xy - mean) ** 2
        std = np.sqrt(np.maximum(var, 0.0))
        th = self._particles[:, 2]
        return PoseEstimate(
            x=float(mean[0]),
            y=float(mean[1]),
            heading_deg=circular_mean(th, w),
            std_xy=(float(std[0]), float(std[1])),
            spread_deg=circular_std(th, w),
            ess=self._ess(w),
        )
