"""A quadruped with a turnable head camera in a room: free exploration."""

from __future__ import annotations

import math
import os
import sys
from typing import Any

import cv2
import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.poses import check_pose
from vc_gym.sim.bullet import bullet_client, connect, pybullet
from vc_gym.sim.head_camera import HeadCameraSpec, render_camera
from vc_gym.sim.odometry import OdometryNoise
from vc_gym.sim.robot import LOCOMOTION_MODES, Quadruped
from vc_gym.sim.scenes import Scene, build_scene, check_scene_name
from vc_gym.sim.top_view import TopView
from vc_gym.validation import check_action, check_reset_options, positive_float

__all__ = [
    "AiboRoomEnv",
    "MAX_ILLUMINATION",
    "MIN_CONTROL_DT_S",
    "ROBOT_CLEARANCE_M",
    "display_available",
]

#: Shortest ``control_dt`` (s): one step of the 240 Hz physics. A shorter step would
#: run no physics at all, and a time limit would take millions of steps to reach.
MIN_CONTROL_DT_S = 1.0 / 240.0
#: Brightest ``illumination`` (linear light; 1 is normal, above it frames saturate).
MAX_ILLUMINATION = 4.0
#: A placed robot's centre keeps this far inside the room's walls.
ROBOT_CLEARANCE_M = 0.1

#: The ``reset`` options the room takes.
RESET_OPTIONS = ("pose",)

#: Bounds of the odometry observation (m, m, degrees): far beyond one step's motion.
_ODO_LIMIT = np.array([5.0, 5.0, 720.0], np.float32)


def display_available() -> bool:
    """Whether a window can be opened here: an X or Wayland display on Linux; always on
    macOS and Windows."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


class AiboRoomEnv(gym.Env):
    """A quadruped with the Sony Aibo's head camera exploring a room (PyBullet).

    ## Description

    The robot of Sturm & Visser's visual compass paper: a four-legged robot (PyBullet's
    ``a1``) whose head carries a 208×160 camera with a 56.9° horizontal field of view,
    about 0.3 m above the floor, in one of several scenes — by default the paper's
    robot lab, a ~7×7 m room with a 6×4 m green carpet field, posters, tables and
    computers. The head pans and tilts at a bounded speed. The robot knows its motion
    only through odometry (commanded motion with per-episode scale errors and noise);
    its true pose is reported in ``info`` for evaluation only.

    ## Action Space

    ``Box(-1, 1, (5,), float32)``: forward speed, sideways speed and turn rate as
    fractions of their maxima (0.5 m/s, 0.2 m/s, 86°/s), then the head pan and tilt
    targets as fractions of their ranges (pan ±90°, positive left; tilt from -45° to
    30°, positive up: -1 is -45°, 0 is level, 1 is 30°). Actions outside [-1, 1] are
    clipped; anything but a finite real numeric array of shape ``(5,)`` (NaN, a
    complex, string or object array, a dict) is a ``ValueError``.

    ## Observation Space

    ``Dict`` with

    * ``image``: ``Box(0, 255, (160, 208, 3), uint8)``, the head camera frame (RGB);
    * ``head``: ``Box((2,), float32)``, the actual pan and tilt in degrees;
    * ``odometry``: ``Box((3,), float32)``, forward (m), left (m) and turn (degrees)
      since the previous step, as the robot's odometry reports them (bounded by
      ±5 m, ±5 m, ±720°, far beyond one step's motion).

    ## Rewards

    None: this is the free-exploration environment; the reward is always 0. Tasks with
    rewards (e.g. ``vc_gym/LearnThenHome-v0``) build on it.

    ## Starting State

    A uniformly random pose on the scene's field (robolab: the 6×4 m carpet), random
    heading, head level and centred; ``options={"pose": (x, y, yaw_deg)}`` sets it.

    ## Episode End

    Terminated when the robot falls (only possible with ``locomotion="dynamic"``);
    truncated by the registered time limit (``max_episode_steps``).

    ## Arguments

    ``gym.make("vc_gym/AiboRoom-v0", scene="robolab", randomize=False,
    locomotion="constraint", illumination=1.0, light_direction=None, control_dt=0.1,
    odometry_noise=None, camera=None, render_mode=None)``

    * ``scene``: a registered scene name (``vc_gym.envs.scene_names()``: the built-in
      ``"robolab"``, ``"office"``, ``"home"``, ``"outdoor_field"``, ``"plain_house"`` and
      any registered with ``vc_gym.sim.register_scene``).
    * ``randomize``: domain randomisation of textures, posters, furniture and light,
      drawn from the reset seed.
    * ``locomotion``: ``"constraint"`` (default: the base follows the commanded motion
      exactly with animated legs and stops at walls), ``"dynamic"`` (a real trot gait;
      falls possible) or ``"kinematic"`` (fastest; wall collisions by geometry).
    * ``illumination``: light level applied to the rendered frames in linear light
      (1 normal, 0.5 the paper's half-illumination test); ``light_direction`` the
      direction of the scene light.
    * ``control_dt``: seconds of simulated time per step, from one physics step
      (``MIN_CONTROL_DT_S``, 1/240 s) to 1 s.
    * ``odometry_noise``: an ``OdometryNoise`` (scale errors and noise).
    * ``camera``: a ``HeadCameraSpec`` (size and field of view of the head camera).

    ## Info

    ``pose`` (true x, y in m and yaw in degrees, ``float64`` array), ``head``
    (pan, tilt in degrees), ``scene`` (name), ``fallen`` (bool), ``sim_time`` (s).
    """

    #: ``human`` (the PyBullet GUI) is listed only where there is a display to open it on,
    #: so that Gymnasium's checker, which tries every listed mode, passes on a headless
    #: machine.
    metadata = {
        "render_modes": ["rgb_array", *(["human"] if display_available() else [])],
        "render_fps": 10,
    }

    def __init__(
        self,
        render_mode: str | None = None,
        scene: str = "robolab",
        randomize: bool = False,
        locomotion: str = "constraint",
        illumination: float = 1.0,
        light_direction: tuple[float, float, float] | None = None,
        control_dt: float = 0.1,
        odometry_noise: OdometryNoise | None = None,
        camera: HeadCameraSpec | None = None,
    ):
        if render_mode == "human" and not display_available():
            raise RuntimeError(
                "render_mode='human' opens the PyBullet GUI and needs a display; none was "
                "found (DISPLAY is not set). Use render_mode='rgb_array' on a headless machine."
            )
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be one of {self.metadata['render_modes']} or None, "
                f"got {render_mode!r}"
            )
        check_scene_name(scene)  # a clear ValueError listing the registered scenes
        if locomotion not in LOCOMOTION_MODES:
            raise ValueError(f"locomotion must be one of {LOCOMOTION_MODES}, got {locomotion!r}")
        if not isinstance(randomize, bool):
            raise ValueError(f"randomize must be a bool, got {randomize!r}")
        if positive_float("illumination", illumination) > MAX_ILLUMINATION:
            raise ValueError(
                f"illumination must be in (0, {MAX_ILLUMINATION:g}] (1: normal), "
                f"got {illumination!r}"
            )
        if not (math.isfinite(control_dt) and MIN_CONTROL_DT_S <= control_dt <= 1.0):
            raise ValueError(
                f"control_dt must be in [1/240, 1] seconds (at least one physics step), "
                f"got {control_dt!r}"
            )
        if light_direction is not None:
            light_direction = tuple(float(v) for v in light_direction)
            if len(light_direction) != 3 or not all(math.isfinite(v) for v in light_direction):
                raise ValueError(f"light_direction must be 3 finite numbers, got {light_direction}")
        self.render_mode = render_mode
        self.scene_name = scene
        self.randomize = randomize
        self.locomotion = locomotion
        self.illumination = float(illumination)
        self.light_direction_override = light_direction
        self.control_dt = float(control_dt)
        self.odometry_noise = odometry_noise if odometry_noise is not None else OdometryNoise()
        self.camera = camera if camera is not None else HeadCameraSpec()

        w, h = self.camera.width, self.camera.height
        self.observation_space = spaces.Dict(
            {
                "image": spaces.Box(0, 255, (h, w, 3), np.uint8),
                "head": spaces.Box(
                    np.array([-90.0, -45.0], np.float32),
                    np.array([90.0, 30.0], np.float32),
                    dtype=np.float32,
                ),
                "odometry": spaces.Box(-_ODO_LIMIT, _ODO_LIMIT, dtype=np.float32),
            }
        )
        self.action_space = spaces.Box(-1.0, 1.0, (5,), np.float32)

        self._bc: bullet_client.BulletClient | None = None
        self._robot: Quadruped | None = None
        self._scene: Scene | None = None
        self._scene_key: tuple | None = None
        self._projection: list[float] | None = None
        self._top_view: TopView | None = None
        self._last_image: np.ndarray | None = None
        self._sim_time = 0.0
        self._closed = False

    # ------------------------------------------------------------------ plumbing
    @property
    def client(self) -> bullet_client.BulletClient:
        """The env's own PyBullet client (for tests and power users)."""
        self._check_open()
        if self._bc is None:
            mode = pybullet.GUI if self.render_mode == "human" else pybullet.DIRECT
            self._bc = connect(mode)
        return self._bc

    @property
    def robot(self) -> Quadruped:
        """The robot (after :meth:`reset`)."""
        self._check_open()  # after close: say so, not "reset first"
        if self._robot is None:
            raise RuntimeError("call reset() first")
        return self._robot

    @property
    def scene(self) -> Scene:
        """The current scene (after :meth:`reset`)."""
        self._check_open()  # after close: say so, not "reset first"
        if self._scene is None:
            raise RuntimeError("call reset() first")
        return self._scene

    @property
    def scene_key(self) -> tuple | None:
        """``(scene, randomize, scene seed)`` of the built scene: changes when it is rebuilt."""
        return self._scene_key

    def inside_walls(self, x: float, y: float) -> bool:
        """Whether a robot centred at ``(x, y)`` stands at least ``ROBOT_CLEARANCE_M``
        inside the walls of the built scene (after :meth:`reset`): where it may be put."""
        rx0, rx1, ry0, ry1 = self.scene.room_bounds
        c = ROBOT_CLEARANCE_M
        return rx0 + c <= x <= rx1 - c and ry0 + c <= y <= ry1 - c

    def walls_text(self) -> str:
        """Where :meth:`inside_walls` holds, for error messages."""
        rx0, rx1, ry0, ry1 = self.scene.room_bounds
        c = ROBOT_CLEARANCE_M
        return f"x {rx0 + c:g}..{rx1 - c:g}, y {ry0 + c:g}..{ry1 - c:g} m"

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError("this AiboRoomEnv is closed; make a new one")

    def _light(self) -> tuple[float, float, float] | None:
        if self.light_direction_override is not None:
            return self.light_direction_override
        return None if self._scene is None else self._scene.light_direction

    def _build(self, scene_seed: int | None) -> None:
        bc = self.client
        bc.resetSimulation()
        rng = np.random.default_rng(scene_seed)
        self._scene = build_scene(bc, self.scene_name, rng=rng, randomize=self.randomize)
        # the robot's Generator is replaced at every reset (below); drawing its seed
        # here from np_random would make a reset that rebuilds the scene consume one
        # more number than one that does not, so reset(seed=s) would depend on history
        self._robot = Quadruped(
            bc, self.locomotion, rng=np.random.default_rng(0), odometry_noise=self.odometry_noise
        )
        self._projection = self.camera.projection(bc)
        self._top_view = None

    # ------------------------------------------------------------------ gym API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        self._check_open()
        options = check_reset_options(options, RESET_OPTIONS)
        super().reset(seed=seed)
        if self._bc is not None and not self._bc.isConnected():
            # the physics server is gone (killed, or disconnected by hand): start a new one
            # and rebuild the world in it, as a fresh env would
            self._bc = None
            self._robot = self._scene = self._top_view = None
            self._scene_key = None
        # the scene depends on the seed only when randomised; rebuild only when it changes
        scene_seed = int(self.np_random.integers(2**31)) if self.randomize else None
        key = (self.scene_name, self.randomize, scene_seed)
        if key != self._scene_key or self._robot is None:
            self._build(scene_seed)
            self._scene_key = key
        if "pose" in options:
            x, y, yaw = check_pose(options["pose"])
            if not self.inside_walls(x, y):
                raise ValueError(
                    f"pose {options['pose']!r} is not inside the walls of {self.scene_name!r} "
                    f"({self.walls_text()})"
                )
        else:
            fx0, fx1, fy0, fy1 = self.scene.field_bounds
            x = float(self.np_random.uniform(fx0, fx1))
            y = float(self.np_random.uniform(fy0, fy1))
            yaw = float(self.np_random.uniform(0.0, 360.0))
        self.robot.reset(x, y, yaw, rng=np.random.default_rng(self.np_random.integers(2**63)))
        self.robot.take_odometry()
        self._sim_time = 0.0
        obs = self._observation(np.zeros(3))
        return obs, self._info()

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        try:
            return self._step(action)
        except pybullet.error:
            # asked only when PyBullet fails, so a step pays nothing for the check
            if self._bc is not None and not self._bc.isConnected():
                raise RuntimeError(
                    "the env's physics server is gone (disconnected or killed); call "
                    "reset() to rebuild the world"
                ) from None
            raise

    def _step(
        self, action: np.ndarray
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        self._check_open()
        robot = self.robot
        a = np.clip(check_action(action, self.action_space.shape), -1.0, 1.0)
        pan_lo, pan_hi = robot.pan_limits
        tilt_lo, tilt_hi = robot.tilt_limits
        tilt = a[4] * (tilt_hi if a[4] >= 0 else -tilt_lo)
        robot.step(
            forward=a[0] * robot.max_forward,
            sideways=a[1] * robot.max_sideways,
            turn_deg_s=a[2] * robot.max_turn_deg_s,
            pan_target_deg=a[3] * (pan_hi if a[3] >= 0 else -pan_lo),
            tilt_target_deg=tilt,
            duration_s=self.control_dt,
            obstacles=self.scene.obstacles,
        )
        self._sim_time += self.control_dt
        obs = self._observation(robot.take_odometry())
        terminated = bool(robot.fallen)
        if self.render_mode == "human":
            self.render()
        return obs, 0.0, terminated, False, self._info()

    def velocity_action(
        self,
        forward_m_s: float = 0.0,
        sideways_m_s: float = 0.0,
        turn_deg_s: float = 0.0,
        pan_deg: float = 0.0,
        tilt_deg: float = 0.0,
    ) -> np.ndarray:
        """The ``Box(-1, 1, (5,))`` action that commands these velocities and head angles.

        The inverse of the scaling in :meth:`step` (forward by ``robot.max_forward``,
        sideways by ``robot.max_sideways``, turn by ``robot.max_turn_deg_s``, pan and
        tilt by their limits), clipped to the action space: the one place where
        physical commands become actions. Scripted behaviours and action adapters
        call it.
        """
        robot = self.robot
        pan_lo, pan_hi = robot.pan_limits
        tilt_lo, tilt_hi = robot.tilt_limits
        a = np.array(
            [
                forward_m_s / robot.max_forward,
                sideways_m_s / robot.max_sideways,
                turn_deg_s / robot.max_turn_deg_s,
                pan_deg / (pan_hi if pan_deg >= 0 else -pan_lo),
                tilt_deg / (tilt_hi if tilt_deg >= 0 else -tilt_lo),
            ],
            np.float32,
        )
        if not np.all(np.isfinite(a)):
            raise ValueError("velocity_action needs finite velocities and angles")
        return np.clip(a, -1.0, 1.0)

    def head_image(self) -> np.ndarray:
        """Render the head camera now (robot body hidden), as a fresh array."""
        robot = self.robot
        eye, yaw, pitch = robot.eye()
        robot.set_visible(False)
        try:
            return render_camera(
                self.client,
                self.camera,
                eye,
                yaw,
                pitch,
                projection=self._projection,
                light_direction=self._light(),
                illumination=self.illumination,
            )
        finally:
            robot.set_visible(True)

    def _observation(self, odometry: np.ndarray) -> dict[str, np.ndarray]:
        image = self.head_image()
        self._last_image = image
        return {
            "image": image.copy(),
            "head": np.asarray(self.robot.head, dtype=np.float32),
            "odometry": np.clip(np.asarray(odometry, np.float32), -_ODO_LIMIT, _ODO_LIMIT),
        }

    def _info(self) -> dict[str, Any]:
        robot = self.robot
        return {
            "pose": np.asarray(robot.pose, dtype=np.float64),
            "head": np.asarray(robot.head, dtype=np.float64),
            "scene": self.scene_name,
            "fallen": bool(robot.fallen),
            "sim_time": self._sim_time,
        }

    def render(self) -> np.ndarray | None:
        """``rgb_array``: top view of the room with the robot, its heading and the
        camera's field of view, next to the current head-camera frame (×2).
        ``human``: the PyBullet GUI shows the scene; returns ``None``."""
        self._check_open()
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode='rgb_array'")
            return None
        if self.render_mode == "human":
            return None
        robot = self.robot
        if self._top_view is None:
            # the background is rendered once: without the robot, or its body would
            # stay painted where it stood at the first render
            robot.set_visible(False)
            try:
                self._top_view = TopView(self.client, self.scene, self._light())
            finally:
                robot.set_visible(True)
        (ex, ey, _), cam_yaw, _ = robot.eye()
        x, y, yaw = robot.pose
        top = self._top_view.draw(x, y, yaw, cam_yaw, self.camera.hfov_deg)
        head = self._last_image if self._last_image is not None else self.head_image()
        scale = top.shape[0] / head.shape[0]
        head = cv2.resize(
            head, (round(head.shape[1] * scale), top.shape[0]), interpolation=cv2.INTER_NEAREST
        )
        return np.ascontiguousarray(np.concatenate([top, head], axis=1))

    def close(self) -> None:
        if self._bc is not None:
            try:
                self._bc.disconnect()
            except pybullet.error:
                pass
            self._bc = None
        self._robot = None
        self._scene = None
        self._top_view = None
        self._closed = True
