"""Sensor models as the filters see them (paper 3.5.2, eq. 22).

A filter never imports the compass. It asks a sensor model for log-likelihoods of the
states it cares about:

* a :class:`HeadingSensor` answers for headings (a grid filter's bins, a Kalman
  filter's measurement is derived from them);
* a :class:`PoseSensor` answers for an array of ``(x, y, θ)`` poses (particles).

Anything with the right method is a sensor: the visual compass and the several-spot
atlas through the adapters in :mod:`vc_gym.localization.compass_sensors`, the baselines, and the
test doubles in :mod:`vc_gym.filters.synthetic_sensors`.

Log-likelihoods may be shifted by any constant (only differences matter) and may be
``-inf`` for impossible states; ``NaN`` and ``+inf`` are errors.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ["HeadingSensor", "PoseSensor", "check_log_likelihood", "check_pose_query"]


@runtime_checkable
class HeadingSensor(Protocol):
    """A sensor model over headings."""

    def heading_log_likelihood(self, observation: Any, headings_deg: np.ndarray) -> np.ndarray:
        """``log p(observation | heading)`` for every heading in ``headings_deg``.

        Parameters
        ----------
        observation : Any
            Whatever the sensor reads (a camera image, a simulated reading, ...).
        headings_deg : numpy.ndarray
            ``(N,)`` headings in degrees, CCW positive.

        Returns
        -------
        numpy.ndarray
            ``(N,)`` float log-likelihoods (up to a constant).
        """
        ...


@runtime_checkable
class PoseSensor(Protocol):
    """A sensor model over planar poses ``(x, y, θ)``."""

    def pose_log_likelihood(self, observation: Any, poses: np.ndarray) -> np.ndarray:
        """``log p(observation | pose)`` for every row of ``poses``.

        Parameters
        ----------
        observation : Any
            Whatever the sensor reads.
        poses : numpy.ndarray
            ``(N, 3)`` array of ``x`` (m), ``y`` (m), ``θ`` (degrees, CCW positive).

        Returns
        -------
        numpy.ndarray
            ``(N,)`` float log-likelihoods (up to a constant).
        """
        ...


def check_log_likelihood(ll: object, n: int, who: str = "sensor") -> np.ndarray:
    """Validate a sensor's answer: shape ``(n,)``, no NaN, no ``+inf``.

    Returns it as ``float64``. ``-inf`` entries are allowed (impossible states).

    Raises
    ------
    ValueError
        Naming the sensor, the expected and the received shape, or the bad values.
    """
    a = np.asarray(ll, dtype=np.float64)
    if a.shape != (n,):
        raise ValueError(f"{who} returned log-likelihoods of shape {a.shape}, expected ({n},)")
    if np.isnan(a).any():
        raise ValueError(f"{who} returned NaN log-likelihoods ({int(np.isnan(a).sum())} of {n})")
    if np.isposinf(a).any():
        raise ValueError(f"{who} returned +inf log-likelihoods")
    return a


def check_pose_query(poses: object, head_pan_deg: object) -> tuple[np.ndarray, float]:
    """Validate a pose sensor's question: ``(N, 3)`` finite poses and a finite head pan.

    Returns them as a ``float64`` array and a float.

    Raises
    ------
    ValueError
        Naming the wrong shape, the non-finite poses or the head pan.
    """
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"poses must have shape (N, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("poses must be finite")
    if isinstance(head_pan_deg, bool) or not isinstance(head_pan_deg, (int, float, np.number)):
        raise ValueError(f"head_pan_deg must be a number, got {head_pan_deg!r}")
    if not np.isfinite(head_pan_deg):
        raise ValueError(f"head_pan_deg must be finite, got {head_pan_deg!r}")
    return p, float(head_pan_deg)
