"""A pool of places as one env: the place drawn at reset, steps go to it, seeded resets repeat."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.utils.env_checker import check_env

from vc_gym.envs import PlacePool


class _Place(gym.Env):
    """A place that says which it is: its observation is its number, and the step count."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, number: int, n_obs: int = 2):
        self.number = number
        self.observation_space = spaces.Box(-1e3, 1e3, (n_obs,), np.float32)
        self.action_space = spaces.Discrete(2)
        self.render_mode = "rgb_array"
        self.steps = 0
        self.closed = False
        self.last_seed = None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.last_seed, self.steps = seed, 0
        return self._obs(), {"from": self.number}

    def step(self, action):
        self.steps += 1
        return self._obs(), 1.0, self.steps >= 3, False, {"from": self.number}

    def render(self):
        return np.full((4, 4, 3), self.number, np.uint8)

    def close(self):
        self.closed = True

    def _obs(self):
        obs = np.zeros(self.observation_space.shape, np.float32)
        obs[0], obs[-1] = self.number, self.steps
        return obs


def test_each_episode_runs_in_the_place_drawn_at_reset():
    pool = PlacePool([_Place(k) for k in range(3)])
    seen = set()
    for seed in range(30):
        obs, info = pool.reset(seed=seed)
        k = info["place"]
        seen.add(k)
        assert obs[0] == k == pool.place and info["from"] == k
        obs, _, terminated, _, info = pool.step(0)
        assert obs[0] == k and info == {"from": k, "place": k} and not terminated
        assert pool.envs[k].steps == 1
        assert pool.render()[0, 0, 0] == k
    assert seen == {0, 1, 2}


def test_a_seeded_reset_gives_the_same_place_and_episode_seed():
    a = PlacePool([_Place(k) for k in range(4)])
    b = PlacePool([_Place(k) for k in range(4)])
    for seed in (0, 1, 7, 123):
        _, ia = a.reset(seed=seed)
        _, ib = b.reset(seed=seed)
        assert ia["place"] == ib["place"]
        assert a.envs[a.place].last_seed == b.envs[b.place].last_seed
    # unseeded resets continue the pool's own stream
    places = [a.reset()[1]["place"] for _ in range(20)]
    assert len(set(places)) > 1


def test_a_pool_passes_the_env_checker():
    check_env(PlacePool([_Place(0), _Place(1)]))


def test_bad_pools_are_refused():
    with pytest.raises(ValueError, match="at least one"):
        PlacePool([])
    with pytest.raises(ValueError, match="envs\\[1\\]"):
        PlacePool([_Place(0), "not an env"])
    with pytest.raises(ValueError, match="same observation_space"):
        PlacePool([_Place(0), _Place(1, n_obs=3)])


def test_step_before_reset_and_a_closed_pool():
    places = [_Place(0), _Place(1)]
    pool = PlacePool(places)
    with pytest.raises(RuntimeError, match="reset"):
        pool.step(0)
    pool.close()
    pool.close()  # twice is fine
    assert all(p.closed for p in places)
    with pytest.raises(RuntimeError, match="closed"):
        pool.reset(seed=0)
    with pytest.raises(RuntimeError, match="closed"):
        pool.step(0)
