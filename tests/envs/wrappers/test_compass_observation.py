"""CompassObservation: compass, atlas and filters inside the env; never the true pose."""

from __future__ import annotations

import math
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from vc_gym.angles import wrap180
from vc_gym.compass import Camera
from vc_gym.envs.wrappers.compass_observation import CompassObservation
from vc_gym.worlds.room import render_room_view


class RayCastRobot(gym.Env):
    """A robot in the ray-cast room: turns and walks by its actions, sees the room.

    ``leak`` decides what ``info["pose"]`` holds: the truth, or garbage. A wrapper that
    never looks at the true pose gives the same observations either way.
    """

    metadata = {"render_modes": []}

    def __init__(self, room, start=(0.6, -0.4, 30.0), leak="truth"):
        self.room, self.start, self.leak = room, start, leak
        self.control_dt = 0.1
        self.camera = SimpleNamespace(hfov_deg=Camera().hfov_deg)
        self.observation_space = spaces.Dict(
            {
                "image": spaces.Box(0, 255, (160, 208, 3), np.uint8),
                "head": spaces.Box(-90.0, 90.0, (2,), np.float32),
                "odometry": spaces.Box(-720.0, 720.0, (3,), np.float32),
            }
        )
        self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)  # forward m, turn /45 deg

    def _obs(self, odo):
        x, y, yaw = self.pose
        img = render_room_view(self.room, x, y, Camera(yaw_deg=yaw))
        return {
            "image": img,
            "head": np.zeros(2, np.float32),
            "odometry": np.asarray(odo, np.float32),
        }

    def _info(self):
        if self.leak == "truth":
            return {"pose": np.array(self.pose)}
        return {"pose": self.np_random.uniform(-9, 9, 3)}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pose = list(self.start)
        return self._obs((0.0, 0.0, 0.0)), self._info()

    def step(self, action):
        fwd, turn = 0.1 * float(action[0]), 45.0 * float(action[1])
        x, y, yaw = self.pose
        th = math.radians(yaw)
        self.pose = [x + fwd * math.cos(th), y + fwd * math.sin(th), (yaw + turn) % 360.0]
        return self._obs((fwd, 0.0, turn)), 0.0, False, False, self._info()


ACTIONS = [(0.0, 0.0)] * 6 + [(0.0, 0.5)] * 4 + [(1.0, 0.0)] * 4 + [(0.0, -0.3)] * 4


def run(env, actions=ACTIONS):
    obs, _ = env.reset(seed=0)
    out = [obs]
    for a in actions:
        obs, *_ = env.step(np.array(a, np.float32))
        out.append(obs)
    return out


def test_observation_never_depends_on_the_true_pose(synthetic_room, room_atlas):
    honest = run(CompassObservation(RayCastRobot(synthetic_room, leak="truth"), room_atlas))
    liar = run(CompassObservation(RayCastRobot(synthetic_room, leak="garbage"), room_atlas))
    for a, b in zip(honest, liar, strict=True):
        assert a.keys() == b.keys()
        for k in a:
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    assert "pose" not in honest[0]


def test_estimates_track_the_robot(synthetic_room, room_atlas):
    env = RayCastRobot(synthetic_room)
    w = CompassObservation(env, room_atlas, belief_bins=36)
    obs_seq = run(w)
    obs = obs_seq[-1]
    true_x, true_y, true_yaw = env.pose
    heading = math.degrees(math.atan2(obs["heading"][1], obs["heading"][0]))
    assert abs(wrap180(heading - true_yaw)) < 10.0
    assert obs["heading_spread"][0] < 30.0
    # the atlas position is coarse (paper: ~0.3 m); it lies towards the robot, not at home
    pos = obs["position"]
    assert np.hypot(pos[0] - true_x, pos[1] - true_y) < np.hypot(true_x, true_y)
    # home_vector is home in the robot's estimated frame
    th = math.atan2(obs["heading"][1], obs["heading"][0])
    hx, hy = -pos[0], -pos[1]
    expect = (hx * math.cos(th) + hy * math.sin(th), -hx * math.sin(th) + hy * math.cos(th))
    np.testing.assert_allclose(obs["home_vector"], expect, atol=1e-4)
    assert obs["goodness"].shape == (4,) and np.all(obs["goodness"] > 0)
    assert obs["belief"].shape == (36,) and obs["belief"].sum() == pytest.approx(1.0, abs=1e-5)
    assert abs(wrap180(10.0 * int(np.argmax(obs["belief"])) + 5.0 - true_yaw)) <= 15.0
    assert w.observation_space.contains(obs)


def test_keep_image_and_padding(synthetic_room, room_atlas):
    w = CompassObservation(RayCastRobot(synthetic_room), room_atlas, n_spots=6, keep_image=False)
    obs, _ = w.reset(seed=0)
    assert "image" not in obs and "image" not in w.observation_space.spaces
    assert obs["goodness"].shape == (6,) and np.all(obs["goodness"][4:] == 0)
    assert w.observation_space.contains(obs)


def test_bad_arguments(synthetic_room, room_atlas):
    env = RayCastRobot(synthetic_room)
    with pytest.raises(ValueError, match="pass an atlas"):
        CompassObservation(env)
    with pytest.raises(ValueError, match="CompassAtlas"):
        CompassObservation(env, atlas="atlas.npz")
    with pytest.raises(ValueError, match="belief_bins"):
        CompassObservation(env, room_atlas, belief_bins=7)
    with pytest.raises(ValueError, match="unknown tracker"):
        CompassObservation(env, room_atlas, tracker="kalmann")
    with pytest.raises(ValueError, match="4 spots"):
        CompassObservation(env, room_atlas, n_spots=2).reset(seed=0)
    plain = gym.make("CartPole-v1")
    with pytest.raises(ValueError, match="image"):
        CompassObservation(plain, room_atlas)


@pytest.mark.parametrize("tracker", ["grid", "particle", "kalman", {"type": "particle", "seed": 4}])
def test_every_tracker_plugs_in(synthetic_room, room_atlas, tracker):
    w = CompassObservation(RayCastRobot(synthetic_room), room_atlas, belief_bins=8, tracker=tracker)
    obs, info = w.reset(seed=0)
    for a in ACTIONS[:6]:
        obs, _, _, _, info = w.step(np.array(a, np.float32))
    assert w.observation_space.contains(obs)
    est = info["estimate"]
    np.testing.assert_allclose(obs["position"], est["position"], atol=1e-5)
    np.testing.assert_allclose(obs["position_std"], est["position_std_m"], atol=1e-5)
    th = math.radians(est["heading_deg"])
    np.testing.assert_allclose(obs["heading"], (math.cos(th), math.sin(th)), atol=1e-6)
    assert w.tracker_updates == 7 and w.tracker_time_s > 0


class DeadReckoning:
    """A tracker written by a user (outside the package): odometry only, from home."""

    def __init__(self):
        self.resets = 0

    def reset(self, atlas, camera, dt_s):
        self.resets += 1
        self.n = len(atlas)
        self.pose = (*atlas.home_position, 0.0)

    def update(self, image, head_pan_deg, odometry):
        from vc_gym.localization import TrackerState
        from vc_gym.poses import compose

        self.pose = compose(self.pose, tuple(float(v) for v in odometry))
        belief = np.zeros(360)
        belief[int(self.pose[2]) % 360] = 1.0
        return TrackerState(
            heading_deg=self.pose[2],
            heading_spread_deg=1.0,
            position=self.pose[:2],
            position_std_m=(0.5, 0.5),
            goodness=np.ones(self.n),
            belief=belief,
            atlas_position=self.pose[:2],
        )


def test_a_tracker_from_outside_the_package_runs_a_whole_episode():
    from vc_gym.agents.scripted import ScriptedHomingPolicy
    from vc_gym.sim.head_camera import HeadCameraSpec

    task = gym.make(
        "vc_gym/LearnThenHome-v0",
        learn_time_s=0.2,
        max_homing_s=4.0,
        camera=HeadCameraSpec(52, 40, 56.9),
        learning_seed=0,
    )
    w = CompassObservation(task, keep_image=False, tracker=DeadReckoning)
    policy = ScriptedHomingPolicy.for_env(w, settle_time_s=0.0)
    obs, info = w.reset(seed=2, options={"pose": (1.0, 0.5, 90.0)})
    assert isinstance(w.tracker, DeadReckoning) and w.tracker.resets == 1
    steps = 0
    while steps < 100:
        steps += 1
        obs, _, terminated, truncated, info = w.step(policy.predict(obs))
        assert info["estimate"]["position"] == list(w.tracker.pose[:2])
        if terminated or truncated:
            break
    assert truncated and steps == 40  # 4 s of homing at 10 Hz
    # it believed it started at home facing east: the home vector points back there
    x, y, th = w.tracker.pose
    assert obs["home_vector"] == pytest.approx(
        (
            -x * math.cos(math.radians(th)) - y * math.sin(math.radians(th)),
            x * math.sin(math.radians(th)) - y * math.cos(math.radians(th)),
        ),
        abs=1e-5,
    )
    w.reset(seed=3)
    assert w.tracker.resets == 2
    w.close()
