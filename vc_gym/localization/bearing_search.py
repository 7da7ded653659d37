"""Where on the field one frame's colour changes fit the landmarks: a global search.

A particle cloud that has lost the robot, or never had it (a kidnapping far from the
learned spots, whose maps place it poorly), needs candidate poses near the truth. The
landmarks are seen from anywhere, so one frame's changes can propose them: seen from a
camera position ``E``, a change at offset ``o`` of the optical axis that is landmark
``L`` (of its colour pair) puts the axis at ``ψ = atan2(L - E) - o``. Over a grid of
camera positions every (change, landmark of its pair) votes for its ``ψ``; where many
changes agree on one direction (a Hough vote) the camera may stand, looking that way.
The best-voted positions, refined on a small grid around each, are scored with the
landmark likelihood (:meth:`BearingSensor.pose_log_likelihood`).
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.compass.bearings import FrameBearings
from vc_gym.localization.bearing_sensor import BearingSensor
from vc_gym.validation import int_at_least, positive_float

__all__ = ["search_poses"]

#: Landmarks nearer the camera position than this (m) do not vote: their direction
#: changes too fast with the position for a grid cell to hold one.
MIN_VOTE_RANGE_M = 0.3


def search_poses(
    sensor: BearingSensor,
    changes: FrameBearings,
    head_pan_deg: float,
    bounds: tuple[float, float, float, float],
    spacing_m: float = 0.3,
    bin_deg: float = 3.0,
    top: int = 8,
    noise_deg: float = 2.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The body poses where ``changes`` fit the landmarks best, anywhere in ``bounds``.

    Parameters
    ----------
    sensor : BearingSensor
        The landmarks (and where the camera sits ahead of the body).
    changes : FrameBearings
        The frame's changes (:meth:`BearingSensor.bearings`).
    head_pan_deg : float
        Head pan of the frame.
    bounds : tuple of float
        ``(x0, x1, y0, y1)``: where the camera may stand (m).
    spacing_m, bin_deg : float
        Grid of camera positions and bins of the voted directions.
    top : int
        How many poses to return.
    noise_deg : float
        Bearing noise of the final scoring (a grid's poses are a few cm and degrees off).

    Returns
    -------
    poses : numpy.ndarray
        ``(K, 3)`` body poses ``x, y`` (m), ``θ`` (deg), ``K ≤ top``, best first; empty
        when no change has a landmark of its pair.
    log_likelihoods : numpy.ndarray
        ``(K,)`` their :meth:`BearingSensor.pose_log_likelihood` at ``noise_deg``.
    """
    x0, x1, y0, y1 = (float(v) for v in bounds)
    if not (math.isfinite(x0 + x1 + y0 + y1) and x0 < x1 and y0 < y1):
        raise ValueError(f"bounds must be finite (x0, x1, y0, y1), x0 < x1, y0 < y1: {bounds}")
    spacing = positive_float("spacing_m", spacing_m)
    bin_rad = math.radians(positive_float("bin_deg", bin_deg))
    int_at_least("top", top, 1)
    pan = math.radians(float(head_pan_deg))
    empty = np.zeros((0, 3)), np.zeros(0)
    lm = sensor.landmarks
    landmark, change = lm.candidates(changes.pairs)
    if landmark.size == 0:
        return empty
    xs = np.arange(x0, x1 + 1e-9, spacing)
    ys = np.arange(y0, y1 + 1e-9, spacing)
    eye = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)  # (G, 2)
    d = lm.positions[landmark][None, :, :] - eye[:, None, :]  # (G, C, 2)
    near = np.hypot(d[..., 0], d[..., 1]) < MIN_VOTE_RANGE_M
    axis = np.arctan2(d[..., 1], d[..., 0]) - np.radians(changes.offsets_deg[change])[None, :]
    n_bins = int(math.ceil(2 * math.pi / bin_rad))
    b = np.floor(np.mod(axis, 2 * math.pi) / bin_rad).astype(np.int64) % n_bins
    cell = np.broadcast_to(np.arange(len(eye))[:, None], b.shape)
    # one vote per (cell, change, bin): a change with two landmarks in one bin counts once
    key = (cell * len(changes) + change[None, :]) * n_bins + b
    key = np.unique(key[~near])
    votes = np.bincount(
        (key // (len(changes) * n_bins)) * n_bins + key % n_bins, minlength=len(eye) * n_bins
    ).reshape(len(eye), n_bins)
    votes = votes + np.roll(votes, -1, axis=1)  # two bins: an axis on a bin's edge
    best_bin = np.argmax(votes, axis=1)
    best = votes[np.arange(len(eye)), best_bin]
    cells = np.argsort(-best, kind="stable")[: 4 * top]
    psi = (best_bin[cells] + 1) * bin_rad  # the two bins' common edge
    theta = psi - pan
    body = eye[cells] - sensor.eye_forward_m * np.stack([np.cos(theta), np.sin(theta)], 1)
    # refine: half a cell and a bin around each
    steps = np.array(
        [(dx, dy, dt) for dx in (-0.5, 0.0, 0.5) for dy in (-0.5, 0.0, 0.5) for dt in (-1, 0, 1)]
    )
    poses = np.repeat(np.column_stack([body, np.degrees(theta)]), len(steps), axis=0)
    poses += np.tile(steps * [spacing, spacing, math.degrees(bin_rad)], (len(cells), 1))
    poses[:, 2] %= 360.0
    ll = sensor.pose_log_likelihood(changes, poses, float(head_pan_deg), noise_deg=noise_deg)
    keep = np.argsort(-ll, kind="stable")[:top]
    return poses[keep], ll[keep]
