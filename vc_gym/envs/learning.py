"""The learning phase of the learn-then-home task: the paper's scripted behaviour (4.3, 5.2).

The robot stands at home (the field's kickoff circle), turns a full circle there
(colour classes, home map, odometry turn calibration by loop closure), learns the
panorama at four spots 1 m around home (a full turn in 8 steps of 45°, each direction
for ``learn_time_s`` with head scanning), walks back home and normalises the spots'
goodness there. It uses camera frames, head angles and odometry only; the true pose is
recorded for plots, never used. Beyond the paper, ``LearningConfig(around_m=...)`` also
learns short turns around home and every spot, for the ``pose`` tracker.

The task env calls a *learner*: any callable ``learner(room, config) -> LearningResult``
(default :class:`ScriptedLearning`), so tests and users can bring their own.
:class:`SpotLearning` is the learner of the paper's orientation experiment (5.1): one
full turn at a single spot, no walking.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace

import numpy as np
from tqdm import tqdm

from vc_gym.angles import interp_circular, wrap180, wrap360
from vc_gym.compass import Camera, ColorClasses, CompassAtlas, CompassConfig, VisualCompass
from vc_gym.compass.bearings import FrameBearings, bands_bearings
from vc_gym.compass.light_gain import REFERENCE_EXPOSURES
from vc_gym.compass.turn_placement import LearnedTurn, place_turns
from vc_gym.filters import HeadingGridFilter
from vc_gym.poses import body_to_world, compose, world_to_body
from vc_gym.sim.robot import EYE_OFFSET_M
from vc_gym.validation import (
    MAX_HALF_LIFE_S,
    MAX_LEARN_TIME_S,
    finite_float,
    flag,
    head_pans,
    int_at_least,
    nonnegative_float,
    positive_float,
    positive_float_at_most,
)

__all__ = [
    "HEAD_SCAN_DEG",
    "LANDMARK_DIMMED_STOPS",
    "HOME",
    "NORMALISE_AT",
    "SPOT_NAMES",
    "Learner",
    "LearningConfig",
    "LearningResult",
    "RobotFell",
    "ScriptedLearner",
    "ScriptedLearning",
    "paper_spots",
    "scripted_atlas_size",
    "SpotLearning",
    "GridLearning",
    "kidnap_pose",
]

#: Home of the task: the world origin (robolab: the centre of the kickoff circle).
HOME = (0.0, 0.0)
SPOT_NAMES = ("east", "north", "west", "south")
#: Where the learning phase normalises the spots (see :class:`LearningConfig`).
NORMALISE_AT = ("return", "start")
#: Head pans cycled while the robot learns a direction, and while it stands still homing.
HEAD_SCAN_DEG = (-40.0, -20.0, 0.0, 20.0, 40.0, 20.0, 0.0, -20.0)
#: With landmarks and maps that read the light: the learning frames are also read as a
#: room this many stops darker would show them
#: (:func:`~vc_gym.compass.bearings.bands_bearings`), so that an edge of a surface whose
#: class flips with a level of rounding is learned under both pairs.
LANDMARK_DIMMED_STOPS = (1.0,)


#: The turns learned around home and each spot with ``around_m``, in the order walked:
#: east, north, west, south (entries ``NAME.e``, ``NAME.n``, ...).
AROUND_SIDES = ("e", "n", "w", "s")


def scripted_atlas_size(config: LearningConfig) -> int:
    """Entries of the atlas :meth:`ScriptedLearner.learn` makes with ``config``: the four
    spots, or with ``around_m`` home and the spots each with its turns around."""
    _check_config(config)
    if not config.around_m:
        return len(SPOT_NAMES)
    return (1 + len(SPOT_NAMES)) * (1 + len(AROUND_SIDES))


class RobotFell(Exception):
    """The robot fell during the learning phase."""


@dataclass(frozen=True)
class LearningConfig:
    """Parameters of the scripted learning phase (paper values as defaults).

    Parameters
    ----------
    spot_distance_m : float
        Distance of the four training spots from home (paper: 1 m).
    learn_time_s : float
        Learning time per direction (paper 4.3: 5 s); at most
        :data:`~vc_gym.validation.MAX_LEARN_TIME_S` (60 s).
    head_scan_deg : tuple of float
        Head pans cycled while learning a direction.
    normalise_at : str
        Where the spots' goodness is normalised (paper 5.2). ``"return"`` (the paper):
        after the spots are learned the robot walks back home by odometry and takes
        ``normalise_directions`` frames there; odometry drift puts it 15-20 cm from the
        true home in the simulated robolab, and homing later stops where it
        normalised. ``"start"``: the frames of the first full turn, taken at the true
        home before the robot ever moved (no walk back).
    normalise_directions : int
        Directions at home whose frames normalise the goodness (paper 5.2).
    half_life_s : float
        Mixing half-life of the heading filter that keeps the robot's heading on the
        home map while it walks between spots (paper 4.2: 0.3 s); at most
        :data:`~vc_gym.validation.MAX_HALF_LIFE_S` (60 s).
    compass : CompassConfig
        Compass parameters of every map.
    around_m : float
        Beyond the paper: with ``around_m > 0`` the robot also walks to the four points
        ``around_m`` east, north, west and south of home and of every spot and learns a
        quarter-length turn at each, kept as atlas entries of their own (``home.e``,
        ``east.n``, ...), and home's own turn becomes the entry ``home``: what a
        tracker needs to re-draw a spot's map for a nearby position
        (:class:`~vc_gym.compass.pose_maps.PoseMaps`). Default 0: the paper's four
        spots. At most half of ``spot_distance_m``.
    landmarks : bool
        Beyond the paper: keep every learned turn's colour changes at their bearings
        (:func:`~vc_gym.compass.bearings.bands_bearings`), place the turns anew where
        their changes agree (:func:`~vc_gym.compass.turn_placement.place_turns`) and
        keep the changes' positions as the atlas' ``landmarks``
        (:class:`~vc_gym.compass.landmarks.LandmarkMap`), what a bearing tracker
        measures against. Default ``False``.
    """

    spot_distance_m: float = 1.0
    learn_time_s: float = 5.0
    head_scan_deg: tuple[float, ...] = HEAD_SCAN_DEG
    normalise_directions: int = 12
    normalise_at: str = "return"
    half_life_s: float = 0.3
    compass: CompassConfig = field(default_factory=CompassConfig)
    around_m: float = 0.0
    landmarks: bool = False

    def __post_init__(self) -> None:
        positive_float("spot_distance_m", self.spot_distance_m)
        positive_float_at_most("learn_time_s", self.learn_time_s, MAX_LEARN_TIME_S, "seconds")
        positive_float_at_most("half_life_s", self.half_life_s, MAX_HALF_LIFE_S, "seconds")
        nonnegative_float("around_m", self.around_m)
        flag("landmarks", self.landmarks)
        if self.around_m > 0.5 * self.spot_distance_m:
            raise ValueError(
                f"around_m must be at most half of spot_distance_m ({self.spot_distance_m:g} m)"
                f", got {self.around_m!r}"
            )
        head_pans("head_scan_deg", self.head_scan_deg)
        if self.normalise_at not in NORMALISE_AT:
            raise ValueError(
                f"normalise_at must be one of {NORMALISE_AT}, got {self.normalise_at!r}"
            )
        n = self.normalise_directions
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"normalise_directions must be an int >= 1, got {n!r}")
        if not isinstance(self.compass, CompassConfig):
            raise ValueError(f"compass must be a CompassConfig, got {type(self.compass).__name__}")

    def to_key(self) -> dict:
        """The fields as plain data, identifying a learned place (atlas files, the place
        cache); ``around_m`` and ``landmarks`` only when set, so the places learned
        without them keep their keys."""
        out = asdict(self)
        for name in ("around_m", "landmarks"):
            if not out[name]:
                del out[name]
        return out


@dataclass
class LearningResult:
    """What a learning phase produced.

    Attributes
    ----------
    atlas : CompassAtlas
        The learned, normalised atlas (home at :data:`HOME`).
    spots : dict
        Where the robot meant to learn each atlas entry (world metres), by name.
    true_path : list of tuple
        True ``(x, y, yaw)`` of every spot-learning frame (for plots only).
    odometry_turn_scale : float
        The loop-closure correction of the odometry's turns (1: none).
    turn_corrections : numpy.ndarray or None
        With ``LearningConfig(landmarks=True)``: ``(turns, 4)`` how each learned turn
        (home first, then in the order learned) was placed anew, a
        :data:`~vc_gym.compass.turn_placement.Correction` of where it was believed.
    turns : list of LearnedTurn
        With ``LearningConfig(landmarks=True)``: the learned turns as believed (home
        first), their frames' colour changes at the odometry's headings.
    """

    atlas: CompassAtlas
    spots: dict[str, tuple[float, float]]
    true_path: list[tuple[float, float, float]] = field(default_factory=list)
    odometry_turn_scale: float = 1.0
    turn_corrections: np.ndarray | None = None
    turns: list[LearnedTurn] = field(default_factory=list)


#: A learner: ``learner(room, config) -> LearningResult``. ``room`` is a
#: ``vc_gym/AiboRoom-v0`` env just reset with the robot at home facing 0°.
Learner = Callable[..., LearningResult]


#: Longest walk to one goal while learning (simulated seconds); then the robot stays put.
WALK_LIMIT_S = 30.0


def paper_spots(spot_distance_m: float) -> dict[str, tuple[float, float]]:
    """The paper's four training spots ``spot_distance_m`` east, north, west and south of
    home (the world origin), by name (5.2)."""
    d = float(spot_distance_m)
    return {"east": (d, 0.0), "north": (0.0, d), "west": (-d, 0.0), "south": (0.0, -d)}


class ScriptedLearner:
    """The paper's learning behaviour on a ``vc_gym/AiboRoom-v0`` env (4.3, 5.2).

    The robot must stand at home facing the world's 0° (its frame is then the world
    frame). :meth:`learn` turns a full circle there (colour classes, home map, odometry
    turn calibration by loop closure), learns four spots ``spot_distance_m`` around
    home (8 × 45°, ``learn_time_s`` each, head scanning), walks back and normalises the
    spots' goodness at home. :meth:`learn_turn` is the full turn on its own: the map
    of the one spot the robot stands on (the paper's orientation experiment, 5.1).

    Parameters
    ----------
    room : AiboRoomEnv
        The room env (unwrapped), with the default head camera.
    config : LearningConfig, optional
        Behaviour parameters.
    progress : bool
        Show a progress bar while learning the spots.
    """

    def __init__(self, room, config: LearningConfig | None = None, progress: bool = False):
        self.room = room
        self.config = config if config is not None else LearningConfig()
        self.progress = progress
        self.dt = room.control_dt
        self.camera = Camera(hfov_deg=room.camera.hfov_deg)
        self._scan_i = 0
        # the robot's belief about its pose during learning (odometry + compass)
        self.belief = np.zeros(3)
        self.rot_scale = 1.0  # odometry turn calibration, from the loop closure at home
        self.turn_accum = 0.0
        self.home_compass: VisualCompass | None = None
        self.learn_filter: HeadingGridFilter | None = None
        self.obs: dict | None = None
        self._home_frames: list[np.ndarray] = []  # the first turn's images, at home
        self.info: dict | None = None
        #: env steps taken so far, and walks that ended before reaching their goal
        #: (:data:`WALK_LIMIT_S`)
        self.steps_taken = 0
        self.unreached = 0
        #: true ``(x, y, yaw)`` of every frame of the last :meth:`learn_turn` (plots only)
        self.turn_path: list[tuple[float, float, float]] = []
        #: with ``config.landmarks``: every turn learned, its frames' colour changes at
        #: the body headings the odometry counted (home first)
        self.turns: list[LearnedTurn] = []
        # the odometry alone, heading unwrapped (the belief's heading follows the home
        # map), and where it stood at the last learning frame: the walks between turns
        self.odometry = np.zeros(3)
        self._last_frame_odometry: np.ndarray | None = None

    def _act(self, forward: float = 0.0, turn: float = 0.0, pan: float = 0.0) -> None:
        self.steps_taken += 1
        action = self.room.velocity_action(forward_m_s=forward, turn_deg_s=turn, pan_deg=pan)
        self.obs, _, terminated, _, self.info = self.room.step(action)
        dx, dy, dth = (float(v) for v in self.obs["odometry"])
        dth *= self.rot_scale
        self.turn_accum += dth
        x, y, th = compose(tuple(self.belief), (dx, dy, dth))
        self.belief = np.array([x, y, th])
        ox, oy = body_to_world(dx, dy, self.odometry[2])
        self.odometry += (ox, oy, dth)
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
        # a walk that has not arrived after WALK_LIMIT_S ends where the robot stands (a
        # heading belief that never settles, e.g. in a plain room seen by a small
        # camera, would otherwise turn towards the goal for thousands of steps)
        limit = self.steps_taken + int(round(WALK_LIMIT_S / self.dt))
        for _ in range(400):
            if self.steps_taken >= limit:
                self.unreached += 1
                return
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
        return paper_spots(self.config.spot_distance_m)

    def steps_per_direction(self) -> int:
        """Frames learned per direction: ``learn_time_s`` at the room's control rate."""
        return max(1, int(round(self.config.learn_time_s / self.dt)))

    def learn_turn(
        self, steps: int | None = None, colors: ColorClasses | None = None
    ) -> VisualCompass:
        """Learn the map of the spot the robot stands on in one full turn (paper 4.3).

        The robot turns a full circle in 8 steps of 45°, ``steps`` frames per
        direction with head scanning; the colour classes are fitted on the turn's
        frames and the odometry's turns are calibrated by loop closure (see
        :meth:`_learn_home`). Afterwards the robot faces where it started and its
        heading belief is kept on the new map (:attr:`learn_filter`), so it can
        turn on and, e.g., take normalisation frames.

        Every call starts afresh: the belief is the origin facing 0°, the odometry
        calibration and the head scan restart. The map's headings are therefore in
        the frame the robot stood in when the call began — the world frame when it
        faced the world's 0°.

        Parameters
        ----------
        steps : int, optional
            Frames per direction; default ``round(learn_time_s / control_dt)``
            (at least 1).
        colors : ColorClasses, optional
            Colour classes to learn with (e.g. another spot's, so that the goodness of
            the spots compares); default: fitted on the turn's frames.

        Returns
        -------
        VisualCompass
            The learned map (also kept as ``home_compass``); the odometry's turn
            scale is ``rot_scale`` and the true poses of the frames ``turn_path``.

        Raises
        ------
        ValueError
            If ``steps`` is not an int >= 1.
        RobotFell
            If the robot falls (only with ``locomotion="dynamic"``).
        """
        if colors is not None and not isinstance(colors, ColorClasses):
            raise ValueError(f"colors must be ColorClasses, got {type(colors).__name__}")
        if steps is None:
            steps = self.steps_per_direction()
        elif isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
            raise ValueError(f"steps must be an int >= 1, got {steps!r}")
        self.belief = np.zeros(3)
        self.odometry = np.zeros(3)
        self._last_frame_odometry = None
        self.learn_filter = None
        self.home_compass = None
        self.rot_scale = 1.0
        self._scan_i = 0
        self._learn_home(int(steps), colors)
        return self.home_compass

    def _normalise(self, atlas: CompassAtlas) -> None:
        """Normalise ``atlas`` on ``normalise_directions`` frames taken where the robot
        stands, turning in equal steps (paper 5.2)."""
        cfg = self.config
        imgs, cams = [], []
        for k in range(cfg.normalise_directions):
            self._turn_to(360.0 * k / cfg.normalise_directions)
            self._act()
            imgs.append(self.obs["image"])
            cams.append(self.camera)
        atlas.normalize(imgs, cams)

    def learn(self) -> LearningResult:
        """Learning phase: home turn, four spots, normalisation at home (with
        ``around_m``, also the turns around home and every spot).

        Raises
        ------
        RobotFell
            If the robot falls (only with ``locomotion="dynamic"``).
        """
        cfg = self.config
        steps = self.steps_per_direction()
        around_steps = max(1, steps // 4)
        spots = self.spots()
        path: list[tuple[float, float, float]] = []
        self.learn_turn(steps)
        colors = self.home_compass.colors
        compasses: dict[str, tuple[tuple[float, float], VisualCompass]] = {}
        # frames: the four spots' turns, and with around_m four short turns around home
        # and around each spot
        around_frames = len(AROUND_SIDES) * 8 * around_steps if cfg.around_m else 0
        bar = tqdm(
            total=len(SPOT_NAMES) * 8 * steps + (1 + len(SPOT_NAMES)) * around_frames,
            desc="learn 4 spots" + (" and the turns around" if cfg.around_m else ""),
            unit="frame",
            disable=not self.progress,
        )
        if cfg.around_m:
            compasses["home"] = (HOME, self.home_compass)
            compasses.update(self._learn_around("home", HOME, colors, around_steps, path, bar))
        for name in SPOT_NAMES:
            self._walk_to(*spots[name])
            compasses[name] = (spots[name], self._learn_here(colors, steps, path, bar))
            if cfg.around_m:
                compasses.update(
                    self._learn_around(name, spots[name], colors, around_steps, path, bar)
                )
        bar.close()
        atlas = CompassAtlas(compasses, home="home", home_position=HOME)
        if cfg.normalise_at == "start":
            # every frame of the first turn: taken at the true home, all around, with
            # the head scanning (many frames per heading: the home level is not noisy)
            images = self._home_frames
            atlas.normalize(images, [self.camera] * len(images))
        else:
            self._walk_to(*HOME)
            self._normalise(atlas)
        if self.unreached:
            warnings.warn(
                f"{self.unreached} walk(s) of the learning phase ended after {WALK_LIMIT_S:g} s "
                "without reaching their goal (a heading belief that never settled); their maps "
                "were learned where the robot stood, away from the positions the atlas gives",
                UserWarning,
                stacklevel=2,
            )
        corrections = None
        if cfg.landmarks:
            atlas.landmarks, corrections = place_turns(self.turns, eye_forward_m=EYE_OFFSET_M[0])
        learned = {name: place for name, (place, _) in compasses.items()}
        return LearningResult(atlas, learned, path, self.rot_scale, corrections, list(self.turns))

    def _learn_here(self, colors: ColorClasses, steps: int, path: list, bar: tqdm) -> VisualCompass:
        """The map of where the robot stands: 8 × 45° by its belief, ``steps`` frames
        each with head scanning (4.3)."""
        vc = VisualCompass(self.config.compass, colors)
        frames = []  # with landmarks: (changes, body heading by odometry, head pan)
        gains = []  # with landmarks: the frames' light
        start = None  # the belief and the odometry's count at the turn's first frame
        for k in range(8):
            self._turn_to(45.0 * k)
            for _ in range(steps):
                self._act(pan=self._next_pan())
                pan = float(self.obs["head"][0])
                vc.learn(self.obs["image"], self.camera.replace(yaw_deg=self.belief[2] + pan))
                path.append(tuple(float(v) for v in self.info["pose"]))
                if self.config.landmarks:
                    if start is None:
                        start = (*self.belief, self.turn_accum, self._walk())
                    # the heading belief follows the home map, whose parallax bends it
                    # away from home; the odometry counts the turn itself well
                    yaw = start[2] + self.turn_accum - start[3]
                    changes = _landmark_changes(vc, self.obs["image"], self.camera)
                    frames.append((changes, float(yaw), pan))
                    gains.extend(_frame_gains(vc, [self.obs["image"]], self.camera))
                    self._last_frame_odometry = self.odometry.copy()
                bar.update()
        if frames:
            self.turns.append(
                LearnedTurn(float(start[0]), float(start[1]), tuple(frames), start[4], tuple(gains))
            )
        return vc

    def _walk(self) -> tuple[float, float, float] | None:
        """The odometry's ``(forward, left, turn)`` since the last learning frame, in the
        body's frame there (``None`` before the first)."""
        last = self._last_frame_odometry
        if last is None:
            return None
        forward, left = world_to_body(*(self.odometry[:2] - last[:2]), last[2])
        return float(forward), float(left), float(self.odometry[2] - last[2])

    def _learn_around(
        self,
        name: str,
        spot: tuple[float, float],
        colors: ColorClasses,
        steps: int,
        path: list,
        bar: tqdm,
    ) -> dict[str, tuple[tuple[float, float], VisualCompass]]:
        """Turns at the four points ``around_m`` east, north, west and south of
        ``spot``, walked to in that order, as entries ``NAME.e``, ``NAME.n``, ..."""
        r = self.config.around_m
        x, y = spot
        out = {}
        for side, (px, py) in zip(
            AROUND_SIDES, ((x + r, y), (x, y + r), (x - r, y), (x, y - r)), strict=True
        ):
            self._walk_to(px, py)
            out[f"{name}.{side}"] = ((px, py), self._learn_here(colors, steps, path, bar))
        return out

    def _learn_home(self, steps: int, colors: ColorClasses | None = None) -> None:
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
        self.turn_path = []
        x0, y0, start = (float(v) for v in self.belief)
        frames = []  # (image, believed body turn since the start, head pan, direction)
        for k in range(8):
            self._turn_to(start + 45.0 * k)
            for _ in range(steps):
                self._act(pan=self._next_pan())
                frames.append((self.obs["image"], self.turn_accum, float(self.obs["head"][0]), k))
                self.turn_path.append(tuple(float(v) for v in self.info["pose"]))
                self._last_frame_odometry = self.odometry.copy()
        self._turn_to(start)
        for _ in range(3):
            self._act()
        self._home_frames = [image for image, _, _, _ in frames]
        if colors is None:
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
        if cfg.landmarks:
            self.turns = [
                LearnedTurn(
                    x0,
                    y0,
                    tuple(
                        (
                            _landmark_changes(home, image, self.camera),
                            start + turn * self.rot_scale,
                            pan,
                        )
                        for image, turn, pan, _ in frames
                    ),
                    frame_gains=_frame_gains(home, self._home_frames, self.camera),
                )
            ]
        self.belief[2] = wrap360(start + actual)
        self.learn_filter = HeadingGridFilter(
            rule="mixing", half_life_s=cfg.half_life_s, dt_s=self.dt
        )
        self.learn_filter.reset(self.belief[2], 2.0)


def _landmark_changes(compass: VisualCompass, image: np.ndarray, camera: Camera) -> FrameBearings:
    """A learning frame's changes for the landmarks. With maps that read the light (a
    reference level), also as a room :data:`LANDMARK_DIMMED_STOPS` darker shows them:
    the readings a bearings tracker makes of a dimmer room."""
    lit = compass.config.exposure in REFERENCE_EXPOSURES
    dimmed = LANDMARK_DIMMED_STOPS if lit else ()
    return bands_bearings(image, camera, compass.colors, dimmed_stops=dimmed)


def _frame_gains(
    compass: VisualCompass, images: list[np.ndarray], camera: Camera
) -> tuple[float, ...]:
    """The images' :meth:`~vc_gym.compass.VisualCompass.frame_gain` (the light their
    colour changes are seen at), or none for maps without a reference level."""
    if compass.config.exposure not in REFERENCE_EXPOSURES:
        return ()
    return tuple(compass.frame_gain(image, camera) for image in images)


class ScriptedLearning:
    """The default learner of the task env: runs :class:`ScriptedLearner`.

    Parameters
    ----------
    progress : bool
        Show a progress bar while the spots are learned.
    """

    def __init__(self, progress: bool = False):
        self.progress = bool(progress)

    def __repr__(self) -> str:
        return "ScriptedLearning()"

    def __call__(self, room, config: LearningConfig) -> LearningResult:
        return ScriptedLearner(room, config, progress=self.progress).learn()


def _check_config(config: object) -> None:
    if not isinstance(config, LearningConfig):
        raise ValueError(f"config must be a LearningConfig, got {type(config).__name__}")


class SpotLearning:
    """A learner for the paper's orientation experiment (5.1): one spot, one full turn.

    The robot is placed at ``spot`` facing the world's 0°, learns the panorama there
    in a full turn (:meth:`ScriptedLearner.learn_turn`: 8 × 45°, ``learn_time_s``
    each with head scanning, colour classes, odometry loop closure) and normalises
    the spot's goodness on ``normalise_directions`` frames taken at the spot, so that
    the normalised goodness ``L̂`` (eq. 28) is 1 there (as the paper's 5.2 does at
    home; figure 5 right plots it over the field).

    Parameters
    ----------
    spot : tuple of float
        The training spot ``(x, y)`` in world metres (paper 5.1: the centre of the rear
        field half).

    Examples
    --------
    >>> room.reset(seed=1)                                     # doctest: +SKIP
    >>> result = SpotLearning((-1.5, 0.0))(room, LearningConfig())  # doctest: +SKIP
    >>> result.atlas.names                                     # doctest: +SKIP
    ('spot',)
    """

    #: Name of the one spot of the atlas (and its home).
    name = "spot"

    def __init__(self, spot: tuple[float, float]):
        try:
            x, y = spot
        except (TypeError, ValueError):
            raise ValueError(f"spot must be (x, y) in metres, got {spot!r}") from None
        self.spot = (finite_float("spot x", x), finite_float("spot y", y))

    def __repr__(self) -> str:
        return f"SpotLearning(spot={self.spot})"

    def __call__(self, room, config: LearningConfig) -> LearningResult:
        """Learn the spot on ``room`` (``AiboRoomEnv``, unwrapped) with ``config``.

        The room is reset without a seed (its random generator continues from the
        caller's last reset) with the robot at the spot facing 0°.

        Returns
        -------
        LearningResult
            ``atlas``: one spot named ``"spot"`` at ``spot``, its home, normalised;
            ``spots``: ``{"spot": spot}``; ``true_path``: the true poses of the
            turn's frames; ``odometry_turn_scale``: the loop-closure correction.

        Raises
        ------
        RobotFell
            If the robot falls (only with ``locomotion="dynamic"``).
        """
        _check_config(config)
        room.reset(options={"pose": (*self.spot, 0.0)})
        learner = ScriptedLearner(room, config)
        compass = learner.learn_turn()
        atlas = CompassAtlas({self.name: (self.spot, compass)}, home=self.name)
        learner._normalise(atlas)
        return LearningResult(
            atlas, {self.name: self.spot}, list(learner.turn_path), learner.rot_scale
        )


class GridLearning:
    """A learner for maps on a grid of spots: the paper's spot learning at every spot.

    At each spot in turn the robot is placed facing 0° and learns the panorama in a full
    turn, as :class:`SpotLearning` does (8 × 45°, ``learn_time_s`` each with head
    scanning, odometry loop closure). The colour classes are fitted at the first spot
    and shared by every map, so the spots' raw scores compare (eq. 28). The first spot
    is the atlas' home. The atlas is not normalised: normalising at one place (paper
    5.2) makes every spot fit equally well *there*, so the map that fits best could no
    longer be told at that spot.

    Beyond the paper, ``around_m > 0`` also learns a full turn at the four points
    ``around_m`` east, west, north and south of every spot (``around_steps`` frames per
    direction) and adds them to the spot's map (:meth:`VisualCompass.merge`). The map
    then holds how the view changes within ``around_m`` of its spot, so it still fits,
    with the right heading, a robot that stands between spots: over the robolab field
    the heading error from the best-fitting map fell by about a third with 0.5 m
    (``vc-gym experiment orientation --modes spot-grid``). With ``keep_around=True`` the
    four turns are kept as atlas entries of their own instead, at the points where they
    were learned and named after their spot (``spot3.e``, ``spot3.w``, ``spot3.n``,
    ``spot3.s``), so a tracker can re-draw a spot's map for a nearby position from them
    (:class:`~vc_gym.compass.ParallaxMap`).

    Parameters
    ----------
    spots : sequence of (x, y)
        The training spots, world metres; the first is home. At most 64.
    around_m : float
        Distance of the four extra turns around each spot (0: the paper's one turn).
    around_steps : int, optional
        Frames per direction of each extra turn; default a quarter of the spot's own
        (so the four extra turns together take as long as the spot's).
    keep_around : bool
        Keep the extra turns as entries of their own (default False: merged into the
        spot's map). Needs ``around_m > 0``.
    """

    #: The names of the turns around a spot, after the spot's name and a dot, in the
    #: order east, west, north, south.
    around_names = ("e", "w", "n", "s")

    #: Spot names are this prefix and the spot's index.
    prefix = "spot"

    def __init__(
        self,
        spots,
        around_m: float = 0.0,
        around_steps: int | None = None,
        keep_around: bool = False,
    ):
        try:
            pts = [(finite_float("spot x", x), finite_float("spot y", y)) for x, y in spots]
        except (TypeError, ValueError):
            raise ValueError(f"spots must be (x, y) pairs in metres, got {spots!r}") from None
        if not 1 <= len(pts) <= 64 or len(set(pts)) != len(pts):
            raise ValueError(f"spots must be 1 to 64 distinct (x, y) pairs, got {len(pts)}")
        self.spots = pts
        self.around_m = nonnegative_float("around_m", around_m)
        self.around_steps = (
            None if around_steps is None else int_at_least("around_steps", around_steps, 1)
        )
        self.keep_around = flag("keep_around", keep_around)
        if self.keep_around and not self.around_m:
            raise ValueError("keep_around=True needs turns around the spots (around_m > 0)")

    def __repr__(self) -> str:
        extra = f", around_m={self.around_m}" if self.around_m else ""
        extra += ", keep_around=True" if self.keep_around else ""
        return f"GridLearning(spots={self.spots}{extra})"

    def _around(self, spot: tuple[float, float]) -> list[tuple[float, float]]:
        if not self.around_m:
            return []
        x, y, r = *spot, self.around_m
        return [(x + r, y), (x - r, y), (x, y + r), (x, y - r)]

    def __call__(self, room, config: LearningConfig) -> LearningResult:
        """Learn every spot on ``room`` (``AiboRoomEnv``, unwrapped) with ``config``.

        Returns
        -------
        LearningResult
            ``atlas``: the spots ``spot0``, ``spot1``, ... at their positions (with
            ``keep_around``, each followed by its turns ``spot0.e``, ... at theirs), home
            ``spot0``, not normalised; ``spots``; ``true_path``: the true poses of every
            turn's frames; ``odometry_turn_scale``: the first spot's loop closure.

        Raises
        ------
        RobotFell
            If the robot falls (only with ``locomotion="dynamic"``).
        """
        _check_config(config)
        maps, path, colors, scale = {}, [], None, 1.0
        turns: list[LearnedTurn] = []  # with landmarks: every turn, where it was placed

        def keep_turn(learner: ScriptedLearner, place: tuple[float, float]) -> None:
            if config.landmarks:  # learned in the frame of the robot placed facing 0°
                turns.append(replace(learner.turns[0], x=place[0], y=place[1]))

        for i, spot in enumerate(self.spots):
            room.reset(options={"pose": (*spot, 0.0)})
            learner = ScriptedLearner(room, config)
            compass = learner.learn_turn(colors=colors)
            if colors is None:
                colors, scale = compass.colors, learner.rot_scale
            path.extend(learner.turn_path)
            keep_turn(learner, spot)
            steps = self.around_steps or max(1, learner.steps_per_direction() // 4)
            name = f"{self.prefix}{i}"
            maps[name] = (spot, compass)
            for side, place in zip(self.around_names, self._around(spot), strict=False):
                room.reset(options={"pose": (*place, 0.0)})
                turn = learner.learn_turn(steps, colors=colors)
                path.extend(learner.turn_path)
                keep_turn(learner, place)
                if self.keep_around:
                    maps[f"{name}.{side}"] = (place, turn)
                else:
                    compass.merge(turn)
        atlas = CompassAtlas(maps, home=f"{self.prefix}0")
        corrections = None
        if config.landmarks:
            # every turn stood where the robot was placed: only the turns' scales are
            # adjusted with the landmarks
            atlas.landmarks, corrections = place_turns(
                turns, eye_forward_m=EYE_OFFSET_M[0], known=[True] * len(turns)
            )
        names = {n: p for n, (p, _) in maps.items()}
        return LearningResult(atlas, names, path, scale, corrections, turns)


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
