"""Behaviour cloning: demonstrations with known returns, a clone that fits them."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.training.imitation import (
    Demonstrations,
    clone_behaviour,
    collect_demonstrations,
)


class CountdownVecEnv:
    """Two envs whose episodes last 3 and 2 steps, reward 1 per step."""

    num_envs = 2
    lengths = (3, 2)

    def reset(self):
        self.t = [0, 0]
        return np.zeros((2, 4), np.float32)

    def step(self, actions):
        assert actions.shape == (2, 3)
        dones, infos = np.zeros(2, bool), [{}, {}]
        for i in range(2):
            self.t[i] += 1
            if self.t[i] == self.lengths[i]:
                dones[i], self.t[i] = True, 0
                infos[i] = {"stop_error_m": 0.1 * (i + 1), "success": i == 0}
        obs = np.array([[t, 0, 0, 0] for t in self.t], np.float32)
        return obs, np.ones(2, np.float32), dones, infos


class ConstantExpert:
    def predict(self, obs):
        return np.tile(np.array([0.5, -0.5, -1.0], np.float32), (len(obs), 1))


def test_demonstrations_hold_finished_episodes_with_discounted_returns():
    demos = collect_demonstrations(CountdownVecEnv(), ConstantExpert(), episodes=3, gamma=0.5)
    assert len(demos.episodes) == 3
    # env 1 ends after 2 steps (twice by step 4), env 0 after 3: 2 + 3 + 2 decisions
    assert [e["decisions"] for e in demos.episodes] == [2, 3, 2]
    np.testing.assert_allclose(demos.returns, [1.5, 1.0, 1.75, 1.5, 1.0, 1.5, 1.0])
    assert demos.actions.shape == (7, 3) and demos.observations.shape == (7, 4)
    assert demos.success_rate == pytest.approx(1 / 3)


@pytest.mark.parametrize("kwargs", [{"episodes": 0}, {"episodes": 2.5}, {"gamma": 0.0}])
def test_bad_collection_settings(kwargs):
    args = {"episodes": 1, "gamma": 0.9, **kwargs}
    with pytest.raises(ValueError):
        collect_demonstrations(CountdownVecEnv(), ConstantExpert(), **args)


def test_the_clone_fits_actions_and_returns_and_explores_narrowly():
    ppo = pytest.importorskip("stable_baselines3").PPO
    import gymnasium as gym
    from gymnasium import spaces

    class Box3(gym.Env):
        observation_space = spaces.Box(-1, 1, (4,), np.float32)
        action_space = spaces.Box(-1, 1, (3,), np.float32)

    model = ppo("MlpPolicy", Box3(), n_steps=16, batch_size=16, seed=0, device="cpu")
    rng = np.random.default_rng(0)
    obs = rng.uniform(-1, 1, (2000, 4)).astype(np.float32)
    actions = np.stack([0.8 * obs[:, 0], -0.5 * obs[:, 1], np.where(obs[:, 2] > 0, 1.0, -1.0)], 1)
    demos = Demonstrations(obs, actions.astype(np.float32), 3.0 * obs[:, 3], [])
    fit = clone_behaviour(model.policy, demos, updates=400, log_std=-1.5)
    assert fit["action_mse"] < 0.05 and fit["value_mse"] < 0.1 and fit["stop_accuracy"] > 0.9
    predicted, _ = model.predict(obs[:200], deterministic=True)
    assert np.mean((predicted[:, 2] > 0.5) == (obs[:200, 2] > 0)) > 0.9
    np.testing.assert_allclose(model.policy.log_std.detach().numpy(), -1.5)
    with pytest.raises(ValueError, match="no demonstrations"):
        clone_behaviour(model.policy, Demonstrations(obs[:0], actions[:0], obs[:0, 0], []))
