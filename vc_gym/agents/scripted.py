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
from vc_gym.filters import HeadingGridFilter
from vc_gym.validation import nonnegative_float, positive_float

__all__ = [
    "EpisodeRecord",
    "LearnThenHomeConfig",
    "RobotFell",
    "ScriptedHomingPolicy",
    "ScriptedLearnThenHome",
    "ScriptedLearner",
    "kidnap_pose",
]

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
            positive_float(name, v)
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


class ScriptedLearner:
    """The paper's learning behaviour on a ``vc_gym/AiboRoom-v0`` env (4.3, 5.2).

    The robot must stand at home facing the world's 0° (its frame is then the world
    frame). :meth:`learn` turns a full circle there (colour classes, home map, odometry
    turn calibration by loop closure), learns four spots ``spot_distance_m`` around
    home (8 × 45°, ``learn_time_s`` each, head scanning), walks back and normalises
    the spots' goodness at home. It uses camera frames, head angles and odometry only.

    Parameters
    ----------
    env : gymnasium.Env
        An ``AiboRoomEnv`` (or a wrapper of one) with the default head camera.
    config : LearnThenHomeConfig, optional
        Behaviour parameters.
    progress : bool
        Show a progress bar while learning the spots.
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
        self.obs: dict | None = None
        self.info: dict | None = None

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
            raise RobotFell()
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

    def spots(self) -> dict[str, tuple[float, float]]:
        """The four training spots around home (world metres)."""
        d = self.config.spot_distance_m
        return {"east": (d, 0.0), "north": (0.0, d), "west": (-d, 0.0), "south": (0.0, -d)}

    def learn(self, record: EpisodeRecord | None = None) -> CompassAtlas:
        """Learning phase: home turn, four spots, normalisation at home.

        Returns the normalised atlas (home ``"home"`` at ``(0, 0)``); the true poses of
        the spot-learning frames go to ``record.learn_true`` (for plots only).

        Raises
        ------
        RobotFell
            If the robot falls (only with ``locomotion="dynamic"``).
        """
        cfg = self.config
        self.belief = np.zeros(3)
        self.learn_filter = None
        steps = max(1, int(round(cfg.learn_time_s / self.dt)))
        spots = self.spots()
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
                    if record is not None:
                        record.learn_true.append(tuple(self.info["pose"]))
                    bar.update()
            compasses[name] = (spots[name], vc)
        bar.close()
        self._walk_to(0.0, 0.0)
        atlas = CompassAtlas(compasses, home="home", home_position=(0.0, 0.0))
        imgs, cams = [], []
        for k in range(cfg.normalise_directions):
            self._turn_to(360.0 * k / cfg.normalise_directions)
            self._act()
            imgs.append(self.obs["image"])
            cams.append(self.camera)
        atlas.normalize(imgs, cams)
        return atlas

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


class ScriptedHomingPolicy:
    """The paper's homing behaviour on :class:`~vc_gym.envs.CompassObservation` outputs.

    First stand still (head scanning) for ``settle_time_s`` and until the heading
    spread is below ``max_spread_deg``, so the filters settle; then turn towards the
    estimated home and walk (slower when close); stand still, scanning with the head,
    once the estimate is within ``home_tolerance_m`` of home. Uses only
    ``home_vector`` and ``heading_spread`` of the observation.

    Parameters
    ----------
    config : LearnThenHomeConfig, optional
        ``home_tolerance_m`` and ``head_scan_deg`` are used.
    dt_s : float
        Control period of the env (seconds per step).
    max_forward : float
        The env's top forward speed (m/s) that an action of 1 commands.
    max_turn_deg_s : float
        The env's top turn rate (deg/s) that an action of 1 commands.
    settle_time_s : float
        Time to stand still at the start of homing.
    max_spread_deg : float
        Stand still while the heading belief is wider than this.
    rearm_factor : float
        Once within ``home_tolerance_m``, walk again only when the estimate leaves
        ``rearm_factor × home_tolerance_m`` (the estimate jitters by ~0.1 m as the head
        scans; without this hysteresis the robot shuffles around home and never stops).
    """

    def __init__(
        self,
        config: LearnThenHomeConfig | None = None,
        dt_s: float = 0.1,
        max_forward: float = 0.5,
        max_turn_deg_s: float = 86.0,
        settle_time_s: float = 2.0,
        max_spread_deg: float = 30.0,
        rearm_factor: float = 2.5,
    ):
        for name, v in (
            ("dt_s", dt_s),
            ("max_forward", max_forward),
            ("max_turn_deg_s", max_turn_deg_s),
            ("max_spread_deg", max_spread_deg),
            ("rearm_factor", rearm_factor),
        ):
            positive_float(name, v)
        nonnegative_float("settle_time_s", settle_time_s)
        self.config = config if config is not None else LearnThenHomeConfig()
        self.dt_s = float(dt_s)
        self.max_forward = float(max_forward)
        self.max_turn_deg_s = float(max_turn_deg_s)
        self.settle_time_s = float(settle_time_s)
        self.max_spread_deg = float(max_spread_deg)
        self.rearm_factor = float(rearm_factor)
        if self.rearm_factor < 1:
            raise ValueError(f"rearm_factor must be >= 1, got {rearm_factor!r}")
        self.reset()

    def reset(self) -> None:
        """Start of a homing episode."""
        self._t = 0
        self._scan_i = 0
        self._arrived = False

    def predict(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """The action (``Box(-1, 1, (5,))`` of the env) for one observation."""
        fwd_home, left_home = (float(v) for v in obs["home_vector"])
        spread = float(obs["heading_spread"][0])
        settling = self._t * self.dt_s < self.settle_time_s or spread > self.max_spread_deg
        self._t += 1
        dist = math.hypot(fwd_home, left_home)
        # hysteresis: once arrived, only a clearly wrong estimate makes the robot move
        tol = self.config.home_tolerance_m
        self._arrived = dist <= (self.rearm_factor if self._arrived else 1.0) * tol
        forward, turn = 0.0, 0.0
        if not settling and not self._arrived:
            err = math.degrees(math.atan2(left_home, fwd_home))
            turn = float(np.clip(2.5 * err, -60.0, 60.0))
            forward = 0.0 if abs(err) > 30 else min(0.25, 0.8 * dist)
        pan = 0.0
        if forward == 0.0:
            pans = self.config.head_scan_deg
            self._scan_i = (self._scan_i + 1) % len(pans)
            pan = pans[self._scan_i]
        a = [forward / self.max_forward, 0.0, turn / self.max_turn_deg_s, pan / 90.0, 0.0]
        return np.clip(np.array(a, np.float32), -1.0, 1.0)

    @staticmethod
    def is_still(action: np.ndarray, threshold: float = 0.05) -> bool:
        """No body motion commanded (the head may move)."""
        return bool(np.all(np.abs(np.asarray(action)[:3]) <= threshold))


class ScriptedLearnThenHome:
    """Runs the paper's learn-then-home episode on a ``vc_gym/AiboRoom-v0`` env.

    :class:`ScriptedLearner` learns the place, then the robot is kidnapped (env reset
    to the start pose) and :class:`ScriptedHomingPolicy` walks home on the outputs of
    a :class:`~vc_gym.envs.CompassObservation` wrapper until it has stood still for
    ``stop_time_s``. Every step's true and estimated pose is recorded.

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
        self.learner = ScriptedLearner(env, self.config, progress)
        self.atlas: CompassAtlas | None = None

    def home(self, record: EpisodeRecord, start_pose: tuple[float, float, float]) -> None:
        """Kidnap to ``start_pose`` and walk home with the filters (paper 5.2)."""
        from vc_gym.envs.compass_observation import CompassObservation

        cfg = self.config
        assert self.atlas is not None
        env = CompassObservation(self.env, atlas=self.atlas, half_life_s=cfg.half_life_s)
        robot = self.u.robot
        policy = ScriptedHomingPolicy(
            cfg, self.dt, max_forward=robot.max_forward, max_turn_deg_s=robot.max_turn_deg_s
        )
        obs, info = env.reset(options={"pose": start_pose})
        record.start = start_pose
        still_steps = 0
        need_still = int(round(cfg.stop_time_s / self.dt))
        n_steps = int(round(cfg.max_homing_s / self.dt))
        for _ in tqdm(range(n_steps), desc="homing", unit="step", disable=not self.progress):
            action = policy.predict(obs)
            still_steps = still_steps + 1 if policy.is_still(action) else 0
            if still_steps > need_still:
                record.stopped = True
                break
            obs, _, terminated, _, info = env.step(action)
            if terminated:
                record.fell = True
                break
            c, s = (float(v) for v in obs["heading"])
            heading = math.degrees(math.atan2(s, c)) % 360.0
            true = tuple(float(v) for v in info["pose"])
            record.true.append(true)
            record.estimated.append((*(float(v) for v in obs["position"]), heading))
            record.heading_error.append(float(wrap180(heading - true[2])))
        record.stop = (record.true[-1][0], record.true[-1][1]) if record.true else None
        record.sim_time_s = float(info["sim_time"])

    def run(self, seed: int, start_pose: tuple[float, float, float] | None = None) -> EpisodeRecord:
        """One full episode: learn at home (the robot starts there facing 0°), then
        kidnapping to ``start_pose`` (default: random on the field) and homing."""
        record = EpisodeRecord(spots=self.learner.spots(), home=(0.0, 0.0))
        self.learner.obs, self.learner.info = self.env.reset(
            seed=seed, options={"pose": (0.0, 0.0, 0.0)}
        )
        try:
            self.atlas = self.learner.learn(record)
            if start_pose is None:
                start_pose = kidnap_pose(np.random.default_rng(seed + 1), self.u.scene.field_bounds)
            self.home(record, start_pose)
        except RobotFell:
            record.fell = True
            record.stop = tuple(self.learner.info["pose"][:2])
        return record


def kidnap_pose(
    rng: np.random.Generator, field_bounds: tuple[float, float, float, float], margin: float = 0.5
) -> tuple[float, float, float]:
    """A random pose on the field, ``margin`` metres inside its edges, random heading."""
    fx0, fx1, fy0, fy1 = field_bounds
    return (
        float(rng.uniform(fx0 + margin, fx1 - margin)),
        float(rng.uniform(fy0 + margin, fy1 - margin)),
        float(rng.uniform(0.0, 360.0)),
    )


class RobotFell(Exception):
    """The robot fell during the learning phase."""
