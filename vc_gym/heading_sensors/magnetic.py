"""A magnetometer heading: the true heading plus noise and a local disturbance field.

No camera: the sensor reads the robot's true heading (in a simulator, from the pose)
and adds what a real magnetometer suffers indoors (section 6 of the paper argues
against it): white noise, and a deviation that depends on *where* the robot is —
steel furniture, radiators and cables bend the earth's field by tens of degrees within
a metre or so of them. The filters get a likelihood that knows the noise but not the
disturbance, as a magnetometer driver would: near a source, the sensor is confidently
wrong.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass import Camera, CompassEstimate
from vc_gym.heading_sensors.base import estimate_of, heading_grid
from vc_gym.poses import check_pose
from vc_gym.validation import finite_float, int_at_least, nonnegative_float, positive_float

__all__ = ["DisturbanceSource", "MagnetometerCompass", "NoisyMagneticCompass"]


@dataclass(frozen=True)
class DisturbanceSource:
    """One object that bends the field: a Gaussian bump of deviation around it.

    Attributes
    ----------
    x_m, y_m : float
        Its position (world metres).
    deviation_deg : float
        Heading deviation right at it (signed, CCW positive).
    radius_m : float
        The bump's standard deviation: at ``radius_m`` the deviation is 61 % of its
        peak, at 2 × ``radius_m`` 14 %.
    """

    x_m: float
    y_m: float
    deviation_deg: float
    radius_m: float

    def __post_init__(self) -> None:
        for name in ("x_m", "y_m", "deviation_deg"):
            object.__setattr__(self, name, finite_float(name, getattr(self, name)))
        object.__setattr__(self, "radius_m", positive_float("radius_m", self.radius_m))
        if abs(self.deviation_deg) > 180.0:
            raise ValueError(f"deviation_deg must be within ±180, got {self.deviation_deg}")


class NoisyMagneticCompass:
    """A magnetometer as a heading sensor (a baseline for the visual compass).

    The reading at pose ``(x, y, θ)`` is ``θ + d(x, y) + n`` with ``n ~ N(0, noise_deg²)``
    and the disturbance ``d(x, y) = Σ_k A_k exp(-|p - c_k|² / (2 r_k²))`` of the
    :class:`DisturbanceSource` objects ``(c_k, A_k, r_k)``.

    The log-likelihood of heading ``h`` given a reading ``z`` is the wrapped Gaussian
    ``-wrap180(z - h)² / (2 σ²)`` with ``σ = model_noise_deg`` (default ``noise_deg``):
    the model knows the noise, not the disturbance.

    Parameters
    ----------
    noise_deg : float
        Standard deviation of the white noise (degrees, >= 0).
    sources : sequence of DisturbanceSource
        The objects that bend the field (default: none, an undisturbed sensor).
    model_noise_deg : float, optional
        σ of the likelihood the filters get (> 0; default ``max(noise_deg, 1)``).
    heading_step_deg : float
        Step of :attr:`headings_deg` (must divide 360).
    """

    #: Short name (as in :data:`vc_gym.heading_sensors.SENSORS`).
    name = "magnetic"

    def __init__(
        self,
        noise_deg: float = 3.0,
        sources: Sequence[DisturbanceSource] = (),
        model_noise_deg: float | None = None,
        heading_step_deg: float = 1.0,
    ):
        self.noise_deg = nonnegative_float("noise_deg", noise_deg)
        if noise_deg > 180.0:
            raise ValueError(f"noise_deg must be <= 180, got {noise_deg}")
        srcs = tuple(sources)
        if not all(isinstance(s, DisturbanceSource) for s in srcs):
            raise ValueError("sources must be DisturbanceSource objects")
        self.sources = srcs
        sigma = max(self.noise_deg, 1.0) if model_noise_deg is None else model_noise_deg
        self.model_noise_deg = positive_float("model_noise_deg", sigma)
        self._headings = heading_grid(heading_step_deg)
        self.heading_step_deg = float(heading_step_deg)

    @classmethod
    def random_field(
        cls,
        field_bounds: Sequence[float],
        rng: np.random.Generator,
        n_sources: int = 4,
        deviation_deg: float = 25.0,
        radius_m: float = 0.6,
        noise_deg: float = 3.0,
        **kwargs: object,
    ) -> NoisyMagneticCompass:
        """A compass with ``n_sources`` drawn uniformly over ``(x0, x1, y0, y1)``,
        each deviating by ``±deviation_deg`` (random sign, 50-100 % of it) with the
        given radius: steel furniture around a room."""
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        x0, x1, y0, y1 = (finite_float("field bound", v) for v in field_bounds)
        if not (x0 < x1 and y0 < y1):
            raise ValueError("field_bounds must be (x0, x1, y0, y1) with x0 < x1, y0 < y1")
        n = int_at_least("n_sources", n_sources, 0)
        dev = nonnegative_float("deviation_deg", deviation_deg)
        sources = [
            DisturbanceSource(
                float(rng.uniform(x0, x1)),
                float(rng.uniform(y0, y1)),
                float(rng.choice([-1.0, 1.0]) * dev * rng.uniform(0.5, 1.0)),
                radius_m,
            )
            for _ in range(n)
        ]
        return cls(noise_deg, sources, **kwargs)  # type: ignore[arg-type]

    @property
    def headings_deg(self) -> np.ndarray:
        """Candidate headings ``0, step, ..., 360 - step`` (read-only)."""
        return self._headings

    def disturbance_deg(self, x_m: float | np.ndarray, y_m: float | np.ndarray) -> np.ndarray:
        """Deviation of the field at ``(x, y)`` (degrees; arrays broadcast)."""
        x = np.asarray(x_m, dtype=np.float64)
        y = np.asarray(y_m, dtype=np.float64)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            raise ValueError("positions must be finite")
        d = np.zeros(np.broadcast(x, y).shape)
        for s in self.sources:
            d = d + s.deviation_deg * np.exp(
                -((x - s.x_m) ** 2 + (y - s.y_m) ** 2) / (2.0 * s.radius_m**2)
            )
        return d

    def read(self, pose: Sequence[float], rng: np.random.Generator) -> float:
        """The reading at the true pose ``(x, y, θ_deg)`` (degrees in ``[0, 360)``)."""
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        x, y, theta = check_pose(pose)
        noise = rng.normal(0.0, self.noise_deg) if self.noise_deg > 0 else 0.0
        return float(wrap360(theta + float(self.disturbance_deg(x, y)) + noise))

    @staticmethod
    def _reading(reading: object) -> float:
        if isinstance(reading, (bool, np.bool_)):
            raise ValueError("a reading must be a heading in degrees, got a bool")
        return finite_float("reading", reading)

    def log_likelihood(self, reading: float) -> np.ndarray:
        """``log p(reading | h)`` for every :attr:`headings_deg` (up to a constant)."""
        z = self._reading(reading)
        d = np.asarray(wrap180(z - self._headings), dtype=np.float64)
        return -0.5 * (d / self.model_noise_deg) ** 2

    def heading_log_likelihood(self, observation: float, headings_deg: np.ndarray) -> np.ndarray:
        """The filters' sensor protocol: the observation is a reading (degrees)."""
        z = self._reading(observation)
        d = np.asarray(wrap180(z - np.asarray(headings_deg, dtype=np.float64)), dtype=np.float64)
        return -0.5 * (d / self.model_noise_deg) ** 2

    def estimate(self, reading: float) -> CompassEstimate:
        """The heading the reading implies, the model's spread, and ``score`` 0.

        ``n_sectors`` is 1 (one reading).
        """
        return estimate_of(self.log_likelihood(reading), self._headings, 0.0, 1)

    def __repr__(self) -> str:
        return (
            f"NoisyMagneticCompass(noise_deg={self.noise_deg}, {len(self.sources)} sources, "
            f"model_noise_deg={self.model_noise_deg})"
        )


class MagnetometerCompass:
    """A magnetometer in the robot's head, offered as an image compass (simulation only).

    A tracker reads its heading sensor with each camera frame; this one ignores the frame
    and reads ``magnetometer`` at the head's true pose, which ``head_pose()`` returns
    (``(x, y, head yaw in degrees)`` from the simulator). So the grid tracker homes with
    a magnetometer where it would use a compass (``vc-gym experiment homing --sensor
    magnetic``). Nothing is learned.

    Parameters
    ----------
    magnetometer : NoisyMagneticCompass
        Noise and disturbance field.
    head_pose : callable
        ``head_pose() -> (x_m, y_m, yaw_deg)``: where the head is and looks now.
    rng : numpy.random.Generator
        The noise draws.
    """

    def __init__(
        self,
        magnetometer: NoisyMagneticCompass,
        head_pose: Callable[[], Sequence[float]],
        rng: np.random.Generator,
    ):
        if not isinstance(magnetometer, NoisyMagneticCompass):
            raise ValueError(
                f"magnetometer must be a NoisyMagneticCompass, got {type(magnetometer).__name__}"
            )
        if not callable(head_pose):
            raise ValueError("head_pose must be a callable returning (x, y, yaw_deg)")
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        self.magnetometer, self.head_pose, self.rng = magnetometer, head_pose, rng

    @property
    def headings_deg(self) -> np.ndarray:
        """The magnetometer's heading grid."""
        return self.magnetometer.headings_deg

    def learn(self, image: np.ndarray, camera: Camera) -> None:
        """Nothing to learn: a magnetometer knows north."""

    def _reading(self) -> float:
        return self.magnetometer.read(tuple(self.head_pose()), self.rng)

    def log_likelihood(self, image: np.ndarray, camera: Camera) -> np.ndarray:
        """The log-likelihood of one reading taken now (the image is not looked at)."""
        return self.magnetometer.log_likelihood(self._reading())

    def estimate(self, image: np.ndarray, camera: Camera) -> CompassEstimate:
        """The estimate of one reading taken now (the image is not looked at)."""
        return self.magnetometer.estimate(self._reading())
