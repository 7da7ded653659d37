"""A tiny env for the rollout tests (importable by worker processes)."""

from __future__ import annotations

import os
import time

import gymnasium as gym
import numpy as np
from gymnasium import spaces


class CountingEnv(gym.Env):
    """Observations that say who made them: ``[step / 10, env_id, episode / 10]``.

    Episodes last 5 steps: terminated if the first action component was positive at
    the last step, truncated otherwise (both ends occur). Every step sleeps
    ``delay_s``; with ``die_at`` the process exits at that step (a dead worker).
    """

    observation_space = spaces.Box(-10.0, 10.0, (3,), np.float32)
    action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)

    def __init__(self, env_id: int, delay_s: float = 0.0, die_at: int | None = None):
        self.env_id, self.delay_s, self.die_at = env_id, delay_s, die_at
        self.episode, self.t, self.total = -1, 0, 0

    def _obs(self) -> np.ndarray:
        return np.array([self.t / 10, self.env_id, self.episode / 10], np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.episode += 1
        self.t = 0
        return self._obs(), {}

    def step(self, action):
        self.total += 1
        if self.die_at is not None and self.total >= self.die_at:
            os._exit(3)
        time.sleep(self.delay_s)
        self.t += 1
        reward = -float(np.sum((np.asarray(action) - 0.5) ** 2))
        end = self.t >= 5
        terminated = end and float(action[0]) > 0
        return self._obs(), reward, terminated, end and not terminated, {}


def counting_env(env_id: int, delay_s: float = 0.0, die_at: int | None = None):
    """Factory of a :class:`CountingEnv` (what a ``SubprocVecEnv`` is given)."""
    return lambda: CountingEnv(env_id, delay_s, die_at)
