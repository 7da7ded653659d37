"""Tests of the simulated quadruped (vc_gym.sim.robot)."""

from __future__ import annotations

import math

import numpy as np
import pybullet
import pytest
from pybullet_utils import bullet_client

from vc_gym.angles import wrap180
from vc_gym.sim.odometry import OdometryNoise
from vc_gym.sim.robot import (
    BODY_HEIGHT_M,
    LOCOMOTION_MODES,
    ROBOT_RADIUS_M,
    Quadruped,
)

WALL = (1.0, 1.2, -2.0, 2.0)  # a wall 1 m ahead of the origin, across the x axis


def _box(bc, lo, hi, rgba=(0.7, 0.7, 0.7, 1.0)) -> int:
    half = [(b - a) / 2 for a, b in zip(lo, hi, strict=True)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi, strict=True)]
    col = bc.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
    vis = bc.createVisualShape(pybullet.GEOM_BOX, halfExtents=half, rgbaColor=rgba)
    body = bc.createMultiBody(0, col, vis, basePosition=centre)
    bc.changeDynamics(body, -1, lateralFriction=1.0)
    return body


@pytest.fixture
def bc():
    """A DIRECT client with a 20 x 20 m floor (top at z = 0)."""
    client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
    try:
        _box(client, (-10, -10, -0.1), (10, 10, 0.0), rgba=(0.3, 0.5, 0.3, 1.0))
        yield client
    finally:
        client.disconnect()


def _wall(bc, box=WALL) -> None:
    _box(bc, (box[0], box[2], 0.0), (box[1], box[3], 0.5))


def _robot(bc, mode="constraint", seed=0, **kwargs) -> Quadruped:
    return Quadruped(bc, mode, rng=np.random.default_rng(seed), **kwargs)


def _walk(robot, forward, sideways, turn, seconds, dt=0.1, obstacles=()) -> None:
    for _ in range(round(seconds / dt)):
        robot.step(forward, sideways, turn, 0.0, 0.0, dt, obstacles=obstacles)


# ------------------------------------------------------------------ locomotion
@pytest.mark.parametrize("mode", LOCOMOTION_MODES)
def test_walks_forward(bc, mode):
    robot = _robot(bc, mode)
    robot.reset(0.0, 0.0, 0.0)
    _walk(robot, 0.3, 0.0, 0.0, 2.0)
    x, y, yaw = robot.pose
    ratio = x / 0.6
    if mode == "dynamic":  # real trot: ~0.8x, plus the acceleration ramp
        assert 0.6 < ratio < 1.0
        assert abs(y) < 0.1 and abs(wrap180(yaw)) < 10.0
    else:
        assert 0.95 < ratio < 1.03
        assert abs(y) < 0.01 and abs(wrap180(yaw)) < 1.0
    assert not robot.fallen


@pytest.mark.parametrize("mode", LOCOMOTION_MODES)
def test_turns(bc, mode):
    robot = _robot(bc, mode)
    robot.reset(1.0, 2.0, 30.0)
    _walk(robot, 0.0, 0.0, 60.0, 1.5)
    x, y, yaw = robot.pose
    turned = wrap180(yaw - 30.0)
    if mode == "dynamic":  # ~0.9x, plus the acceleration ramp
        assert 0.65 * 90 < turned < 1.0 * 90
        assert math.hypot(x - 1.0, y - 2.0) < 0.1
    else:
        assert abs(turned - 90.0) < 3.0
        assert math.hypot(x - 1.0, y - 2.0) < 0.01
    assert not robot.fallen


def test_dynamic_stays_up_at_the_limits(bc):
    robot = _robot(bc, "dynamic")
    robot.reset(0.0, 0.0, 0.0)
    # abrupt switches between extreme commands (beyond the limits: clipped)
    for command in [(1.0, 0.0, 200.0), (-1.0, 0.0, -200.0), (0.5, 0.3, 86.0), (-0.5, -0.2, 86.0)]:
        _walk(robot, *command, 1.0)
        assert not robot.fallen, command


def test_fallen_reports_a_flipped_robot(bc):
    robot = _robot(bc, "dynamic")
    robot.reset(0.0, 0.0, 0.0)
    assert not robot.fallen
    upside_down = pybullet.getQuaternionFromEuler([math.pi, 0.0, 0.0])
    bc.resetBasePositionAndOrientation(robot.body_id, [0.0, 0.0, 0.3], upside_down)
    assert robot.fallen


@pytest.mark.parametrize("mode", ["constraint", "kinematic"])
def test_stops_at_a_wall(bc, mode):
    _wall(bc)
    robot = _robot(bc, mode)
    robot.reset(0.0, 0.0, 0.0)
    _walk(robot, 0.5, 0.0, 0.0, 4.0, obstacles=[WALL])
    x, y, yaw = robot.pose
    assert 0.65 < x < WALL[0] - 0.2  # reached the wall, did not enter it
    assert abs(y) < 0.02 and abs(wrap180(yaw)) < 2.0
    assert not robot.fallen
    # the commanded pose did not run away into the wall: backing off starts at once
    _walk(robot, -0.3, 0.0, 0.0, 1.0, obstacles=[WALL])
    assert robot.pose[0] < x - 0.25


def test_kinematic_keeps_out_of_inflated_obstacles(bc):
    robot = _robot(bc, "kinematic")
    box = (1.0, 1.5, -0.5, 0.5)
    robot.reset(0.0, 0.3, 20.0)
    positions = []
    for _ in range(40):
        robot.step(0.5, 0.0, 0.0, 0.0, 0.0, 0.1, obstacles=[box])
        positions.append(robot.pose[:2])
    for x, y in positions:
        gx = max(box[0] - x, x - box[1], 0.0)
        gy = max(box[2] - y, y - box[3], 0.0)
        assert math.hypot(gx, gy) >= ROBOT_RADIUS_M - 1e-9
    # it slid along the obstacle instead of stopping dead: no sideways progress lost
    assert positions[-1][1] == pytest.approx(0.3 + 2.0 * math.sin(math.radians(20.0)))
    assert min(x for x, _ in positions) < box[0] - ROBOT_RADIUS_M + 0.01 < positions[-1][0]


def test_step_runs_the_expected_number_of_physics_steps(bc):
    class Counting:
        def __init__(self, client):
            self.client = client
            self.steps = 0

        def stepSimulation(self):
            self.steps += 1
            return self.client.stepSimulation()

        def __getattr__(self, name):
            return getattr(self.client, name)

    counting = Counting(bc)
    robot = _robot(counting, "constraint", physics_hz=240, control_hz=60)
    robot.step(0.2, 0.0, 0.0, 0.0, 0.0, 0.1)
    assert counting.steps == 24
    kinematic = _robot(counting, "kinematic")
    kinematic.step(0.2, 0.0, 0.0, 0.0, 0.0, 0.1)
    assert counting.steps == 24


# ------------------------------------------------------------------ head and eye
def test_head_moves_at_bounded_speed_and_clips():
    client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
    try:
        robot = _robot(client, "kinematic", head_speed_deg_s=180.0)
        robot.reset(0.0, 0.0, 0.0)
        assert robot.head == (0.0, 0.0)
        robot.step(0.0, 0.0, 0.0, 60.0, -60.0, 0.1)
        assert robot.head == pytest.approx((18.0, -18.0))
        robot.step(0.0, 0.0, 0.0, 60.0, -60.0, 1.0)
        assert robot.head == pytest.approx((60.0, -45.0))  # tilt clipped at -45
        robot.step(0.0, 0.0, 0.0, 500.0, 500.0, 2.0)
        assert robot.head == pytest.approx((90.0, 30.0))
        robot.step(0.0, 0.0, 0.0, -500.0, 0.0, 0.5)
        assert robot.head == pytest.approx((0.0, 0.0))
        robot.reset(0.0, 0.0, 0.0, head_pan_deg=-200.0, head_tilt_deg=10.0)
        assert robot.head == pytest.approx((-90.0, 10.0))
    finally:
        client.disconnect()


@pytest.mark.parametrize("mode", LOCOMOTION_MODES)
def test_eye_pose(bc, mode):
    robot = _robot(bc, mode)
    robot.reset(0.5, -1.0, 350.0, head_pan_deg=30.0, head_tilt_deg=-10.0)
    for _ in range(3):  # let the dynamic robot settle, head kept where it is
        robot.step(0.0, 0.0, 0.0, 30.0, -10.0, 0.1)
    assert robot.head == (30.0, -10.0)
    (ex, ey, ez), cam_yaw, cam_pitch = robot.eye()
    x, y, yaw = robot.pose
    assert wrap180(cam_yaw - (yaw + 30.0)) == pytest.approx(0.0, abs=1e-6)
    assert 0.0 <= cam_yaw < 360.0
    assert cam_pitch == pytest.approx(-10.0, abs=2.0)
    assert ez == pytest.approx(0.30, abs=0.02)
    # the eye is 0.25 m ahead of the trunk, in the body's heading direction
    ahead = math.degrees(math.atan2(ey - y, ex - x))
    assert wrap180(ahead - yaw) == pytest.approx(0.0, abs=1.0)
    assert math.hypot(ex - x, ey - y) == pytest.approx(0.25, abs=0.01)


def test_reset_places_the_robot(bc):
    robot = _robot(bc, "constraint")
    _walk(robot, 0.3, 0.0, 30.0, 0.5)
    robot.reset(-2.0, 3.0, 123.0)
    x, y, yaw = robot.pose
    assert (x, y, yaw) == pytest.approx((-2.0, 3.0, 123.0), abs=1e-6)
    assert robot.eye()[0][2] == pytest.approx(BODY_HEIGHT_M + 0.03, abs=1e-6)
    assert np.all(robot.take_odometry() == 0.0)


# ------------------------------------------------------------------ odometry
def _odometry_run(mode: str, seed: int) -> tuple[np.ndarray, tuple[float, float, float]]:
    client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
    try:
        _box(client, (-10, -10, -0.1), (10, 10, 0.0))
        robot = _robot(client, mode, seed=seed)
        robot.reset(0.0, 0.0, 0.0)
        _walk(robot, 0.3, 0.05, 20.0, 1.0)
        return robot.take_odometry(), robot.pose
    finally:
        client.disconnect()


@pytest.mark.parametrize("mode", LOCOMOTION_MODES)
def test_odometry_is_seeded_and_not_the_truth(mode):
    odo_a, pose_a = _odometry_run(mode, seed=1)
    odo_b, pose_b = _odometry_run(mode, seed=1)
    odo_c, _ = _odometry_run(mode, seed=2)
    assert odo_a.shape == (3,) and odo_a.dtype == np.float64
    np.testing.assert_array_equal(odo_a, odo_b)
    assert pose_a == pose_b
    assert not np.allclose(odo_a, odo_c)
    # close to the true motion, but not equal to it
    true = np.array([pose_a[0], pose_a[1], wrap180(pose_a[2])])
    assert not np.allclose(odo_a, true, atol=1e-4)
    assert np.allclose(odo_a[:2], true[:2], atol=0.1)
    assert abs(odo_a[2] - true[2]) < 6.0


def test_odometry_is_in_the_frame_of_the_last_call(bc):
    robot = _robot(bc, "kinematic", odometry_noise=OdometryNoise(0, 0, 0, 0, 0))
    robot.reset(1.0, 1.0, 90.0)
    _walk(robot, 0.0, 0.0, 60.0, 1.5)  # turn left 90 degrees in place
    _walk(robot, 0.4, 0.0, 0.0, 1.0)  # then 0.4 m ahead: to the robot's former left
    np.testing.assert_allclose(robot.take_odometry(), [0.0, 0.4, 90.0], atol=1e-9)
    np.testing.assert_array_equal(robot.take_odometry(), np.zeros(3))


def test_odometry_scale_errors_have_the_configured_spread(bc):
    noise = OdometryNoise(trans_scale=0.08, rot_scale=0.04, trans_std=0.0, rot_std=0.0)
    robot = _robot(bc, "kinematic", odometry_noise=noise, seed=3)
    trans, rot = [], []
    for _ in range(200):
        robot.reset(0.0, 0.0, 0.0)
        robot.step(0.5, 0.0, 60.0, 0.0, 0.0, 0.5)
        odo = robot.take_odometry()
        x, y, yaw = robot.pose
        trans.append(math.hypot(odo[0], odo[1]) / math.hypot(x, y))
        rot.append(odo[2] / wrap180(yaw))
    assert np.std(trans) == pytest.approx(0.08, rel=0.3)
    assert np.std(rot) == pytest.approx(0.04, rel=0.3)
    assert abs(np.mean(trans) - 1.0) < 3 * 0.08 / math.sqrt(200)
    assert abs(np.mean(rot) - 1.0) < 3 * 0.04 / math.sqrt(200)


def test_odometry_step_noise_scales_with_motion(bc):
    noise = OdometryNoise(trans_scale=0.0, rot_scale=0.0, trans_std=0.05, rot_std=0.1)
    robot = _robot(bc, "kinematic", odometry_noise=noise, seed=4)
    forward, turn = [], []
    for _ in range(200):
        robot.reset(0.0, 0.0, 0.0)
        robot.step(0.4, 0.0, 0.0, 0.0, 0.0, 1.0)  # 0.4 m
        forward.append(robot.take_odometry()[0])
        robot.step(0.0, 0.0, 40.0, 0.0, 0.0, 0.5)  # 20 degrees
        turn.append(robot.take_odometry()[2])
    assert np.std(forward) == pytest.approx(0.05 * 0.4, rel=0.3)
    assert np.mean(forward) == pytest.approx(0.4, abs=0.01)
    assert np.std(turn) == pytest.approx(0.1 * 20.0, rel=0.3)


def test_dynamic_odometry_is_calibrated(bc):
    robot = _robot(bc, "dynamic", odometry_noise=OdometryNoise(0, 0, 0, 0, 0))
    robot.reset(0.0, 0.0, 0.0)
    _walk(robot, 0.4, 0.0, 0.0, 2.0)
    odo = robot.take_odometry()
    x, _, _ = robot.pose
    assert odo[0] == pytest.approx(x, rel=0.1)


# ------------------------------------------------------------------ visibility
def test_set_visible_hides_the_robot_from_the_camera(bc):
    robot = _robot(bc, "kinematic")
    robot.reset(0.0, 0.0, 45.0)
    view = bc.computeViewMatrix([0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    proj = bc.computeProjectionMatrixFOV(40.0, 1.0, 0.1, 10.0)

    def shot():
        _, _, rgb, _, seg = bc.getCameraImage(
            96, 96, view, proj, renderer=pybullet.ER_TINY_RENDERER
        )
        rgb = np.asarray(rgb, dtype=np.uint8).reshape(96, 96, 4)[..., :3]
        return rgb, np.count_nonzero(np.asarray(seg).reshape(96, 96) == robot.body_id)

    rgb_shown, shown = shot()
    robot.set_visible(False)
    rgb_hidden, hidden = shot()
    robot.set_visible(True)
    rgb_again, again = shot()
    assert shown > 200
    assert hidden == 0
    changed = np.count_nonzero(np.abs(rgb_shown.astype(int) - rgb_hidden).sum(axis=2) > 30)
    assert changed > 0.8 * shown
    assert again == shown
    np.testing.assert_array_equal(rgb_again, rgb_shown)


# ------------------------------------------------------------------ validation
def test_bad_arguments_raise(bc):
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="dynamic"):
        Quadruped(bc, "walking", rng=rng)
    with pytest.raises(ValueError, match="Generator"):
        Quadruped(bc, "kinematic", rng=np.random.RandomState(0))  # noqa: NPY002
    with pytest.raises(ValueError, match="control_hz"):
        Quadruped(bc, "kinematic", rng=rng, physics_hz=60, control_hz=240)
    with pytest.raises(ValueError, match="pan_limits"):
        Quadruped(bc, "kinematic", rng=rng, pan_limits=(30.0, -30.0))
    with pytest.raises(ValueError, match="max_forward"):
        Quadruped(bc, "kinematic", rng=rng, max_forward=float("nan"))
    with pytest.raises(ValueError, match="odometry_noise"):
        Quadruped(bc, "kinematic", rng=rng, odometry_noise=0.1)
    robot = Quadruped(bc, "kinematic", rng=rng)
    good = dict(forward=0.1, sideways=0.0, turn_deg_s=0.0, pan_target_deg=0.0, tilt_target_deg=0.0)
    for key in good:
        with pytest.raises(ValueError, match=key):
            robot.step(**{**good, key: float("nan")}, duration_s=0.1)
    for duration in (0.0, -0.1, float("inf"), float("nan")):
        with pytest.raises(ValueError, match="duration_s"):
            robot.step(**good, duration_s=duration)
    for obstacles in ([(0.0, 1.0, 0.0)], [(1.0, 0.0, 0.0, 1.0)], [(0, 1, 0, float("nan"))]):
        with pytest.raises(ValueError, match="obstacles"):
            robot.step(**good, duration_s=0.1, obstacles=obstacles)
    with pytest.raises(ValueError, match="yaw_deg"):
        robot.reset(0.0, 0.0, float("inf"))
    with pytest.raises(ValueError, match="Generator"):
        robot.reset(0.0, 0.0, 0.0, rng=42)


@pytest.mark.parametrize(
    "field", ["trans_scale", "rot_scale", "trans_std", "rot_std", "slip_std_m"]
)
@pytest.mark.parametrize("value", [-0.1, float("nan"), float("inf")])
def test_odometry_noise_validates(field, value):
    with pytest.raises(ValueError, match=field):
        OdometryNoise(**{field: value})


def test_names_moved_out_of_robot_stay_importable():
    import vc_gym.sim
    from vc_gym.sim import gait, odometry, robot

    assert robot.OdometryNoise is odometry.OdometryNoise is vc_gym.sim.OdometryNoise
    assert robot.BODY_HEIGHT_M == gait.BODY_HEIGHT_M
    for module in (robot, vc_gym.sim):
        for name in module.__all__:
            assert hasattr(module, name), (module.__name__, name)
