"""A pose belief that sees finer than a sector: the pose tracker's particles weighed
also by the bearings of the learned landmarks."""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from vc_gym.angles import circular_mean, wrap180
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.compass.bearings import FrameBearings
from vc_gym.compass.light_gain import REFERENCE_EXPOSURES
from vc_gym.exposure import SessionLight
from vc_gym.localization.bearing_search import search_poses
from vc_gym.localization.bearing_sensor import BearingSensor
from vc_gym.localization.pose_tracker import PoseTracker
from vc_gym.localization.tracker_protocol import TrackerState, check_frame_inputs
from vc_gym.validation import int_at_least, open_fraction, positive_float

__all__ = [
    "LANDMARK_EXTENT_PCT",
    "LIGHT_PARTICLES",
    "LIGHT_SCORE_DECAY",
    "MIN_SEARCH_CHANGES",
    "SEARCH_NOISE_DEG",
    "SEARCH_SPREAD",
    "SPREAD_RANGE_M",
    "BearingTracker",
]

#: Percentile of the landmarks' positions taken as the walls (each side) when a search
#: widens the tracker's bounds.
LANDMARK_EXTENT_PCT = 5.0
#: Fewest changes of a frame for the field search (fewer fit many poses).
MIN_SEARCH_CHANGES = 6
#: Bearing noise (deg) at which the search's poses and the belief are compared.
SEARCH_NOISE_DEG = 2.0
#: Spread (x m, y m, θ deg) of the particles drawn around the search's poses.
SEARCH_SPREAD = (0.08, 0.08, 2.0)
#: How many of the belief's heaviest particles score a reading of the light.
LIGHT_PARTICLES = 32
#: Factor by which the light's evidence decays at each check of the light.
LIGHT_SCORE_DECAY = 0.95
#: Distance at which a particle cloud's position spread is turned into the bearing
#: spread it causes (a typical wall distance).
SPREAD_RANGE_M = 3.0


class BearingTracker(PoseTracker):
    """Particles over ``(x, y, θ)`` weighed by the spots' re-drawn maps and by the
    bearings of the atlas' landmarks (beyond the paper).

    The sector histograms of :class:`PoseTracker` (the paper's sensor model, eq. 16, on
    maps re-drawn for each particle's position) place the robot on the field: the first
    frame's particles are drawn from them, a kidnapping is noticed by them and the
    particles they re-draw bring a lost belief back. The colour changes' bearings
    (:class:`~vc_gym.localization.bearing_sensor.BearingSensor` on the atlas'
    :attr:`~vc_gym.compass.CompassAtlas.landmarks`) weigh the same particles to a
    fraction of a degree per change: the fine pose. Between the checks (every
    ``rescore_every``-th frame, when the maps score every spot) the bearings alone weigh
    a frame that shows at least ``min_changes_alone`` changes: the maps, re-drawn for a
    position from a few turns, are off by decimetres and would pull the fine pose towards
    their error. At a check, and on a frame with fewer changes (which pin the pose only
    loosely), both weigh. The bearings' log-likelihood is divided by
    ``bearing_temperature`` (the changes of one frame are not independent either) and
    added to the maps' before the outlier floor. Their noise is ``bearing_noise_deg``
    widened, in quadrature, by the spread of the cloud's core (its heading, and its
    position seen from :data:`SPREAD_RANGE_M`): a broad cloud is sharpened step by step
    instead of being taken over by the particle that happens to line up a few changes.

    The frames' changes are read at the session's light relative to the landmarks'
    learning light, in whole stops, so that a room at half the light shows the changes
    it was learned with. The median gain of the recent frames
    (:class:`~vc_gym.exposure.SessionLight` over the maps' per-frame gains) divided by
    :attr:`~vc_gym.compass.landmarks.LandmarkMap.light_gain` brackets it between two
    whole stops; it cannot choose between them, since what a route's frames show moves
    their level by up to two thirds of a stop at the same light. The landmarks choose:
    every ``light_every``-th frame is read at both, and each reading is scored by how
    far the changes fit the belief's best particles above the outlier floor (every
    frame at first); the stop whose decayed score is higher reads the frames.

    An atlas without landmarks (learned without ``landmarks=True``) leaves the maps
    alone, with a warning: the tracker is then the pose tracker with its stated spread.

    Parameters
    ----------
    bearing_noise_deg : float
        σ of an observed change's bearing, degrees.
    bearing_outlier : float
        Density floor of a change no landmark explains, in ``(0, 1)``.
    bearing_temperature : float
        Divides the bearings' log-likelihood.
    min_changes_alone : int
        Fewest changes of a frame between the checks for the bearings to weigh it alone
        (a large number: the maps weigh every frame as well).
    light_every : int
        Frames between the checks of the light by the landmarks (each reads the frame's
        changes twice).
    search_every : int
        Every how many of the maps' checks the frame's changes are also searched for over
        the whole field (:func:`~vc_gym.localization.bearing_search.search_poses`); 0:
        never. When the search's best pose fits the changes better than the belief by
        ``search_nats`` at two such checks running, the belief is taken as lost (as the
        maps' check does), and half of the particles drawn anew come from the search:
        the maps, learned at the spots, place a robot far from them poorly, while the
        landmarks are seen from anywhere.
    search_nats : float
        How much better the search's best pose must fit (log-likelihood, nats).
    resolution_m, resolution_deg : float
        Added in quadrature to the particles' spread in the stated uncertainty (see
        :class:`PoseTracker`); smaller than the pose tracker's, because the bearings
        tell positions apart to centimetres.
    outlier, motion_noise, n_particles
        As :class:`PoseTracker`'s; a lower weight floor and a tighter motion noise than
        its defaults: the bearings, not the motion noise, keep the cloud on the robot.
    **pose_options
        Any other :class:`PoseTracker` argument.
    """

    def __init__(
        self,
        bearing_noise_deg: float = 0.5,
        bearing_outlier: float = 0.05,
        bearing_temperature: float = 1.0,
        min_changes_alone: int = 12,
        light_every: int = 8,
        search_every: int = 0,
        search_nats: float = 5.0,
        resolution_m: float = 0.015,
        resolution_deg: float = 0.25,
        outlier: float = 0.001,
        motion_noise: tuple[float, float, float] = (0.005, 0.005, 0.5),
        n_particles: int = 500,
        **pose_options: Any,
    ):
        super().__init__(
            n_particles=n_particles,
            resolution_m=resolution_m,
            resolution_deg=resolution_deg,
            outlier=outlier,
            motion_noise=motion_noise,
            **pose_options,
        )
        self.bearing_noise_deg = positive_float("bearing_noise_deg", bearing_noise_deg)
        self.bearing_outlier = open_fraction("bearing_outlier", bearing_outlier)
        self.bearing_temperature = positive_float("bearing_temperature", bearing_temperature)
        self.min_changes_alone = int_at_least("min_changes_alone", min_changes_alone, 1)
        self.light_every = int_at_least("light_every", light_every, 1)
        self.search_every = int_at_least("search_every", search_every, 0)
        self.search_nats = positive_float("search_nats", search_nats)
        self.sensor: BearingSensor | None = None
        self.bearing_light = SessionLight(self.light.window)  # the maps' light window
        self._changes: FrameBearings | None = None
        self._light_scores: dict[int, float] = {}  # whole stops: decayed evidence
        self._light_frame = 0
        self._found: tuple[np.ndarray, np.ndarray] | None = None  # this check's search
        self._checks = self._search_run = 0
        self._pan = 0.0

    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Forget the pose; (re)build the pose maps and the bearing sensor for ``atlas``."""
        super().reset(atlas, camera, dt_s)
        self.sensor = None
        self.bearing_light.reset()
        self._light_scores, self._light_frame = {}, 0
        self._found, self._checks, self._search_run = None, 0, 0
        if atlas.landmarks is None or len(atlas.landmarks) == 0:
            warnings.warn(
                "the atlas has no landmarks (learn it with landmarks=True): the bearings "
                "tracker then weighs its particles by the sector maps alone",
                UserWarning,
                stacklevel=2,
            )
            return
        self.sensor = BearingSensor(
            atlas.landmarks,
            atlas.compasses[0].colors,
            camera,
            noise_deg=self.bearing_noise_deg,
            outlier=self.bearing_outlier,
        )

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Motion update by ``odometry``, then sensor update by ``image``: the maps and
        the bearings of its colour changes."""
        pan, *_ = check_frame_inputs(head_pan_deg, odometry, ready=self.atlas is not None)
        self._changes = None if self.sensor is None else self._read_changes(image, pan)
        self._pan, self._found = pan, None
        if self.search_every and self._changes is not None:
            if self._check_due():
                self._checks += 1
                if (self._checks - 1) % self.search_every == 0:
                    self._found = self._search()
        return super().update(image, head_pan_deg, odometry)

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The pose tracker's bounds, with a search widened to the landmarks' extent
        (the walls they stand on hold the field: a kidnapping may leave the robot
        farther from the spots than their margin)."""
        lo, hi = super()._bounds()
        landmarks = self.atlas.landmarks
        if not self.search_every or landmarks is None or len(landmarks) < 2:
            return lo, hi
        # the outermost few per cent may be triangulated far beyond the walls
        walls = np.percentile(
            landmarks.positions, [LANDMARK_EXTENT_PCT, 100 - LANDMARK_EXTENT_PCT], axis=0
        )
        return np.minimum(lo, walls[0]), np.maximum(hi, walls[1])

    def _search(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The poses anywhere on the field that the frame's changes fit best
        (``None`` for a frame with too few changes to place it)."""
        if len(self._changes) < MIN_SEARCH_CHANGES:
            return None
        bounds = (self._lo[0], self._hi[0], self._lo[1], self._hi[1])
        poses, ll = search_poses(self.sensor, self._changes, self._pan, bounds)
        return (poses, ll) if len(poses) else None

    def _check_lost(self, scores: np.ndarray, ll: np.ndarray) -> None:
        """The maps' check, and with a search the bearings' own: the search's best pose
        against the belief's expected fit at the same noise."""
        super()._check_lost(scores, ll)
        if self._found is None:
            return
        poses, found_ll = self._found
        fit = self.sensor.pose_log_likelihood(
            self._changes, self.filter.particles, self._pan, noise_deg=SEARCH_NOISE_DEG
        )
        logw = self.filter.log_weights
        gap = float(found_ll[0]) - _log_mean_exp(fit, logw)
        self._search_run = self._search_run + 1 if gap > self.search_nats else 0
        if self._search_run >= 2:
            self._lost_run, self._search_run = max(self._lost_run, self.lost_checks), 0

    def _drawn(self, scores: np.ndarray, pan: float, k: int) -> np.ndarray:
        """``k`` body poses drawn anew: with this check's search, half of them around its
        poses (weighted by their fit), the rest from the maps as :class:`PoseTracker`
        draws them."""
        if self._found is None:
            return super()._drawn(scores, pan, k)
        poses, found_ll = self._found
        n = k // 2
        out = np.empty((k, 3))
        out[: k - n] = super()._drawn(scores, pan, k - n)
        p = np.exp(found_ll - found_ll.max())
        picked = self.rng.choice(len(poses), size=n, p=p / p.sum())
        out[k - n :] = poses[picked] + self.rng.normal(0.0, SEARCH_SPREAD, (n, 3))
        np.clip(out[k - n :, :2], self._lo, self._hi, out=out[k - n :, :2])
        out[k - n :, 2] %= 360.0
        return out

    def _read_changes(self, image: np.ndarray, pan: float) -> FrameBearings:
        """The frame's changes at the session's light (see the class docstring)."""
        compass = self.maps.maps[0]
        if compass.config.exposure not in REFERENCE_EXPOSURES:
            return self.sensor.bearings(image)
        light = self.bearing_light.update(compass.frame_gain(image, self.camera))
        stops = math.log2(light / self.sensor.landmarks.light_gain)
        low = math.floor(stops)
        self._light_frame += 1
        # every frame of the first 2 x light_every (the light is not known yet), then
        # every light_every-th
        settled = self._light_frame > 2 * self.light_every
        if self._fresh or (settled and (self._light_frame - 1) % self.light_every):
            return self.sensor.bearings(image, 2.0 ** self._light_stop(low, round(stops)))
        read = {k: self.sensor.bearings(image, 2.0**k) for k in (low, low + 1)}
        for k in self._light_scores:
            self._light_scores[k] *= LIGHT_SCORE_DECAY
        for k, changes in read.items():
            self._light_scores[k] = self._light_scores.get(k, 0.0) + self._evidence(changes, pan)
        return read[self._light_stop(low, round(stops))]

    def _light_stop(self, low: int, nearest: int) -> int:
        """Of the whole stops ``low`` and ``low + 1``, the one the landmarks' decayed
        evidence favours; ``nearest`` while neither has any."""
        a, b = self._light_scores.get(low, 0.0), self._light_scores.get(low + 1, 0.0)
        if a == b:
            return nearest
        return low if a > b else low + 1

    def _evidence(self, changes: FrameBearings, pan: float) -> float:
        """How far the belief's best particles explain ``changes`` above the outlier
        floor: the log of their weighted mean likelihood ratio against every change
        being an outlier (0 for a frame without changes; never below 0)."""
        if len(changes) == 0:
            return 0.0
        logw = self.filter.log_weights
        best = np.argsort(logw)[-LIGHT_PARTICLES:]
        ll = self.sensor.pose_log_likelihood(
            changes, self.filter.particles[best], pan, noise_deg=self._bearing_noise_deg()
        )
        ratio = ll - len(changes) * math.log(self.bearing_outlier)
        return _log_mean_exp(ratio, logw[best])

    def _fine_alone(self) -> bool:
        changes = self._changes
        return changes is not None and len(changes) >= self.min_changes_alone

    def _fine_log_likelihood(self, pan: float, poses: np.ndarray) -> np.ndarray | float:
        if self.sensor is None or self._changes is None:
            return 0.0
        # a broad cloud has few particles within a bearing's σ of the truth: the bearing
        # noise is widened by the cloud's own spread (its heading, and its position seen
        # from SPREAD_RANGE_M away), so that the bearings sharpen it step by step instead
        # of seizing the particle that happens to line up a few changes. The spread of
        # the cloud's core: the few particles drawn afresh at a check must not blunt it.
        spread = self._bearing_noise_deg()
        ll = self.sensor.pose_log_likelihood(self._changes, poses, pan, noise_deg=spread)
        return ll / self.bearing_temperature

    def _bearing_noise_deg(self) -> float:
        """The bearing noise widened by the spread of the cloud's core."""
        heading_deg, position_m = _core_spread(self.filter.particles, self.filter.weights)
        return math.hypot(
            self.bearing_noise_deg,
            heading_deg,
            math.degrees(math.atan2(position_m, SPREAD_RANGE_M)),
        )


def _log_mean_exp(values: np.ndarray, log_weights: np.ndarray) -> float:
    """``log(Σ w·exp(values) / Σ w)`` for weights given as logs, without overflow."""
    return float(np.logaddexp.reduce(values + log_weights) - np.logaddexp.reduce(log_weights))


def _weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    order = np.argsort(values)
    cumulative = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])])


def _core_spread(particles: np.ndarray, weights: np.ndarray) -> tuple[float, float]:
    """Robust σ (1.4826 × the weighted median absolute deviation) of the particles'
    heading (deg) and of their distance from the weighted mean position (m)."""
    off = np.abs(wrap180(particles[:, 2] - circular_mean(particles[:, 2], weights)))
    centre = weights @ particles[:, :2]
    dist = np.hypot(*(particles[:, :2] - centre).T)
    return 1.4826 * _weighted_median(off, weights), 1.4826 * _weighted_median(dist, weights)
