"""A pose belief over the whole field: Monte Carlo localisation on re-drawn maps."""

from __future__ import annotations

import math
import warnings
import weakref

import numpy as np

from vc_gym.angles import wrap360
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.compass.pose_maps import MAX_LATTICE_STEPS, FrameTerms, PoseMaps, around_groups
from vc_gym.exposure import SessionLight
from vc_gym.filters import ParticleFilter
from vc_gym.filters.particle_filter import check_particle_count
from vc_gym.localization.tracker_protocol import (
    TrackerState,
    check_frame_inputs,
    check_reset_inputs,
)
from vc_gym.validation import (
    MAX_ABS_DEG,
    MAX_ABS_METRES,
    int_at_least,
    nonnegative_float,
    positive_float,
)

__all__ = ["SPOT_RULES", "PoseTracker"]

#: Which spot's map scores a particle (:class:`PoseTracker` ``spot_rule``).
SPOT_RULES = ("nearest", "best2")

#: Pose maps built per atlas (learning the wall distances of every spot takes a while):
#: an env resets its tracker every episode with the same atlas.
_POSE_MAPS: weakref.WeakKeyDictionary[CompassAtlas, dict[tuple, PoseMaps]] = (
    weakref.WeakKeyDictionary()
)


def pose_maps_of(atlas: CompassAtlas, lattice_m: float, reach_m: float) -> PoseMaps:
    """:meth:`PoseMaps.from_atlas`, built once per atlas object and settings."""
    built = _POSE_MAPS.setdefault(atlas, {})
    key = (lattice_m, reach_m)
    if key not in built:
        if all(len(group) == 1 for group in around_groups(atlas.names).values()):
            warnings.warn(
                "the atlas has no turns learned around its spots (GridLearning(keep_around="
                "True), or the task's around_m > 0): the pose tracker then knows a position "
                "only to the nearest spot's area",
                UserWarning,
                stacklevel=3,
            )
        built[key] = PoseMaps.from_atlas(atlas, lattice_m, reach_m)
    return built[key]


def _softmax(log_p: np.ndarray) -> np.ndarray:
    p = np.exp(log_p - np.max(log_p))
    return p / p.sum()


class PoseTracker:
    """Particles over ``(x, y, θ)`` weighed by every spot's map re-drawn for their
    position (beyond the paper; Monte Carlo localisation, eq. 17-22).

    Motion update: every particle moves by its own noisy copy of the odometry (eq.
    18-21), with ``motion_noise`` plus ``odometry_noise`` of the odometry itself (the
    robot's odometry has per-run scale errors of a few per cent).

    Sensor update: the frame's log-likelihood at each particle's pose under the map of
    the spot nearest it, re-drawn for the particle's position
    (:class:`~vc_gym.compass.pose_maps.PoseMaps`: each spot's map with the turns learned
    around it, :class:`~vc_gym.compass.ParallaxMap`), divided by ``temperature`` (the
    terms of eq. 16 are far from independent), with an outlier floor so that one
    misleading frame cannot wipe out the right hypothesis. Systematic resampling when
    the effective sample size drops below half.

    Sensor resetting: every ``rescore_every`` frames the frame is scored against every
    spot. Poses drawn from that answer (a spot by how well the frame fits at it, a
    position around it, a heading by the spot's heading likelihood) start the belief at
    the first frame and replace ``inject_fraction`` of the particles at every such
    frame. When the best spot explains the frames much better than the belief does,
    for several checks running (a kidnapping, or a belief that lost the robot),
    ``reset_fraction`` of the particles are replaced instead.

    Stated uncertainty: the particles' spread plus, in quadrature, the resolution of
    the maps themselves (``resolution_m``, ``resolution_deg``): the cloud shrinks to
    what the likelihood can tell apart, but the likelihood of a 4.5° sector histogram
    does not pin a walking robot's position closer than ~0.2 m nor its heading closer
    than a few degrees (``scripts/pose_likelihood_diagnostic.py``), and a spread that
    leaves that out is overconfident.

    Without turns learned around a spot (an atlas learned without ``keep_around``) the
    spot's map cannot be re-drawn: it scores every position near the spot alike, and
    the position is known only to the nearest spot's area (about 1 m in ``vc-gym bench
    trackers``).

    Which map scores a particle: ``spot_rule="nearest"`` the map of the spot nearest
    it; ``"best2"`` the better of its two nearest spots' maps, which smooths the step
    in the likelihood where the nearest spot changes (each map fits best near its own
    spot).

    Light: with maps learned with ``exposure="session"`` the frames are brought to
    one gain for the run's light (:class:`~vc_gym.exposure.SessionLight`), read from
    the frames so far, instead of one gain per frame.

    Parameters
    ----------
    n_particles : int
        Number of particles, in ``[1, MAX_PARTICLES]``.
    temperature : float
        Divides the frame's log-likelihood.
    outlier : float
        Smallest weight factor one frame can give a particle, relative to the best, in
        ``[0, 1)``.
    motion_noise : tuple of float
        Per-frame noise ``(σ forward m, σ left m, σ turn deg)``.
    odometry_noise : float
        Further σ per unit of odometry (a fraction of each component).
    rescore_every : int
        Frames between scorings of every spot (sensor resetting, kidnapping check).
    inject_fraction, reset_fraction : float
        Fractions of the particles redrawn from the spots at a check, and when the
        belief lost the robot; in ``[0, 1]``.
    lost_nats, lost_checks : float, int
        The belief counts as lost when the best spot's tempered log-likelihood exceeds
        the belief's by more than ``lost_nats`` at ``lost_checks`` checks running.
    reset_spread_m : float
        σ of the positions drawn around a spot.
    margin_m : float
        Particles stay within the spots' bounding box grown by this much.
    resolution_m, resolution_deg : float
        Added in quadrature to the particles' position std and heading spread in the
        stated uncertainty.
    spot_rule : str
        ``"nearest"`` or ``"best2"``: which spot's map scores a particle.
    lattice_m, reach_m : float
        :class:`~vc_gym.compass.pose_maps.PoseMaps` settings.
    light_window : int
        Frames the session's light is read from (``exposure="session"`` maps).
    seed : int
        Every :meth:`reset` draws from ``numpy.random.default_rng(seed)``.
    """

    def __init__(
        self,
        n_particles: int = 500,
        temperature: float = 40.0,
        outlier: float = 0.02,
        motion_noise: tuple[float, float, float] = (0.01, 0.01, 1.0),
        odometry_noise: float = 0.1,
        rescore_every: int = 5,
        inject_fraction: float = 0.02,
        reset_fraction: float = 0.5,
        lost_nats: float = 3.0,
        lost_checks: int = 2,
        reset_spread_m: float = 0.35,
        margin_m: float = 1.0,
        resolution_m: float = 0.25,
        resolution_deg: float = 4.0,
        spot_rule: str = "best2",
        lattice_m: float = 0.1,
        reach_m: float = 1.5,
        light_window: int = 100,
        seed: int = 0,
    ):
        self.n_particles = check_particle_count(n_particles)
        self.temperature = positive_float("temperature", temperature)
        self.outlier = self._fraction("outlier", outlier, below_one=True)
        noise = tuple(nonnegative_float("motion_noise", v) for v in motion_noise)
        if len(noise) != 3 or max(noise[:2]) > MAX_ABS_METRES or noise[2] > MAX_ABS_DEG:
            raise ValueError(
                f"motion_noise must be 3 numbers >= 0 (m, m, deg) within {MAX_ABS_METRES:g} m "
                f"and {MAX_ABS_DEG:g}°, got {motion_noise!r}"
            )
        self.motion_noise = noise
        self.odometry_noise = self._fraction("odometry_noise", odometry_noise)
        self.rescore_every = int_at_least("rescore_every", rescore_every, 1)
        self.inject_fraction = self._fraction("inject_fraction", inject_fraction)
        self.reset_fraction = self._fraction("reset_fraction", reset_fraction)
        self.lost_nats = nonnegative_float("lost_nats", lost_nats)
        self.lost_checks = int_at_least("lost_checks", lost_checks, 1)
        self.reset_spread_m = positive_float("reset_spread_m", reset_spread_m)
        self.margin_m = nonnegative_float("margin_m", margin_m)
        if self.margin_m > MAX_ABS_METRES or self.reset_spread_m > MAX_ABS_METRES:
            raise ValueError(f"margin_m and reset_spread_m must be at most {MAX_ABS_METRES:g} m")
        self.resolution_m = nonnegative_float("resolution_m", resolution_m)
        self.resolution_deg = nonnegative_float("resolution_deg", resolution_deg)
        if self.resolution_m > MAX_ABS_METRES or self.resolution_deg > 180:
            raise ValueError(
                f"resolution_m must be at most {MAX_ABS_METRES:g} m and resolution_deg at "
                f"most 180°, got {resolution_m!r}, {resolution_deg!r}"
            )
        if spot_rule not in SPOT_RULES:
            raise ValueError(f"spot_rule must be one of {list(SPOT_RULES)}, got {spot_rule!r}")
        self.spot_rule = spot_rule
        self.lattice_m = positive_float("lattice_m", lattice_m)
        self.reach_m = positive_float("reach_m", reach_m)
        if self.reach_m / self.lattice_m > MAX_LATTICE_STEPS:  # refused now, not at reset
            raise ValueError(
                f"reach_m / lattice_m must be at most {MAX_LATTICE_STEPS} (the pose maps' "
                f"lattice is precomputed), got {reach_m!r} / {lattice_m!r}"
            )
        self.light = SessionLight(int_at_least("light_window", light_window, 1))
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
            raise ValueError(f"seed must be an int, got {seed!r}")
        self.seed = int(seed)
        self.atlas: CompassAtlas | None = None

    @staticmethod
    def _fraction(name: str, value: object, below_one: bool = False) -> float:
        v = nonnegative_float(name, value)
        if v > 1 or (below_one and v == 1):
            raise ValueError(f"{name} must be in [0, {'1)' if below_one else '1]'}, got {value!r}")
        return v

    # ------------------------------------------------------------------ protocol
    def reset(self, atlas: CompassAtlas, camera: Camera, dt_s: float) -> None:
        """Forget the pose; (re)build the pose maps for ``atlas`` (once per atlas)."""
        check_reset_inputs(atlas, camera, dt_s)
        self.maps = pose_maps_of(atlas, self.lattice_m, self.reach_m)
        self.atlas, self.camera = atlas, camera
        lo, hi = self._bounds()
        self._lo, self._hi = lo, hi
        self.rng = np.random.default_rng(self.seed)
        self.filter = ParticleFilter(
            self.n_particles,
            bounds=(float(lo[0]), float(hi[0]) + 1e-3, float(lo[1]), float(hi[1]) + 1e-3),
            rng=self.rng,
            inject_fraction=0.0,
        )
        self.light.reset()
        self._frame = 0
        self._fresh = True
        self._lost_run = 0
        #: The last check's gap: best spot's log-likelihood minus the belief's (nats).
        self.last_gap = 0.0

    @property
    def particles(self) -> np.ndarray:
        """``(N, 3)`` the particles ``(x m, y m, θ deg)``, world frame (a copy)."""
        return self.filter.particles

    @property
    def weights(self) -> np.ndarray:
        """``(N,)`` the particles' weights (sum 1)."""
        return self.filter.weights

    def update(
        self, image: np.ndarray, head_pan_deg: float, odometry: np.ndarray | tuple
    ) -> TrackerState:
        """Motion update by ``odometry``, then sensor update by ``image``."""
        pan, fwd, left, turn = check_frame_inputs(
            head_pan_deg, odometry, ready=self.atlas is not None
        )
        pf, k = self.filter, self.odometry_noise
        sf, sl, st = self.motion_noise
        pf.predict((fwd, left, turn), (sf + k * abs(fwd), sl + k * abs(left), st + k * abs(turn)))
        p = pf.particles
        outside = np.flatnonzero(np.any((p[:, :2] < self._lo) | (p[:, :2] > self._hi), axis=1))
        if outside.size:  # the robot stays in the room: particles stay near the spots
            p[outside, :2] = np.clip(p[outside, :2], self._lo, self._hi)
            pf.replace(outside, p[outside])
        check = self._check_due()
        self._frame += 1
        if not check and self._fine_alone():
            # between the checks a finer measurement alone weighs the particles
            self._weigh_by(self._fine_log_likelihood(pan, p))
            return self._state()
        near = self._scoring_spots(p[:, :2])
        spots = None if check else np.unique(near)
        terms = self.maps.frame(image, self.camera, spots, self._gain(image))
        if terms.has_evidence:
            if self._fresh:
                drawn = self._drawn(self._spot_scores(terms), pan, self.n_particles)
                pf.replace(np.arange(self.n_particles), drawn)
                self._fresh = False
            else:
                self._weigh(terms, pan, near, check)
        return self._state()

    # ------------------------------------------------------------------ parts
    def _check_due(self) -> bool:
        """Whether the next frame is a check: the maps score every spot (the first
        frame, then every ``rescore_every``-th)."""
        return self._fresh or self._frame % self.rescore_every == 0

    def _bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Where the robot may be: ``margin_m`` around the spots (their turns too)."""
        return (
            self.maps.positions.min(axis=0) - self.margin_m,
            self.maps.positions.max(axis=0) + self.margin_m,
        )

    def _gain(self, image: np.ndarray) -> float | None:
        """The session's gain for ``exposure="session"`` maps, else ``None`` (the maps'
        own rule)."""
        if self.maps.config.exposure != "session":
            return None
        return self.light.update(self.maps.maps[0].frame_gain(image, self.camera))

    def _scoring_spots(self, xy: np.ndarray) -> np.ndarray:
        """``(N, k)`` the spots whose maps may score each position (``spot_rule``)."""
        if self.spot_rule == "nearest":
            return self.maps.nearest(xy)[:, None]
        return self.maps.nearest_two(xy)

    def _log_likelihood(
        self, terms: FrameTerms, pan: float, near: np.ndarray, poses: np.ndarray
    ) -> np.ndarray:
        """Tempered log-likelihood of the frame at ``poses`` (body headings): the best
        of the maps of ``near`` (``(N, k)`` spots)."""
        heading = wrap360(poses[:, 2] + pan)
        ll = np.max(
            [
                self.maps.log_likelihood(terms, poses[:, :2], heading, near[:, j])
                for j in range(near.shape[1])
            ],
            axis=0,
        )
        return ll / self.temperature

    def _weigh(self, terms: FrameTerms, pan: float, near: np.ndarray, check: bool) -> None:
        pf = self.filter
        ll = self._log_likelihood(terms, pan, near, pf.particles)
        scores = self._spot_scores(terms) if check else None
        if scores is not None:
            self._check_lost(scores, ll)
        self._weigh_by(ll + self._fine_log_likelihood(pan, pf.particles))
        if scores is not None:
            lost = self._lost_run >= self.lost_checks
            fraction = self.reset_fraction if lost else self.inject_fraction
            if lost:
                self._lost_run = 0
            n = int(round(fraction * self.n_particles))
            if n:
                if pf.ess < self.n_particles:  # weights not uniform: resample first
                    pf.resample()
                idx = self.rng.choice(self.n_particles, size=n, replace=False)
                pf.replace(idx, self._drawn(scores, pan, n))

    def _weigh_by(self, ll: np.ndarray) -> None:
        """Weigh the particles by the log-likelihood ``ll`` above the outlier floor."""
        top = float(ll.max())
        robust = np.log(self.outlier + (1.0 - self.outlier) * np.exp(ll - top))
        self.filter.update(_Given(robust), None)

    def _fine_alone(self) -> bool:
        """Whether, between the checks, the further measurement
        (:meth:`_fine_log_likelihood`) alone weighs this frame's particles, the maps
        left unscored; never here."""
        return False

    def _fine_log_likelihood(self, pan: float, poses: np.ndarray) -> np.ndarray | float:
        """A further measurement's log-likelihood at the particles, added to the maps'
        after the kidnapping check (which compares the maps' alone); none here."""
        del pan, poses
        return 0.0

    def _spot_scores(self, terms: FrameTerms) -> np.ndarray:
        """``(n_spots, n_headings)`` tempered log-likelihood at every spot's position."""
        return (
            np.stack([self.maps.heading_log_likelihood(terms, s) for s in range(len(self.maps))])
            / self.temperature
        )

    def _check_lost(self, scores: np.ndarray, ll: np.ndarray) -> None:
        """Compare the belief with the best spot (``scores``: :meth:`_spot_scores`):
        the log of the frame's expected likelihood under the belief against the best
        spot's."""
        best = float(scores.max())
        logw = self.filter.log_weights
        top = float(np.max(logw + ll))
        belief = top + math.log(float(np.sum(np.exp(logw + ll - top))))
        self.last_gap = best - belief
        self._lost_run = self._lost_run + 1 if self.last_gap > self.lost_nats else 0

    def _drawn(self, scores: np.ndarray, pan: float, k: int) -> np.ndarray:
        """``k`` body poses drawn from the frame's fit at every spot (``scores``:
        :meth:`_spot_scores`)."""
        top = scores.max(axis=1)
        spot = self.rng.choice(len(top), size=k, p=_softmax(top))
        out = np.empty((k, 3))
        out[:, :2] = self.maps.positions[spot] + self.rng.normal(0.0, self.reset_spread_m, (k, 2))
        np.clip(out[:, :2], self._lo, self._hi, out=out[:, :2])
        step = self.maps.config.heading_step_deg
        for s in np.unique(spot):
            rows = np.flatnonzero(spot == s)
            h = self.rng.choice(scores.shape[1], size=rows.size, p=_softmax(scores[s]))
            out[rows, 2] = h * step + self.rng.uniform(-0.5, 0.5, rows.size) * step - pan
        out[:, 2] = wrap360(out[:, 2])
        return out

    def _state(self) -> TrackerState:
        pf = self.filter
        e = pf.estimate()
        th = pf.particles[:, 2]
        belief = np.bincount(np.floor(th).astype(np.int64) % 360, weights=pf.weights, minlength=360)
        r = self.resolution_m
        return TrackerState(
            heading_deg=float(e.heading_deg) % 360.0,
            heading_spread_deg=float(min(math.hypot(e.spread_deg, self.resolution_deg), 180.0)),
            position=(e.x, e.y),
            position_std_m=(math.hypot(e.std_xy[0], r), math.hypot(e.std_xy[1], r)),
            goodness=np.zeros(len(self.atlas.names)),
            belief=belief / belief.sum(),
            atlas_position=(e.x, e.y),
        )


class _Given:
    """A pose sensor that returns log-likelihoods computed beforehand."""

    def __init__(self, ll: np.ndarray):
        self.ll = ll

    def pose_log_likelihood(self, observation: object, poses: np.ndarray) -> np.ndarray:
        del observation, poses
        return self.ll
