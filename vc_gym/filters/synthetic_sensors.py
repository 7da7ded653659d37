"""Simple sensor models with known noise: test doubles and baselines for the filters."""

from __future__ import annotations

import math

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.validation import positive_float

__all__ = ["VonMisesHeadingSensor", "GaussianPoseSensor"]


def _i0e(kappa: float) -> float:
    """Exponentially scaled Bessel function ``I0(κ) e^-κ`` without overflow."""
    if kappa < 100.0:
        return float(np.i0(kappa)) * math.exp(-kappa)
    # asymptotic expansion, relative error < 1e-6 for κ >= 100
    return (1.0 + 1.0 / (8.0 * kappa) + 9.0 / (128.0 * kappa**2)) / math.sqrt(2 * math.pi * kappa)


class VonMisesHeadingSensor:
    """A heading sensor that reads the true heading plus von Mises noise.

    The observation is a heading reading in degrees; the likelihood of heading ``φ``
    is ``κ cos(reading - φ)`` with ``κ = 1 / σ²`` (σ in radians), i.e. approximately a
    Gaussian of standard deviation ``noise_deg``.

    Parameters
    ----------
    noise_deg : float
        Standard deviation of the reading noise.
    outlier_prob : float
        Probability that a reading is uniformly random (a wrong compass answer); the
        likelihood then has a floor, as a robust sensor model should.
    """

    def __init__(self, noise_deg: float = 5.0, outlier_prob: float = 0.0):
        self.noise_deg = positive_float("noise_deg", noise_deg)
        if not 0.0 <= outlier_prob < 1.0:
            raise ValueError(f"outlier_prob must be in [0, 1), got {outlier_prob}")
        self.outlier_prob = float(outlier_prob)
        self.kappa = 1.0 / math.radians(self.noise_deg) ** 2

    def read(self, true_heading_deg: float, rng: np.random.Generator) -> float:
        """A noisy reading of ``true_heading_deg`` drawn with ``rng``."""
        if rng.random() < self.outlier_prob:
            return float(rng.uniform(0.0, 360.0))
        return float(true_heading_deg + math.degrees(rng.vonmises(0.0, self.kappa)))

    def heading_log_likelihood(self, observation: float, headings_deg: np.ndarray) -> np.ndarray:
        """Log-likelihood of every heading given the reading ``observation`` (degrees)."""
        z = float(observation)
        if not math.isfinite(z):
            raise ValueError(f"reading must be finite, got {observation!r}")
        d = np.radians(wrap180(z - np.asarray(headings_deg, dtype=np.float64)))
        ll = self.kappa * (np.cos(d) - 1.0)
        if self.outlier_prob > 0:
            # mixture with a uniform density, in the log domain
            dens = np.exp(ll) / (2 * math.pi * _i0e(self.kappa))
            ll = np.log((1 - self.outlier_prob) * dens + self.outlier_prob / (2 * math.pi))
        return ll

    def pose_log_likelihood(self, observation: float, poses: np.ndarray) -> np.ndarray:
        """Heading-only pose sensor: the likelihood depends on ``θ`` alone."""
        return self.heading_log_likelihood(observation, np.asarray(poses)[:, 2])


class GaussianPoseSensor:
    """A pose sensor reading ``(x, y, θ)`` with Gaussian position and heading noise.

    Parameters
    ----------
    pos_noise_m : float
        Standard deviation of the x and y readings.
    heading_noise_deg : float or None
        Standard deviation of the heading reading; ``None`` reads position only.
    """

    def __init__(self, pos_noise_m: float = 0.2, heading_noise_deg: float | None = 10.0):
        self.pos_noise_m = positive_float("pos_noise_m", pos_noise_m)
        self.heading_noise_deg = (
            None
            if heading_noise_deg is None
            else positive_float("heading_noise_deg", heading_noise_deg)
        )

    def read(self, true_pose: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """A noisy reading of the pose ``(x, y, θ)``."""
        x, y, th = (float(v) for v in true_pose)
        noise_th = 0.0 if self.heading_noise_deg is None else rng.normal(0, self.heading_noise_deg)
        return np.array(
            [
                x + rng.normal(0, self.pos_noise_m),
                y + rng.normal(0, self.pos_noise_m),
                th + noise_th,
            ]
        )

    def pose_log_likelihood(self, observation: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Log-likelihood of every pose given the reading ``observation``."""
        z = np.asarray(observation, dtype=np.float64)
        if z.shape != (3,) or not np.all(np.isfinite(z)):
            raise ValueError(f"reading must be a finite (x, y, θ) triple, got {observation!r}")
        p = np.asarray(poses, dtype=np.float64)
        d2 = (p[:, 0] - z[0]) ** 2 + (p[:, 1] - z[1]) ** 2
        ll = -0.5 * d2 / self.pos_noise_m**2
        if self.heading_noise_deg is not None:
            dth = wrap180(p[:, 2] - z[2])
            ll = ll - 0.5 * (dth / self.heading_noise_deg) ** 2
        return ll
