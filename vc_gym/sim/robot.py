"""The simulated quadruped: PyBullet's Unitree ``a1`` carrying an Aibo-like head camera.

The a1 has no head, so the camera ("eye") pose is computed from the base pose plus a
pan and a tilt angle that the robot moves at a bounded speed. Three locomotion modes
trade realism for speed and robustness:

``"dynamic"``
    Real trot physics: the 12 leg joints follow an open-loop trot (:mod:`vc_gym.sim.gait`:
    period 0.3 s, 6 cm foot lift, 0.27 m body height, feet 3 cm outside the hips) by
    motor position control. Forward, sideways and turning motion come from the stance feet sweeping
    backwards at the body velocity. Like a real walking engine, it ramps the velocity
    towards the command (at most 2 m/s² and 6 rad/s²) and scales a command down when
    its fastest foot would have to sweep faster than 0.5 m/s (only combined fast
    walking and turning). The robot really walks at about 0.8 × the executed speed
    forwards (0.97 × backwards, 1.0 × sideways) and turns at about 0.9 × the executed
    rate (measured, see :data:`DYNAMIC_SPEED_FACTOR`); it can bump into things and
    fall (:attr:`Quadruped.fallen`), e.g. when it walks into a wall.
``"constraint"`` (default)
    The base is carried exactly along the commanded motion by a fixed constraint with a
    limited force while the legs still trot. Static walls stop it: when the base stops
    following, the commanded pose stops advancing (it never runs away into the wall).
``"kinematic"``
    No physics at all: the base pose is integrated directly and the legs are posed by
    the gait so the robot still looks like it walks. Moves into obstacle footprints
    (axis-aligned boxes passed to :meth:`Quadruped.step`, inflated by
    :data:`ROBOT_RADIUS_M`) are refused; the robot slides along them when it can.

Angles are in degrees in the public API, counter-clockwise positive seen from above
(positive pan looks left, positive tilt looks up).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

import numpy as np

from vc_gym.angles import wrap360
from vc_gym.sim.bullet import pybullet, pybullet_data
from vc_gym.sim.gait import (
    BODY_HEIGHT_M,
    FOOT_XY,
    GAIT_PERIOD_S,
    arc_displacement,
    gait_joint_angles,
)
from vc_gym.sim.odometry import OdometryNoise
from vc_gym.validation import finite_float, positive_float

__all__ = [
    "LOCOMOTION_MODES",
    "OdometryNoise",
    "Quadruped",
    "A1_URDF",
    "BODY_HEIGHT_M",
    "EYE_OFFSET_M",
    "ROBOT_RADIUS_M",
    "DYNAMIC_SPEED_FACTOR",
    "DYNAMIC_BACKWARD_FACTOR",
    "DYNAMIC_SIDEWAYS_FACTOR",
    "DYNAMIC_TURN_FACTOR",
]

#: The locomotion modes of :class:`Quadruped`.
LOCOMOTION_MODES = ("dynamic", "constraint", "kinematic")

#: The robot model (PyBullet's Unitree a1).
A1_URDF = os.path.join(pybullet_data.getDataPath(), "a1", "a1.urdf")

#: Eye position in the trunk frame (m): ahead of the trunk like a head on a short neck,
#: so that the eye is 0.30 m above the floor when standing (the Aibo's camera height).
EYE_OFFSET_M = (0.25, 0.0, 0.03)

#: Radius of the robot's footprint in the floor plane, for obstacle inflation (m).
ROBOT_RADIUS_M = 0.25

#: Real speed / commanded speed of the dynamic trot walking forwards on a friction-1
#: floor (measured over 3 s walks at 0.1-0.5 m/s: 0.79-0.83).
DYNAMIC_SPEED_FACTOR = 0.8
#: The same walking backwards (measured at 0.3 and 0.5 m/s: 0.97).
DYNAMIC_BACKWARD_FACTOR = 0.97
#: The same walking sideways (measured at 0.1 and 0.2 m/s: 0.99-1.01).
DYNAMIC_SIDEWAYS_FACTOR = 1.0
#: Real turn rate / commanded turn rate of the dynamic trot (measured: 0.90-0.93 turning
#: in place at 30-86 deg/s, about 0.8 while also walking forwards).
DYNAMIC_TURN_FACTOR = 0.9

# ---------------------------------------------------------------- a1 joints and motors
# (the leg geometry and the trot itself are in vc_gym.sim.gait)
# joint indices of (abduction, thigh, calf) of each leg, and of the toe links
_LEG_JOINTS = [1, 3, 4, 6, 8, 9, 11, 13, 14, 16, 18, 19]
_TOE_LINKS = [5, 10, 15, 20]
_POSITION_GAINS = [0.3] * 12
_VELOCITY_GAINS = [1.0] * 12
_MOTOR_FORCES = [20.0, 55.0, 55.0] * 4
_FOOT_FRICTION = 1.0

# constraint mode: force limit of the carrying constraint and when the base "lags"
_CONSTRAINT_MAX_FORCE_N = 400.0
_LAG_TOLERANCE_M = 0.03
_LAG_TOLERANCE_DEG = 4.0

# dynamic mode: limits of the walking engine (stride of the fastest foot, acceleration)
_MAX_FOOT_SPEED = 0.5
_MAX_ACCEL = 2.0
_MAX_ANG_ACCEL = 6.0

_FALL_TILT_DEG = 60.0
_FALL_HEIGHT_M = 0.12


# ------------------------------------------------------------------------ helpers
def _rotate(q: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    """Rotate vector ``v`` by the quaternion ``q`` (x, y, z, w)."""
    qx, qy, qz, qw = q
    vx, vy, vz = v
    # t = 2 q_vec x v ; v' = v + w t + q_vec x t
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + (qy * tz - qz * ty),
        vy + qw * ty + (qz * tx - qx * tz),
        vz + qw * tz + (qx * ty - qy * tx),
    )


def _yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


def _check_limits(name: str, limits: Sequence[float]) -> tuple[float, float]:
    try:
        lo, hi = limits
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair (low, high), got {limits!r}") from None
    lo, hi = finite_float(f"{name}[0]", lo), finite_float(f"{name}[1]", hi)
    if lo > hi:
        raise ValueError(f"{name} must have low <= high, got {limits!r}")
    return lo, hi


def _check_obstacles(obstacles: Sequence[Sequence[float]]) -> np.ndarray:
    try:
        boxes = np.asarray(obstacles, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"obstacles must be a sequence of (xmin, xmax, ymin, ymax), got {obstacles!r}"
        ) from None
    if boxes.size == 0:
        return np.zeros((0, 4))
    if boxes.ndim != 2 or boxes.shape[1] != 4:
        raise ValueError(
            f"obstacles must have shape (n, 4) as (xmin, xmax, ymin, ymax), got {boxes.shape}"
        )
    if not np.all(np.isfinite(boxes)):
        raise ValueError("obstacles must be finite")
    if np.any(boxes[:, 0] > boxes[:, 1]) or np.any(boxes[:, 2] > boxes[:, 3]):
        raise ValueError("obstacles must have xmin <= xmax and ymin <= ymax")
    return boxes


# ------------------------------------------------------------------------ the robot
class Quadruped:
    """The a1 quadruped with a pan/tilt head camera, in one PyBullet client.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client; every PyBullet call goes through it. Gravity (-9.81) and the time
        step (``1 / physics_hz``) are set on it. The floor belongs to the caller; the
        dynamic gait is tuned for a floor friction of 1.0.
    locomotion : str
        One of :data:`LOCOMOTION_MODES` (see the module documentation).
    rng : numpy.random.Generator
        Source of the odometry errors (scale errors drawn at :meth:`reset`, per-step
        noise in :meth:`step`).
    odometry_noise : OdometryNoise, optional
        Odometry errors; default ``OdometryNoise()``.
    physics_hz, control_hz : int
        Physics rate and the rate at which the gait targets (and, in constraint mode,
        the wall check) are updated. ``control_hz`` must not exceed ``physics_hz``.
    max_forward, max_sideways : float
        Speed limits (m/s); commands are clipped to ``±`` these.
    max_turn_deg_s : float
        Turn-rate limit (degrees/s).
    head_speed_deg_s : float
        Speed at which pan and tilt move towards their targets (degrees/s).
    pan_limits, tilt_limits : (float, float)
        Ranges of pan (positive left) and tilt (positive up) in degrees.

    Attributes
    ----------
    body_id : int
        PyBullet body id of the robot.
    locomotion : str
        The locomotion mode.

    Notes
    -----
    Odometry reports what the walking engine was told to do, as the Aibo's did: the
    commanded velocities integrated over each step (in ``"dynamic"`` mode the executed,
    ramped velocities multiplied by the measured efficiency of the trot,
    :data:`DYNAMIC_SPEED_FACTOR`, :data:`DYNAMIC_BACKWARD_FACTOR`,
    :data:`DYNAMIC_SIDEWAYS_FACTOR` and :data:`DYNAMIC_TURN_FACTOR`), then distorted by
    the per-episode scale errors and the per-step noise of :class:`OdometryNoise`. A
    robot pushing against a wall therefore believes it is still walking, like a real
    one whose legs keep moving.

    Cost (2-core machine, floor and four walls, no rendering): a physics step takes
    about 100-115 µs; ``step(duration_s=0.1)`` (24 physics steps, 6 gait updates) about
    2.3 ms (dynamic), 2.6 ms (constraint) and 0.04 ms (kinematic); hiding and showing
    the robot about 35 µs, which saves ~9 ms of a 208×160 ``ER_TINY_RENDERER`` frame.
    Gait targets are sent every ``round(physics_hz / control_hz)`` physics steps.
    """

    def __init__(
        self,
        bc,
        locomotion: str = "constraint",
        *,
        rng: np.random.Generator,
        odometry_noise: OdometryNoise | None = None,
        physics_hz: int = 240,
        control_hz: int = 60,
        max_forward: float = 0.5,
        max_sideways: float = 0.2,
        max_turn_deg_s: float = 86.0,
        head_speed_deg_s: float = 180.0,
        pan_limits: Sequence[float] = (-90.0, 90.0),
        tilt_limits: Sequence[float] = (-45.0, 30.0),
    ) -> None:
        if locomotion not in LOCOMOTION_MODES:
            raise ValueError(f"locomotion must be one of {LOCOMOTION_MODES}, got {locomotion!r}")
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        if odometry_noise is None:
            odometry_noise = OdometryNoise()
        if not isinstance(odometry_noise, OdometryNoise):
            raise ValueError(
                f"odometry_noise must be an OdometryNoise, got {type(odometry_noise).__name__}"
            )
        for name, value in (("physics_hz", physics_hz), ("control_hz", control_hz)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if control_hz > physics_hz:
            raise ValueError(f"control_hz ({control_hz}) must not exceed physics_hz ({physics_hz})")
        self.locomotion = locomotion
        self.odometry_noise = odometry_noise
        self.physics_hz = int(physics_hz)
        self.control_hz = int(control_hz)
        self.max_forward = positive_float("max_forward", max_forward)
        self.max_sideways = positive_float("max_sideways", max_sideways)
        self.max_turn_deg_s = positive_float("max_turn_deg_s", max_turn_deg_s)
        self.head_speed_deg_s = positive_float("head_speed_deg_s", head_speed_deg_s)
        self.pan_limits = _check_limits("pan_limits", pan_limits)
        self.tilt_limits = _check_limits("tilt_limits", tilt_limits)
        self._rng = rng
        self._bc = bc
        self._dt = 1.0 / self.physics_hz
        self._ticks_per_control = max(1, round(self.physics_hz / self.control_hz))

        bc.setGravity(0.0, 0.0, -9.81)
        bc.setTimeStep(self._dt)
        # Sorted contact pairs: without this the broadphase's pair order depends on the
        # history of the client, so an episode's physics would differ by ~1e-9 m depending
        # on which episodes ran before it in the same process, and now and then such a
        # difference would flip a stop decision.
        bc.setPhysicsEngineParameter(deterministicOverlappingPairs=1)
        kinematic = locomotion == "kinematic"
        self.body_id: int = bc.loadURDF(
            A1_URDF,
            [0.0, 0.0, BODY_HEIGHT_M],
            [0.0, 0.0, 0.0, 1.0],
            useFixedBase=kinematic,
        )
        body = self.body_id
        # base (centre of mass) frame relative to the trunk (URDF link) frame
        self._com_offset = tuple(bc.getDynamicsInfo(body, -1)[3])
        for link in _TOE_LINKS:
            bc.changeDynamics(body, link, lateralFriction=_FOOT_FRICTION)
        # every visual shape with its colour, to hide and restore
        self._visuals: list[tuple[int, tuple[float, ...]]] = []
        seen: set[int] = set()
        for shape in bc.getVisualShapeData(body):
            if shape[1] not in seen:
                seen.add(shape[1])
                self._visuals.append((shape[1], tuple(shape[7])))
        self._visible = True
        self._constraint: int | None = None
        if locomotion == "constraint":
            self._constraint = bc.createConstraint(
                body,
                -1,
                -1,
                -1,
                pybullet.JOINT_FIXED,
                [0.0, 0.0, 0.0],
                [-c for c in self._com_offset],  # pin the trunk frame, not the COM
                [0.0, 0.0, BODY_HEIGHT_M],
            )
        # hot-path calls bound once (the client id is injected by the BulletClient)
        self._step_simulation = bc.stepSimulation
        self._motor_array = bc.setJointMotorControlArray
        self._change_constraint = bc.changeConstraint
        self._base_state = bc.getBasePositionAndOrientation
        self._reset_joints = bc.resetJointStatesMultiDof

        self._pan = 0.0
        self._tilt = 0.0
        self._phase = 0.0
        self._tick = 0
        # commanded trunk pose (constraint and kinematic modes): x, y, yaw (rad)
        self._cmd = [0.0, 0.0, 0.0]
        self._vel = [0.0, 0.0, 0.0]  # dynamic: executed body velocity (m/s, m/s, rad/s)
        self._move_mask = (1.0, 1.0, 1.0)  # constraint: which of world dx, dy, dyaw may advance
        self._trans_gain = 1.0
        self._rot_gain = 1.0
        self._odo = np.zeros(3)  # accumulated (forward, left, turn rad)
        self.reset(0.0, 0.0, 0.0)

    # ------------------------------------------------------------------ state
    def reset(
        self,
        x: float,
        y: float,
        yaw_deg: float,
        head_pan_deg: float = 0.0,
        head_tilt_deg: float = 0.0,
        *,
        rng: np.random.Generator | None = None,
    ) -> None:
        """Stand the robot at ``(x, y)`` facing ``yaw_deg`` and start a new episode.

        Parameters
        ----------
        x, y : float
            Trunk position on the floor (m).
        yaw_deg : float
            Heading, degrees counter-clockwise from +x.
        head_pan_deg, head_tilt_deg : float
            Initial head angles, clipped to the limits.
        rng : numpy.random.Generator, optional
            Replaces the generator for this and later draws. The per-episode odometry
            scale errors are drawn from it now; the accumulated odometry is cleared.
        """
        x = finite_float("x", x)
        y = finite_float("y", y)
        yaw = math.radians(finite_float("yaw_deg", yaw_deg))
        pan = finite_float("head_pan_deg", head_pan_deg)
        tilt = finite_float("head_tilt_deg", head_tilt_deg)
        if rng is not None:
            if not isinstance(rng, np.random.Generator):
                raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
            self._rng = rng
        bc, body = self._bc, self.body_id
        self._pan = min(max(pan, self.pan_limits[0]), self.pan_limits[1])
        self._tilt = min(max(tilt, self.tilt_limits[0]), self.tilt_limits[1])
        self._phase = 0.0
        self._tick = 0
        self._cmd = [x, y, yaw]
        self._move_mask = (1.0, 1.0, 1.0)
        self._vel = [0.0, 0.0, 0.0]
        q = _yaw_quat(yaw)
        com = _rotate(q, self._com_offset)
        bc.resetBasePositionAndOrientation(
            body, [x + com[0], y + com[1], BODY_HEIGHT_M + com[2]], q
        )
        bc.resetBaseVelocity(body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        stand = gait_joint_angles(0.0, 0.0, 0.0, 0.0)
        self._reset_joints(body, _LEG_JOINTS, [[a] for a in stand], [[0.0]] * 12)
        if self.locomotion != "kinematic":
            self._set_motors(stand)
        if self._constraint is not None:
            self._change_constraint(
                self._constraint,
                jointChildPivot=[x, y, BODY_HEIGHT_M],
                jointChildFrameOrientation=q,
                maxForce=_CONSTRAINT_MAX_FORCE_N,
            )
        noise = self.odometry_noise
        scales = self._rng.standard_normal(2)
        self._trans_gain = max(0.0, 1.0 + noise.trans_scale * float(scales[0]))
        self._rot_gain = max(0.0, 1.0 + noise.rot_scale * float(scales[1]))
        self._odo = np.zeros(3)

    @property
    def pose(self) -> tuple[float, float, float]:
        """True ``(x, y, yaw_deg)`` of the trunk; yaw in ``[0, 360)``."""
        pos, orn = self._trunk_pose()
        fx, fy, _ = _rotate(orn, (1.0, 0.0, 0.0))
        return pos[0], pos[1], float(wrap360(math.degrees(math.atan2(fy, fx))))

    @property
    def head(self) -> tuple[float, float]:
        """Actual ``(pan_deg, tilt_deg)`` of the head."""
        return self._pan, self._tilt

    @property
    def odometry_scale(self) -> tuple[float, float]:
        """This episode's multiplicative odometry scale factors (translation, rotation)."""
        return self._trans_gain, self._rot_gain

    def eye(self) -> tuple[tuple[float, float, float], float, float]:
        """Pose of the head camera.

        Returns
        -------
        position : (float, float, float)
            Eye position in the world (m), :data:`EYE_OFFSET_M` in the trunk frame.
        yaw_deg : float
            Camera yaw = body yaw + pan, in ``[0, 360)``.
        pitch_deg : float
            Camera pitch = tilt + body pitch (nose up positive).
        """
        pos, orn = self._trunk_pose()
        off = _rotate(orn, EYE_OFFSET_M)
        fx, fy, fz = _rotate(orn, (1.0, 0.0, 0.0))
        body_yaw = math.degrees(math.atan2(fy, fx))
        body_pitch = math.degrees(math.atan2(fz, math.hypot(fx, fy)))
        eye = (pos[0] + off[0], pos[1] + off[1], pos[2] + off[2])
        return eye, float(wrap360(body_yaw + self._pan)), self._tilt + body_pitch

    @property
    def fallen(self) -> bool:
        """Whether the trunk rolled or pitched beyond 60° or sank below 0.12 m."""
        pos, (qx, qy, qz, qw) = self._trunk_pose()
        roll = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
        pitch = math.asin(min(max(2.0 * (qw * qy - qz * qx), -1.0), 1.0))
        limit = math.radians(_FALL_TILT_DEG)
        return abs(roll) > limit or abs(pitch) > limit or pos[2] < _FALL_HEIGHT_M

    def take_odometry(self) -> np.ndarray:
        """Odometry accumulated since the previous call (then cleared).

        Returns
        -------
        numpy.ndarray
            ``(forward_m, left_m, turn_deg)``, float64, shape (3,): the robot's belief of
            its motion, expressed in its frame at the previous call. It contains the
            scale errors and noise of :class:`OdometryNoise`; it is not the true motion.
        """
        out = np.array([self._odo[0], self._odo[1], math.degrees(self._odo[2])])
        self._odo = np.zeros(3)
        return out

    def set_visible(self, visible: bool) -> None:
        """Show or hide every visual shape of the robot (alpha 0 hides it in all renderers).

        Hide the robot while rendering its own head camera; hidden shapes also cost no
        rendering time. Physics is unaffected.
        """
        visible = bool(visible)
        if visible == self._visible:
            return
        change = self._bc.changeVisualShape
        body = self.body_id
        for link, rgba in self._visuals:
            change(body, link, rgbaColor=rgba if visible else (rgba[0], rgba[1], rgba[2], 0.0))
        self._visible = visible

    # ------------------------------------------------------------------ motion
    def step(
        self,
        forward: float,
        sideways: float,
        turn_deg_s: float,
        pan_target_deg: float,
        tilt_target_deg: float,
        duration_s: float,
        obstacles: Sequence[tuple[float, float, float, float]] = (),
    ) -> None:
        """Walk with the given body velocity and move the head for ``duration_s`` seconds.

        Parameters
        ----------
        forward, sideways : float
            Body velocity in m/s (sideways positive to the left), clipped to the limits.
        turn_deg_s : float
            Turn rate in degrees/s (positive counter-clockwise), clipped to the limit.
        pan_target_deg, tilt_target_deg : float
            Head targets, clipped to the limits; the head moves towards them at
            ``head_speed_deg_s``.
        duration_s : float
            How long (> 0). Physics modes run ``round(duration_s * physics_hz)`` physics
            steps; the kinematic mode integrates exactly ``duration_s``.
        obstacles : sequence of (xmin, xmax, ymin, ymax)
            Floor-plane boxes the kinematic robot must not enter (inflated by
            :data:`ROBOT_RADIUS_M`); the physics modes collide with the real bodies
            instead and ignore this argument (it is still validated).
        """
        vx = finite_float("forward", forward)
        vy = finite_float("sideways", sideways)
        turn = finite_float("turn_deg_s", turn_deg_s)
        pan_t = finite_float("pan_target_deg", pan_target_deg)
        tilt_t = finite_float("tilt_target_deg", tilt_target_deg)
        duration = finite_float("duration_s", duration_s)
        if duration <= 0:
            raise ValueError(f"duration_s must be > 0, got {duration_s!r}")
        boxes = _check_obstacles(obstacles)
        vx = min(max(vx, -self.max_forward), self.max_forward)
        vy = min(max(vy, -self.max_sideways), self.max_sideways)
        turn = min(max(turn, -self.max_turn_deg_s), self.max_turn_deg_s)
        wz = math.radians(turn)

        if self.locomotion == "kinematic":
            elapsed = duration
            self._step_kinematic(vx, vy, wz, duration, boxes)
        else:
            n = round(duration * self.physics_hz)
            elapsed = n * self._dt
            if self.locomotion == "constraint":
                self._step_constraint(vx, vy, wz, n)
            else:
                executed = self._step_dynamic(vx, vy, wz, n)

        # head: constant-speed motion towards the clipped targets
        reach = self.head_speed_deg_s * elapsed
        pan_t = min(max(pan_t, self.pan_limits[0]), self.pan_limits[1])
        tilt_t = min(max(tilt_t, self.tilt_limits[0]), self.tilt_limits[1])
        self._pan += min(max(pan_t - self._pan, -reach), reach)
        self._tilt += min(max(tilt_t - self._tilt, -reach), reach)

        # odometry: what the walking engine was told, distorted
        if self.locomotion == "dynamic":
            ex, ey, eth = executed
            believed = (
                ex * (DYNAMIC_SPEED_FACTOR if ex >= 0 else DYNAMIC_BACKWARD_FACTOR),
                ey * DYNAMIC_SIDEWAYS_FACTOR,
                eth * DYNAMIC_TURN_FACTOR,
            )
        else:
            believed = arc_displacement(vx, vy, wz, elapsed)
        self._add_odometry(*believed)

    def _add_odometry(self, dx: float, dy: float, dth: float) -> None:
        noise = self.odometry_noise
        z = self._rng.standard_normal(3)
        sx = math.hypot(noise.trans_std * abs(dx), noise.slip_std_m)
        sy = math.hypot(noise.trans_std * abs(dy), noise.slip_std_m)
        dx = self._trans_gain * dx + sx * float(z[0])
        dy = self._trans_gain * dy + sy * float(z[1])
        dth = self._rot_gain * dth + noise.rot_std * abs(dth) * float(z[2])
        # compose with the accumulated motion (SE(2), frame of the last take_odometry)
        ox, oy, oth = self._odo
        c, s = math.cos(oth), math.sin(oth)
        self._odo = np.array([ox + c * dx - s * dy, oy + s * dx + c * dy, oth + dth])

    def _set_motors(self, angles: Sequence[float]) -> None:
        self._motor_array(
            self.body_id,
            _LEG_JOINTS,
            pybullet.POSITION_CONTROL,
            targetPositions=angles,
            positionGains=_POSITION_GAINS,
            velocityGains=_VELOCITY_GAINS,
            forces=_MOTOR_FORCES,
        )

    def _gait_tick(self, vx: float, vy: float, wz: float) -> None:
        """Advance the gait by one control period and send the leg targets."""
        control_dt = self._ticks_per_control * self._dt
        self._phase = (self._phase + control_dt / GAIT_PERIOD_S) % 1.0
        self._set_motors(gait_joint_angles(self._phase, vx, vy, wz))

    def _step_dynamic(self, vx: float, vy: float, wz: float, n: int) -> tuple[float, float, float]:
        """Run ``n`` physics steps; returns the executed motion (forward, left, turn rad)."""
        step = self._step_simulation
        k = self._ticks_per_control
        dt = self._dt
        # the walking engine limits the stride of the fastest foot and the acceleration
        vfx = vx - wz * FOOT_XY[:, 1]
        vfy = vy + wz * FOOT_XY[:, 0]
        fastest = float(np.sqrt(vfx * vfx + vfy * vfy).max())
        if fastest > _MAX_FOOT_SPEED:
            shrink = _MAX_FOOT_SPEED / fastest
            vx, vy, wz = vx * shrink, vy * shrink, wz * shrink
        ox = oy = oth = 0.0
        ev = self._vel
        for _ in range(n):
            if self._tick % k == 0:
                h = k * dt
                ev[0] += min(max(vx - ev[0], -_MAX_ACCEL * h), _MAX_ACCEL * h)
                ev[1] += min(max(vy - ev[1], -_MAX_ACCEL * h), _MAX_ACCEL * h)
                ev[2] += min(max(wz - ev[2], -_MAX_ANG_ACCEL * h), _MAX_ANG_ACCEL * h)
                self._gait_tick(ev[0], ev[1], ev[2])
            step()
            self._tick += 1
            # integrate the executed velocity in the frame at the start of the step
            c, s = math.cos(oth), math.sin(oth)
            ox += (c * ev[0] - s * ev[1]) * dt
            oy += (s * ev[0] + c * ev[1]) * dt
            oth += ev[2] * dt
        return ox, oy, oth

    def _step_constraint(self, vx: float, vy: float, wz: float, n: int) -> None:
        step = self._step_simulation
        change = self._change_constraint
        cid = self._constraint
        k = self._ticks_per_control
        dt = self._dt
        cmd = self._cmd
        for _ in range(n):
            if self._tick % k == 0:
                self._gait_tick(vx, vy, wz)
                self._update_move_mask(vx, vy, wz, k * dt)
            mx, my, mth = self._move_mask
            c, s = math.cos(cmd[2]), math.sin(cmd[2])
            cmd[0] += mx * (c * vx - s * vy) * dt
            cmd[1] += my * (s * vx + c * vy) * dt
            cmd[2] += mth * wz * dt
            change(
                cid,
                jointChildPivot=(cmd[0], cmd[1], BODY_HEIGHT_M),
                jointChildFrameOrientation=_yaw_quat(cmd[2]),
                maxForce=_CONSTRAINT_MAX_FORCE_N,
            )
            step()
            self._tick += 1

    def _update_move_mask(self, vx: float, vy: float, wz: float, horizon: float) -> None:
        """Constraint mode: let the commanded pose advance only where the base follows.

        A component (world x, world y, yaw) may advance if, after one more control
        period, the commanded pose would still be within the lag tolerance of the true
        trunk pose, or if the advance reduces the lag (backing away from a wall).
        """
        (px, py, _), orn = self._trunk_pose()
        fx, fy, _ = _rotate(orn, (1.0, 0.0, 0.0))
        yaw = math.atan2(fy, fx)
        cx, cy, cth = self._cmd
        c, s = math.cos(cth), math.sin(cth)
        dx = (c * vx - s * vy) * horizon
        dy = (s * vx + c * vy) * horizon
        ex, ey = cx - px, cy - py
        lag = math.hypot(ex, ey)
        tol = _LAG_TOLERANCE_M

        def ok(ax: float, ay: float) -> bool:
            new = math.hypot(ex + ax, ey + ay)
            return new <= tol or new <= lag

        if ok(dx, dy):
            mx = my = 1.0
        elif ok(dx, 0.0):
            mx, my = 1.0, 0.0
        elif ok(0.0, dy):
            mx, my = 0.0, 1.0
        else:
            mx = my = 0.0
        eth = math.atan2(math.sin(cth - yaw), math.cos(cth - yaw))
        new_eth = abs(eth + wz * horizon)
        mth = 1.0 if new_eth <= math.radians(_LAG_TOLERANCE_DEG) or new_eth <= abs(eth) else 0.0
        self._move_mask = (mx, my, mth)

    def _step_kinematic(
        self, vx: float, vy: float, wz: float, duration: float, boxes: np.ndarray
    ) -> None:
        cmd = self._cmd
        n = max(1, math.ceil(duration * self.control_hz - 1e-9))
        h = duration / n
        for _ in range(n):
            dfx, dfy, dth = arc_displacement(vx, vy, wz, h)
            c, s = math.cos(cmd[2]), math.sin(cmd[2])
            dx, dy = c * dfx - s * dfy, s * dfx + c * dfy
            x, y = cmd[0], cmd[1]
            if len(boxes):
                blocked_now = self._blocked(boxes, x, y)
                for ax, ay in ((dx, dy), (dx, 0.0), (0.0, dy), (0.0, 0.0)):
                    if not np.any(self._blocked(boxes, x + ax, y + ay) & ~blocked_now):
                        break
                dx, dy = ax, ay
            cmd[0] = x + dx
            cmd[1] = y + dy
            cmd[2] += dth
        self._phase = (self._phase + duration / GAIT_PERIOD_S) % 1.0
        q = _yaw_quat(cmd[2])
        com = _rotate(q, self._com_offset)
        bc, body = self._bc, self.body_id
        bc.resetBasePositionAndOrientation(
            body, [cmd[0] + com[0], cmd[1] + com[1], BODY_HEIGHT_M + com[2]], q
        )
        legs = gait_joint_angles(self._phase, vx, vy, wz)
        self._reset_joints(body, _LEG_JOINTS, [[a] for a in legs])

    @staticmethod
    def _blocked(boxes: np.ndarray, x: float, y: float) -> np.ndarray:
        """Which boxes the robot's disc (radius ROBOT_RADIUS_M) at (x, y) overlaps."""
        gx = np.maximum(np.maximum(boxes[:, 0] - x, x - boxes[:, 1]), 0.0)
        gy = np.maximum(np.maximum(boxes[:, 2] - y, y - boxes[:, 3]), 0.0)
        return gx * gx + gy * gy < ROBOT_RADIUS_M * ROBOT_RADIUS_M

    def _trunk_pose(self) -> tuple[tuple[float, float, float], tuple[float, ...]]:
        """World position and orientation of the trunk (URDF) frame."""
        com, orn = self._base_state(self.body_id)
        off = _rotate(orn, self._com_offset)
        return (com[0] - off[0], com[1] - off[1], com[2] - off[2]), orn
