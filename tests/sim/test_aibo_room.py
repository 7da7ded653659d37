"""Every registered vc_gym env behaves like a well-made Gymnasium env.

Small camera images keep the suite fast; ``vc-gym bench env`` measures full size.
"""

from __future__ import annotations

import math
import multiprocessing as mp
import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import vc_gym
from vc_gym.sim.head_camera import HeadCameraSpec
from vc_gym.sim.scenes import SCENES

ENV_IDS = sorted(vc_gym.ENV_SPECS)
SMALL = HeadCameraSpec(52, 40, 56.9)

# Warnings we accept from the checkers, with the reason:
ALLOWED_WARNINGS = (
    # SB3 prefers channel-first images; Gymnasium's convention (and ours) is HxWxC
    "channel",
    # the learning phase says so when a walk did not arrive: in plain_house this small
    # camera's heading belief does not always settle
    "walk(s) of the learning phase ended",
)


#: Envs registered as a task plus wrappers (their entry point is a function).
WRAPPED = {"vc_gym/Homing-v0"}

#: Per-env keyword arguments that keep the tests fast (a short scripted learning phase).
FAST = {
    "vc_gym/LearnThenHome-v0": {"learn_time_s": 0.2, "learning_seed": 0},
    "vc_gym/Homing-v0": {"learn_time_s": 0.2, "learning_seed": 0},
}


def make(env_id, **kwargs):
    kwargs.setdefault("camera", SMALL)
    return gym.make(env_id, **{**FAST.get(env_id, {}), **kwargs})


def _filtered(record):
    return [
        str(w.message)
        for w in record
        if not any(a in str(w.message) for a in ALLOWED_WARNINGS)
        and "pkg_resources" not in str(w.message)
    ]


@pytest.mark.slow
@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("scene", SCENES)
def test_gymnasium_check_env(env_id, scene):
    env = make(env_id, scene=scene)
    # an env made of wrappers is checked as the agent sees it (the checker then warns
    # that it is not the unwrapped env: expected)
    wrapped = env_id in WRAPPED
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        check_env(env if wrapped else env.unwrapped)
    env.close()
    problems = [m for m in _filtered(record) if not (wrapped and "unwrapped version" in m)]
    assert not problems, problems


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_sb3_check_env(env_id):
    sb3_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    env = make(env_id)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        sb3_checker.check_env(env, warn=True)
    env.close()
    assert not _filtered(record), _filtered(record)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_observations(env_id):
    runs = []
    for _ in range(2):
        env = make(env_id, randomize=True)
        obs, _ = env.reset(seed=123)
        env.action_space.seed(7)
        frames = [obs]
        for i in range(50):
            obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
            frames.append(obs)
            if terminated or truncated:  # e.g. a stop decision of vc_gym/Homing-v0
                obs, _ = env.reset(seed=1000 + i)
                frames.append(obs)
        env.close()
        runs.append(frames)
    for a, b in zip(*runs, strict=True):
        if isinstance(a, dict):
            assert a.keys() == b.keys()
            for key in a:
                np.testing.assert_array_equal(a[key], b[key])
        else:  # vc_gym/Homing-v0: one feature vector
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("scene", SCENES)
def test_different_seeds_different_randomised_scenes(scene):
    images = []
    for seed in (1, 2):
        env = make("vc_gym/AiboRoom-v0", scene=scene, randomize=True)
        obs, _ = env.reset(seed=seed, options={"pose": (0.0, 0.0, 0.0)})
        images.append(obs["image"])
        env.close()
    assert not np.array_equal(images[0], images[1])


def test_observations_are_fresh_arrays():
    env = make("vc_gym/AiboRoom-v0")
    obs1, info1 = env.reset(seed=0)
    obs2, _, _, _, info2 = env.step(np.zeros(5, np.float32))
    for key in obs1:
        assert not np.shares_memory(obs1[key], obs2[key])
    assert not np.shares_memory(info1["pose"], info2["pose"])
    env.close()


def test_info_reports_true_pose_and_odometry_differs():
    env = make("vc_gym/AiboRoom-v0", locomotion="kinematic")
    _, info = env.reset(seed=3, options={"pose": (0.0, 0.0, 0.0)})
    assert info["pose"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    assert info["scene"] == "robolab" and info["fallen"] is False
    total = np.zeros(3)
    for _ in range(10):
        obs, reward, terminated, truncated, info = env.step(np.array([0.6, 0, 0, 0, 0], np.float32))
        total += obs["odometry"]
        assert reward == 0.0 and not terminated
    true_dx = info["pose"][0]
    assert true_dx == pytest.approx(0.3, rel=0.1)  # 10 steps of 0.1 s at 0.3 m/s
    assert total[0] != pytest.approx(true_dx, abs=1e-9)  # odometry is not the truth
    assert total[0] == pytest.approx(true_dx, rel=0.3)
    env.close()


def test_render_rgb_array_shape():
    env = make("vc_gym/AiboRoom-v0", render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    # the top view (square) and the head frame scaled to the same height, side by side
    h = frame.shape[0]
    assert frame.shape[1] == h + round(SMALL.width * h / SMALL.height)
    env.close()


def test_the_top_views_background_does_not_keep_the_robot_where_it_first_stood():
    backgrounds = []
    for pose in ((1.0, 1.0, 0.0), (-1.5, -1.0, 90.0)):
        env = make("vc_gym/AiboRoom-v0", render_mode="rgb_array")
        env.reset(seed=0, options={"pose": pose})
        env.render()  # the first render draws the background
        backgrounds.append(env.unwrapped._top_view.background.copy())
        assert env.unwrapped.robot._visible  # shown again after the background
        env.close()
    np.testing.assert_array_equal(backgrounds[0], backgrounds[1])


def test_render_human_without_display_is_a_clear_error(monkeypatch):
    from vc_gym.sim import aibo_room

    monkeypatch.setattr(aibo_room, "display_available", lambda: False)
    with pytest.raises(RuntimeError, match="display"):
        aibo_room.AiboRoomEnv(render_mode="human")


def test_a_step_before_the_first_reset_is_refused():
    env = make("vc_gym/AiboRoom-v0")
    with pytest.raises(RuntimeError, match="reset"):
        env.unwrapped.step(np.zeros(5, np.float32))
    env.close()


def test_close_is_idempotent_and_closed_env_refuses():
    env = make("vc_gym/AiboRoom-v0")
    env.reset(seed=0)
    env.close()
    env.close()
    with pytest.raises(RuntimeError, match="closed"):
        env.unwrapped.step(np.zeros(5, np.float32))
    with pytest.raises(RuntimeError, match="closed"):
        env.unwrapped.reset()
    # what wrappers reach for (the robot, the scene) says closed too, not "reset first"
    for reach in (lambda: env.unwrapped.robot, lambda: env.unwrapped.scene):
        with pytest.raises(RuntimeError, match="closed"):
            reach()


def test_repeated_make_close_does_not_leak_clients():
    import pybullet

    before = None
    for _ in range(6):
        env = make("vc_gym/AiboRoom-v0")
        env.reset(seed=0)
        cid = env.unwrapped.client._client
        before = cid if before is None else before
        env.close()
        assert not pybullet.isConnected(physicsClientId=cid)
    # client ids are reused, so six make/close cycles did not pile up connections
    assert cid <= before + 1


@pytest.mark.parametrize(
    "kwargs",
    [
        {"scene": "moon"},
        {"locomotion": "teleport"},
        {"illumination": 0.0},
        {"illumination": float("nan")},
        {"illumination": 100.0},
        {"illumination": True},
        {"control_dt": 0.0},
        {"control_dt": 1e-6},  # no physics step: a time limit would take 10^8 steps
        {"render_mode": "ascii"},
        {"randomize": "yes"},
    ],
)
def test_bad_arguments(kwargs):
    with pytest.raises(ValueError):
        gym.make("vc_gym/AiboRoom-v0", **kwargs)


@pytest.mark.parametrize(
    ("pose", "message"),
    [
        ((100.0, 100.0, 0.0), "pose .* inside the walls"),
        ((0.0, -3.48, 0.0), "pose .* inside the walls"),
        ((np.nan, 0.0, 0.0), "pose must be 3 finite"),
    ],
)
def test_a_pose_outside_the_walls_is_refused(pose, message):
    env = make("vc_gym/AiboRoom-v0")
    with pytest.raises(ValueError, match=message):
        env.reset(seed=0, options={"pose": pose})
    env.reset(seed=0, options={"pose": (3.3, -3.3, 10.0)})  # near a corner, inside: fine
    env.close()


def test_bad_actions():
    env = make("vc_gym/AiboRoom-v0")
    env.reset(seed=0)
    with pytest.raises(ValueError):
        env.step(np.zeros(4, np.float32))
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([np.nan, 0, 0, 0, 0], np.float32))
    env.step(np.full(5, 7.0, np.float32))  # out of range is clipped, not an error
    env.close()


def _make_and_step(env_id: str) -> tuple:
    env = gym.make(f"vc_gym:{env_id}", camera=HeadCameraSpec(26, 20, 56.9))
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step(env.action_space.sample())
    env.close()
    return obs["image"].shape, obs["odometry"].dtype.str


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_make_in_fresh_subprocess(method):
    ctx = mp.get_context(method)
    with ctx.Pool(1) as pool:
        shape, dtype = pool.apply(_make_and_step, ("vc_gym/AiboRoom-v0",))
    assert shape == (20, 26, 3) and dtype == "<f4"


def test_env_spec_pickles():
    env = make("vc_gym/AiboRoom-v0")
    spec = pickle.loads(pickle.dumps(env.spec))
    assert spec.id == "vc_gym/AiboRoom-v0"
    env.close()


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_vector_envs_of_two(mode):
    venv = gym.make_vec("vc_gym/AiboRoom-v0", num_envs=2, vectorization_mode=mode, camera=SMALL)
    obs, _ = venv.reset(seed=0)
    assert obs["image"].shape == (2, SMALL.height, SMALL.width, 3)
    for _ in range(3):
        obs, reward, terminated, truncated, info = venv.step(venv.action_space.sample())
    assert reward.shape == (2,)
    assert not np.array_equal(obs["image"][0], obs["image"][1])  # different start poses
    venv.close()


# ------------------------------------------------------------------ geometry
def _add_marker(bc, x, y):
    vs = bc.createVisualShape(bc.GEOM_BOX, halfExtents=[0.015, 0.015, 1.5], rgbaColor=[1, 0, 0, 1])
    return bc.createMultiBody(0, -1, vs, [x, y, 1.5])


@pytest.mark.parametrize("body_yaw", [0.0, 100.0, 250.0])
@pytest.mark.parametrize("pan", [-40.0, 0.0, 35.0])
def test_marker_appears_at_pinhole_column(body_yaw, pan):
    spec = HeadCameraSpec()  # full 208x160 for pixel accuracy
    env = gym.make("vc_gym/AiboRoom-v0", camera=spec, scene="outdoor_field", locomotion="kinematic")
    env.reset(seed=0, options={"pose": (0.0, 0.0, body_yaw)})
    u = env.unwrapped
    # turn the head to the pan (bounded head speed: a few steps)
    for _ in range(10):
        u.step(np.array([0, 0, 0, pan / 90.0, 0], np.float32))
    eye, cam_yaw, pitch = u.robot.eye()
    assert abs(vc_gym.wrap180(cam_yaw - u.robot.pose[2] - pan)) < 0.5
    before = u.head_image()
    bearing = cam_yaw + 12.0  # 12 deg left of the optical axis, 1.8 m away
    mx = eye[0] + 1.8 * math.cos(math.radians(bearing))
    my = eye[1] + 1.8 * math.sin(math.radians(bearing))
    _add_marker(u.client, mx, my)
    img = u.head_image()
    red = np.abs(img.astype(int) - before.astype(int)).sum(axis=2) > 30  # where the marker is
    f = (spec.width / 2) / math.tan(math.radians(spec.hfov_deg / 2))
    row = int(round((spec.height - 1) / 2 + f * math.tan(math.radians(pitch))))  # horizon
    cols = np.flatnonzero(red[row])
    assert cols.size > 0, "marker not visible"
    true_bearing = math.degrees(math.atan2(my - eye[1], mx - eye[0]))
    offset = (true_bearing - cam_yaw + 180) % 360 - 180
    predicted = (spec.width - 1) / 2 - f * math.tan(math.radians(offset)) / math.cos(
        math.radians(pitch)
    )
    assert abs(cols.mean() - predicted) <= 2.0, (cols.mean(), predicted)
    env.close()


def test_odometry_drift_matches_configured_noise():
    from vc_gym.sim.odometry import OdometryNoise

    noise = OdometryNoise(trans_scale=0.1, rot_scale=0.0, trans_std=0.0, rot_std=0.0)
    env = make("vc_gym/AiboRoom-v0", locomotion="kinematic", odometry_noise=noise)
    ratios = []
    for seed in range(40):
        env.reset(seed=seed, options={"pose": (-1.0, 0.0, 0.0)})
        odo = 0.0
        for _ in range(5):
            obs, *_ = env.step(np.array([0.4, 0, 0, 0, 0], np.float32))
            odo += float(obs["odometry"][0])
        true = env.unwrapped.robot.pose[0] + 1.0
        ratios.append(odo / true)
    env.close()
    assert np.std(ratios) == pytest.approx(0.1, rel=0.35)
    assert np.mean(ratios) == pytest.approx(1.0, abs=0.05)


def test_an_episode_does_not_depend_on_the_episodes_before_it():
    """reset(seed=s) gives the same episode in a fresh env and after other episodes
    (the first reset builds the scene; physics keeps contact caches between resets)."""
    actions = [np.array([0.6, 0.1, 0.3, 0.2, 0.0], np.float32)] * 15

    def episode(env):
        obs, info = env.reset(seed=5)
        poses = [info["pose"]]
        for a in actions:
            obs, _, _, _, info = env.step(a)
            poses.append(info["pose"])
        return np.array(poses), obs["image"]

    fresh = make("vc_gym/AiboRoom-v0")
    first = episode(fresh)
    again = episode(fresh)  # no rebuild this time
    fresh.close()
    used = make("vc_gym/AiboRoom-v0")
    used.reset(seed=1)
    for _ in range(20):
        used.step(np.array([1.0, 0.0, -0.5, 0.0, 0.0], np.float32))
    after = episode(used)
    used.close()
    for other in (again, after):
        np.testing.assert_array_equal(first[0], other[0])
        np.testing.assert_array_equal(first[1], other[1])


def test_a_lost_physics_server_is_a_clear_error_and_reset_rebuilds_the_world():
    env = make("vc_gym/AiboRoom-v0")
    first, _ = env.reset(seed=3)
    env.unwrapped.client.disconnect()  # as if the server had died
    with pytest.raises(RuntimeError, match="physics server is gone"):
        env.step(np.zeros(5, np.float32))
    again, _ = env.reset(seed=3)  # the same env starts a new server: no need to make it anew
    np.testing.assert_array_equal(first["image"], again["image"])
    env.step(np.zeros(5, np.float32))
    env.close()


@pytest.mark.parametrize(
    ("platform", "env", "expected"),
    [
        ("linux", {}, False),
        ("linux", {"DISPLAY": ":0"}, True),
        ("linux", {"WAYLAND_DISPLAY": "wayland-0"}, True),
        ("darwin", {}, True),
    ],
)
def test_a_display_is_found_where_there_is_one(monkeypatch, platform, env, expected):
    from vc_gym.sim import aibo_room

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    for key, value in env.items():
        monkeypatch.setenv(key, value)
    monkeypatch.setattr(aibo_room.sys, "platform", platform)
    assert aibo_room.display_available() is expected


def test_human_is_listed_only_where_a_window_can_open():
    from vc_gym.sim.aibo_room import AiboRoomEnv, display_available

    assert ("human" in AiboRoomEnv.metadata["render_modes"]) == display_available()
