"""Scripted learn-then-home behaviour of the paper (sections 4.3 and 5.2).

The robot stands at home (the field's kickoff circle), learns the panorama at four spots
1 m around it (a full turn in 8 steps of 45°, each direction for ``learn_time_s`` with
head scanning), walks back home and normalises the spots' goodness there. Then it is
kidnapped to a random pose on the field with a random heading and walks home using an
orientational grid filter (eq. 23-27) and a translational filter (eq. 30-32) fed by the
compass atlas, until it has stood still for ``stop_time_s``.

The robot only uses what it could know: camera frames, head angles and odometry. The
true pose is read from ``info`` for the record (trajectories, errors), never for control.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.compass.sensors import interp_circular
from vc_gym.filters import HeadingGridFilter, TranslationalFilter

__all__ = ["LearnThenHomeConfig", "ScriptedLearnThenHome", "EpisodeRecord"]

SPOT_NAMES = ("east", "north", "west", "south")


@dataclass(frozen=True)
class LearnThenHomeConfig:
    """Parameters of the scripted learn-then-home behaviour (paper values as defaults).

    Parameters
    ----------
    spot_distance_m : float
        Distance of the four training spots from home (paper: 1 m).
    learn_time_s : float
        Learning time per direction (paper 4.3: 5 s).
    head_scan_deg : tuple of float
        Head pans cycled while learning a direction and while homing.
    normalise_directions : int
        Directions at home whose frames normalise the goodness (paper 5.2).
    stop_time_s : float
        The episode ends when the robot has stood still this long (paper: 5 s).
    home_tolerance_m : float
        The robot stops when its position estimate is this close to home.
    max_homing_s : float
        Time limit of the homing phase.
    half_life_s : float
        Mixing half-life of both filters (paper 4.2: 0.3 s).
    compass : CompassConfig
        Compass parameters.
    """

    spot_distance_m: float = 1.0
    learn_time_s: float = 5.0
    head_scan_deg: tuple[float, ...] = (-40.0, -20.0, 0.0, 20.0, 40.0, 20.0, 0.0, -20.0)
    normalise_directions: int = 12
    stop_time_s: float = 5.0
    home_tolerance_m: float = 0.1
    max_homing_s: float = 60.0
    half_life_s: float = 0.3
    compass: CompassConfig = field(default_factory=CompassConfig)

    def __post_init__(self) -> None:
        for name in (
            "spot_distance_m",
            "learn_time_s",
            "stop_time_s",
            "home_tolerance_m",
            "max_homing_s",
            "half_life_s",
        ):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be finite and > 0, got {v!r}")
        if not self.head_scan_deg or any(abs(p) > 90 for p in self.head_scan_deg):
            raise ValueError(
                f"head_scan_deg must be non-empty pans within ±90°, got {self.head_scan_deg}"
            )
        if int(self.normalise_directions) < 1:
            raise ValueError("normalise_directions must be >= 1")


@dataclass
class EpisodeRecord:
    """What happened in one episode (world frame, metres and degrees)."""

    spots: dict[str, tuple[float, float]]
    home: tuple[float, float]
    learn_true: list[tuple[float, float, float]] = field(default_factory=list)
    start: tuple[float, float, float] | None = None
    true: list[tuple[float, float, float]] = field(default_factory=list)
    estimated: list[tuple[float, float, float]] = field(default_factory=list)
    heading_error: list[float] = field(default_factory=list)
    stop: tuple[float, float] | None = None
    stopped: bool = False
    fell: bool = False
    sim_time_s: float = 0.0

    def summary(self) -> dict[str, object]:
        """Home error (m), final heading error (deg), success flags."""
        assert self.stop is not None
        err = math.hypot(self.stop[0] - self.home[0], self.stop[1] - self.home[1])
        return {
            "home_error_m": err,
            "stop_offset_m": [self.stop[0] - self.home[0], self.stop[1] - self.home[1]],
            "final_heading_error_deg": abs(self.heading_error[-1]) if self.heading_error else None,
            "mean_heading_error_deg": float(np.mean(np.abs(self.heading_error)))
            if self.heading_error
            else None,
            "stopped": self.stopped,
            "fell": self.fell,
            "homing_steps": len(self.true),
            "sim_time_s": self.sim_time_s,
        }


class ScriptedLearnThenHome:
    """Runs the paper's learn-then-home episode on a ``vc_gym/AiboRoom-v0`` env.

    Parameters
    ----------
    env : gymnasium.Env
        An ``AiboRoomEnv`` (or a wrapper of one) with the default head camera.
    config : LearnThenHomeConfig, optional
        Behaviour parameters.
    progress : bool
        Show a progress bar per phase.
    """

    def __init__(self, env, config: LearnThenHomeConfig | None = None, progress: bool = True):
        self.env = env
        self.u = env.unwrapped
        self.config = config if config is not None else LearnThenHomeConfig()
        self.progress = progress
        self.dt = self.u.control_dt
        self.camera = Camera(hfov_deg=self.u.camera.hfov_deg)
        self._scan_i = 0
        # the robot's belief about its pose during learning (odometry + compass)
        self.belief = np.zeros(3)
        self.rot_scale = 1.0  # odometry turn calibration, from the loop closure at home
        self.turn_accum = 0.0
        self.home_compass: VisualCompass | None = None
        self.learn_filter: HeadingGridFilter | None = None
        self.atlas: CompassAtlas | None = None
        self.heading_filter: HeadingGridFilter | None = None
        self.obs: dict | None = None
        self.info: dict | None = None

    # ------------------------------------------------------------------ low level
    def _act(self, forward=0.0, turn=0.0, pan=0.0) -> None:
        u = self.u
        a = np.array(
            [forward / u.robot.max_forward, 0.0, turn / u.robot.max_turn_deg_s, pan / 90.0, 0.0],
            np.float32,
        )
        self.obs, _, terminated, _, self.info = self.env.step(np.clip(a, -1, 1))
        dx, dy, dth = (float(v) for v in self.obs["odometry"])
        dth *= self.rot_scale
        self.turn_accum += dth
        th = math.radians(self.belief[2])
        self.belief += [
            dx * math.cos(th) - dy * math.sin(th),
            dx * math.sin(th) + dy * math.cos(th),
            dth,
        ]
        self.belief[2] = wrap360(self.belief[2])
        if terminated:
            raise _Fell()
        if self.learn_filter is not None and self.home_compass is not None:
            # keep the heading belief on the home map while learning elsewhere
            f = self.learn_filter
            f.predict(dth, noise_deg=0.3 + 0.05 * abs(dth))
            pan = float(self.obs["head"][0])
            ll = self.home_compass.log_likelihood(self.obs["image"], self.camera)
            step = self.home_compass.config.heading_step_deg
            f.update_log_likelihood(interp_circular(ll, step, f.headings_deg + pan))
            self.belief[2] = f.estimate().heading_deg

    def _next_pan(self) -> float:
        pans = self.config.head_scan_deg
        self._scan_i = (self._scan_i + 1) % len(pans)
        return pans[self._scan_i]

    def _turn_to(self, yaw_deg: float, pan: float = 0.0, tol: float = 2.0) -> None:
        for _ in range(200):
            err = float(wrap180(yaw_deg - self.belief[2]))
            if abs(err) < tol:
                return
            self._act(turn=float(np.clip(3.0 * err, -80.0, 80.0)), pan=pan)

    def _walk_to(self, x: float, y: float, tol: float = 0.05) -> None:
        for _ in range(400):
            dx, dy = x - self.belief[0], y - self.belief[1]
            dist = math.hypot(dx, dy)
            if dist < tol:
                return
            bearing = math.degrees(math.atan2(dy, dx))
            err = float(wrap180(bearing - self.belief[2]))
            if abs(err) > 20:
                self._turn_to(bearing)
                continue
            self._act(forward=min(0.3, 1.5 * dist), turn=float(np.clip(3.0 * err, -60, 60)))

    # ------------------------------------------------------------------ phases
    def learn(self, record: EpisodeRecord) -> None:
        """Learning phase: four spots around home, then normalisation at home."""
        cfg = self.config
        steps = max(1, int(round(cfg.learn_time_s / self.dt)))
        d = cfg.spot_distance_m
        spots = {"east": (d, 0.0), "north": (0.0, d), "west": (-d, 0.0), "south": (0.0, -d)}
        self._learn_home(steps)
        colors = self.home_compass.colors
        compasses = {}
        bar = tqdm(
            total=4 * 8 * steps, desc="learn 4 spots", unit="frame", disable=not self.progress
        )
        for name in SPOT_NAMES:
            self._walk_to(*spots[name])
            vc = VisualCompass(cfg.compass, colors)
            for k in range(8):
                self._turn_to(45.0 * k)
                for _ in range(steps):
                    self._act(pan=self._next_pan())
                    pan = float(self.obs["head"][0])
                    vc.learn(self.obs["image"], self.camera.replace(yaw_deg=self.belief[2] + pan))
                    record.learn_true.append(tuple(self.info["pose"]))
                    bar.update()
            compasses[name] = (spots[name], vc)
        bar.close()
        self._walk_to(0.0, 0.0)
        self.atlas = CompassAtlas(compasses, home="home", home_position=(0.0, 0.0))
        imgs, cams = [], []
        for k in range(cfg.normalise_directions):
            self._turn_to(360.0 * k / cfg.normalise_directions)
            self._act()
            imgs.append(self.obs["image"])
            cams.append(self.camera)
        self.atlas.normalize(imgs, cams)

    def _learn_home(self, steps: int) -> None:
        """Learn the home map in a full turn and calibrate the odometry's turns.

        The robot turns a full circle in 8 steps of 45°, scanning with its head, and
        keeps the frames. Its colour classes are fitted on them (the paper calibrated
        colours beforehand). Loop closure: a map of the first direction tells how far
        the robot really turned when its odometry says 360°; that scale corrects the
        odometry from then on and the headings of every frame of the turn, which are
        then learned as the home map (odometry drift taken as proportional to the turn).
        """
        cfg = self.config
        self.turn_accum = 0.0
        start = float(self.belief[2])
        frames = []  # (image, believed body turn since the start, head pan, direction)
        for k in range(8):
            self._turn_to(start + 45.0 * k)
            for _ in range(steps):
                self._act(pan=self._next_pan())
                frames.append((self.obs["image"], self.turn_accum, float(self.obs["head"][0]), k))
        self._turn_to(start)
        for _ in range(3):
            self._act()
        per_direction = {}
        for image, _, _, k in frames:
            per_direction.setdefault(k, image)
        colors = VisualCompass(cfg.compass).fit_colors(list(per_direction.values())).colors
        first = VisualCompass(cfg.compass, colors)
        for image, turn, pan, k in frames:
            if k == 0:
                first.learn(image, self.camera.replace(yaw_deg=start + turn + pan))
        believed = self.turn_accum  # about 360
        measured = first.estimate(self.obs["image"], self.camera).heading_deg
        actual = believed + float(wrap180(measured - (start + believed)))
        if believed > 180.0:
            self.rot_scale = float(np.clip(actual / believed, 0.8, 1.25))
        home = VisualCompass(cfg.compass, colors)
        for image, turn, pan, _ in frames:
            home.learn(image, self.camera.replace(yaw_deg=start + turn * self.rot_scale + pan))
        self.home_compass = home
        self.belief[2] = wrap360(start + actual)
        self.learn_filter = HeadingGridFilter(
            rule="mixing", half_life_s=cfg.half_life_s, dt_s=self.dt
        )
        self.learn_filter.reset(self.belief[2], 2.0)

    def _heading_ll(self, atlas_est, pan: float) -> np.ndarray:
        best = max(atlas_est.goodness, key=atlas_est.goodness.get)
        ll = atlas_est.estimates[best].log_likelihood
        step = self.atlas.compasses[0].config.heading_step_deg
        return interp_circular(ll, step, self.heading_filter.headings_deg + pan)

    def home(self, record: EpisodeRecord, start_pose: tuple[float, float, float]) -> None:
        """Kidnap to ``start_pose`` and walk home with the filters (paper 5.2)."""
        cfg = self.config
        assert self.atlas is not None
        self.obs, self.info = self.env.reset(options={"pose": start_pose})
        record.start = start_pose
        hf = HeadingGridFilter(rule="mixing", half_life_s=cfg.half_life_s, dt_s=self.dt)
        tf = TranslationalFilter(self.atlas.positions, half_life_s=cfg.half_life_s, dt_s=self.dt)
        self.heading_filter = hf
        still_steps = 0
        need_still = int(round(cfg.stop_time_s / self.dt))
        n_steps = int(round(cfg.max_homing_s / self.dt))
        forward, turn = 0.0, 0.0
        for t in tqdm(range(n_steps), desc="homing", unit="step", disable=not self.progress):
            pan = self._next_pan() if forward == 0.0 else 0.0
            a = np.array(
                [
                    forward / self.u.robot.max_forward,
                    0.0,
                    turn / self.u.robot.max_turn_deg_s,
                    pan / 90.0,
                    0.0,
                ],
                np.float32,
            )
            self.obs, _, terminated, _, self.info = self.env.step(a)
            if terminated:
                record.fell = True
                break
            dx, dy, dth = (float(v) for v in self.obs["odometry"])
            hf.predict(dth, noise_deg=0.5 + 0.1 * abs(dth))
            est = self.atlas.estimate_position(self.obs["image"], self.camera)
            head_pan = float(self.obs["head"][0])
            hf.update_log_likelihood(self._heading_ll(est, head_pan))
            heading = hf.estimate().heading_deg
            th = math.radians(heading)
            tf.predict(dx * math.cos(th) - dy * math.sin(th), dx * math.sin(th) + dy * math.cos(th))
            tf.update_position(est.position)
            x, y = tf.position
            true = tuple(float(v) for v in self.info["pose"])
            record.true.append(true)
            record.estimated.append((x, y, heading))
            record.heading_error.append(float(wrap180(heading - true[2])))
            # control: first settle the heading belief, then drive to where τ̂ = home
            to_home = (-x, -y)
            dist = math.hypot(*to_home)
            if t * self.dt < 2.0 or hf.estimate().spread_deg > 30.0:
                forward, turn = 0.0, 0.0
            elif dist > cfg.home_tolerance_m:
                err = float(wrap180(math.degrees(math.atan2(to_home[1], to_home[0])) - heading))
                turn = float(np.clip(2.5 * err, -60.0, 60.0))
                forward = 0.0 if abs(err) > 30 else min(0.25, 0.8 * dist)
            else:
                forward, turn = 0.0, 0.0
            moving = forward != 0.0 or turn != 0.0
            still_steps = 0 if moving else still_steps + (t * self.dt >= 2.0)
            if still_steps >= need_still:
                record.stopped = True
                break
        record.stop = (record.true[-1][0], record.true[-1][1]) if record.true else None
        record.sim_time_s = float(self.info["sim_time"])

    def run(self, seed: int, start_pose: tuple[float, float, float] | None = None) -> EpisodeRecord:
        """One full episode: learn at home (the robot starts there facing 0°), then
        kidnapping to ``start_pose`` (default: random on the field) and homing."""
        d = self.config.spot_distance_m
        record = EpisodeRecord(
            spots={"east": (d, 0.0), "north": (0.0, d), "west": (-d, 0.0), "south": (0.0, -d)},
            home=(0.0, 0.0),
        )
        self.obs, self.info = self.env.reset(seed=seed, options={"pose": (0.0, 0.0, 0.0)})
        self.belief = np.zeros(3)
        try:
            self.learn(record)
            if start_pose is None:
                rng = np.random.default_rng(seed + 1)
                fx0, fx1, fy0, fy1 = self.u.scene.field_bounds
                start_pose = (
                    float(rng.uniform(fx0 + 0.5, fx1 - 0.5)),
                    float(rng.uniform(fy0 + 0.5, fy1 - 0.5)),
                    float(rng.uniform(0.0, 360.0)),
                )
            self.home(record, start_pose)
        except _Fell:
            record.fell = True
            record.stop = tuple(self.info["pose"][:2])
        return record


class _Fell(Exception):
    """The robot fell during the learning phase."""
