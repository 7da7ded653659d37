"""Landmarks: the colour-class changes of the learned turns, placed in the room.

The learning phase turns on the spot at several known positions (home, the spots and,
in the ``pose-home`` mode, 0.5 m around each). A colour change on a wall (a door frame,
a poster's side) is seen by each of those turns at another bearing
(:func:`~vc_gym.compass.bearings.frame_bearings`); rays from two positions cross at the
change itself. :func:`learn_landmarks` finds, for every colour pair, the points where the
rays of at least ``min_positions`` positions cross within ``tolerance_deg`` (greedily,
the best supported first; a ray serves one landmark), and places each by weighted least
squares on its rays, with the covariance that the rays' angular scatter gives.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.bearings import FrameBearings
from vc_gym.validation import int_at_least, positive_float

__all__ = ["LandmarkMap", "LearnedView", "learn_landmarks"]


@dataclass(frozen=True)
class LearnedView:
    """One learning frame's changes, seen from a known pose.

    Attributes
    ----------
    bearings : FrameBearings
        The frame's changes (offsets relative to the camera's yaw).
    camera_yaw_deg : float
        World direction of the camera's optical axis (body heading plus head pan).
    x, y : float
        Where the frame was taken (m).
    """

    bearings: FrameBearings
    camera_yaw_deg: float
    x: float
    y: float


@dataclass(frozen=True)
class LandmarkMap:
    """Colour changes placed in the room.

    Attributes
    ----------
    positions : numpy.ndarray
        ``(M, 2)`` landmark positions (m).
    pairs : numpy.ndarray
        ``(M,)`` colour-pair code of each (``left * n_colors + right``, as the camera
        sees it from inside the room).
    std_m : numpy.ndarray
        ``(M,)`` position uncertainty, the root mean square of the covariance's axes.
    support : numpy.ndarray
        ``(M,)`` how many learning positions saw it.
    n_colors : int
        Number of colour classes of the map.
    """

    positions: np.ndarray
    pairs: np.ndarray
    std_m: np.ndarray
    support: np.ndarray
    n_colors: int

    def __len__(self) -> int:
        return int(self.pairs.size)


def _rays(views: Iterable[LearnedView]) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Every change of every view as a world ray: origins (R, 2), bearings (R,) in
    radians, pair codes (R,); and the number of colours."""
    origins, angles, pairs, n_colors = [], [], [], None
    for v in views:
        b = v.bearings
        if n_colors is None:
            n_colors = b.n_colors
        elif b.n_colors != n_colors:
            raise ValueError("the views' bearings use different colour classes")
        if not all(math.isfinite(t) for t in (v.camera_yaw_deg, v.x, v.y)):
            raise ValueError(f"a view's pose must be finite, got {(v.x, v.y, v.camera_yaw_deg)}")
        origins.append(np.broadcast_to([v.x, v.y], (len(b), 2)))
        angles.append(np.radians(v.camera_yaw_deg + b.offsets_deg))
        pairs.append(b.pairs)
    if n_colors is None:
        raise ValueError("no views to learn landmarks from")
    cat = np.concatenate
    return cat(origins).astype(np.float64), cat(angles), cat(pairs), n_colors


def _intersections(o: np.ndarray, a: np.ndarray, min_angle: float, max_range: float):
    """Points where two rays of different origins cross in front of both."""
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    i, j = np.triu_indices(len(a), k=1)
    cross = d[i, 0] * d[j, 1] - d[i, 1] * d[j, 0]
    ok = (np.abs(cross) > math.sin(min_angle)) & (np.hypot(*(o[i] - o[j]).T) > 1e-6)
    i, j, cross = i[ok], j[ok], cross[ok]
    w = o[j] - o[i]
    t = (w[:, 0] * d[j, 1] - w[:, 1] * d[j, 0]) / cross
    s = (w[:, 0] * d[i, 1] - w[:, 1] * d[i, 0]) / cross
    front = (t > 0.05) & (s > 0.05) & (t < max_range) & (s < max_range)
    return o[i[front]] + t[front, None] * d[i[front]]


def _fit(o: np.ndarray, a: np.ndarray, floor_rad: float) -> tuple[np.ndarray, float]:
    """Weighted least-squares point nearest the rays (perpendicular distance over range),
    twice (the ranges from the first answer), and its RMS position uncertainty."""
    normal = np.stack([-np.sin(a), np.cos(a)], axis=1)
    weights = np.ones(len(a))
    point = np.zeros(2)
    for _ in range(2):
        A = normal * weights[:, None]
        c = np.sum(normal * o, axis=1) * weights
        point = np.linalg.lstsq(A, c, rcond=None)[0]
        weights = 1.0 / np.maximum(np.hypot(*(point - o).T), 0.1)
    A = normal * weights[:, None]
    residual = (A @ point - np.sum(normal * o, axis=1) * weights)  # radians, about
    dof = max(len(a) - 2, 1)
    sigma = max(math.sqrt(float(residual @ residual) / dof), floor_rad)
    cov = sigma**2 * np.linalg.pinv(A.T @ A)
    return point, math.sqrt(max(float(np.trace(cov)) / 2.0, 0.0))


def learn_landmarks(
    views: Iterable[LearnedView],
    min_positions: int = 3,
    tolerance_deg: float = 1.0,
    min_angle_deg: float = 2.0,
    max_range_m: float = 20.0,
    resolution_deg: float = 0.15,
) -> LandmarkMap:
    """Place the colour changes that several learning positions saw in the room.

    Parameters
    ----------
    views : iterable of LearnedView
        The learning frames' changes with their known poses.
    min_positions : int
        Fewest distinct positions whose rays must cross at a landmark (at least 2).
    tolerance_deg : float
        Largest angle between a ray and the direction from its origin to a landmark for
        the ray to count as seeing it.
    min_angle_deg : float
        Smallest angle between two rays whose crossing is a candidate.
    max_range_m : float
        Farthest a landmark may lie from the positions that saw it.
    resolution_deg : float
        Smallest angular scatter assumed for a landmark's rays (sub-pixel columns).

    Returns
    -------
    LandmarkMap
    """
    int_at_least("min_positions", min_positions, 2)
    tol = math.radians(positive_float("tolerance_deg", tolerance_deg))
    min_angle = math.radians(positive_float("min_angle_deg", min_angle_deg))
    max_range = positive_float("max_range_m", max_range_m)
    floor = math.radians(positive_float("resolution_deg", resolution_deg))
    origins, angles, pairs, n_colors = _rays(views)
    found: list[tuple[np.ndarray, int, float, int]] = []
    for pair in np.unique(pairs):
        sel = np.flatnonzero(pairs == pair)
        o, a = origins[sel], angles[sel]
        _, where = np.unique(np.round(o, 6), axis=0, return_inverse=True)
        where = where.reshape(-1)
        free = np.ones(len(a), bool)
        while free.sum() >= min_positions:
            idx = np.flatnonzero(free)
            points = _intersections(o[idx], a[idx], min_angle, max_range)
            if len(points) == 0:
                break
            # which free rays see each candidate (angle to it within the tolerance)
            to = points[:, None, :] - o[idx][None, :, :]
            miss = np.angle(np.exp(1j * (np.arctan2(to[..., 1], to[..., 0]) - a[idx][None])))
            sees = np.abs(miss) < tol
            # distinct positions among each candidate's rays
            at = np.zeros((len(idx), int(where.max()) + 1))
            at[np.arange(len(idx)), where[idx]] = 1.0
            support = np.count_nonzero(sees.astype(np.float64) @ at, axis=1)
            best = int(np.argmax(support))
            if support[best] < min_positions:
                break
            rays = idx[sees[best]]
            point, std = _fit(o[rays], a[rays], floor)
            found.append((point, int(pair), std, int(support[best])))
            free[rays] = False
    if not found:
        none = np.zeros(0, np.int64)
        return LandmarkMap(np.zeros((0, 2)), none, np.zeros(0), none, n_colors)
    return LandmarkMap(
        np.array([f[0] for f in found], np.float64),
        np.array([f[1] for f in found], np.int64),
        np.array([f[2] for f in found], np.float64),
        np.array([f[3] for f in found], np.int64),
        n_colors,
    )
