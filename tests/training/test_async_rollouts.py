"""Asynchronous PPO rollouts: PPO's buffer, independent of timing, dead workers, training."""

from __future__ import annotations

import copy
import json
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

import torch  # noqa: E402
from tiny_configs import TINY  # noqa: E402
from toy_envs import CountingEnv, counting_env  # noqa: E402

from vc_gym.agents.learned import LearnedHomingAgent  # noqa: E402
from vc_gym.training.async_rollouts import (  # noqa: E402
    AsyncRolloutPPO,
    AsyncSubprocVecEnv,
    WorkerDiedError,
    policy_action,
)
from vc_gym.training.config import TrainConfig  # noqa: E402
from vc_gym.training.train import train  # noqa: E402

N_STEPS = 12


def _model(delays, die_at=None, seed=3, cls=AsyncRolloutPPO):
    venv = AsyncSubprocVecEnv(
        [counting_env(i, d, die_at if i == 1 else None) for i, d in enumerate(delays)],
        start_method="forkserver",
    )
    model = cls(
        "MlpPolicy", venv, n_steps=N_STEPS, batch_size=12, n_epochs=2, seed=seed, device="cpu"
    )
    return model, venv


def _parameters(model) -> list[torch.Tensor]:
    return [p.detach().clone() for p in model.policy.parameters()]


def test_each_env_fills_its_own_consecutive_rows():
    model, venv = _model([0.0, 0.01])  # env 1 is slower: env 0 runs ahead
    try:
        model.learn(total_timesteps=2 * N_STEPS)  # one rollout
        rb = model.rollout_buffer
        # PPO's update has flattened the (step, env) observations env by env; the
        # episode starts keep their (step, env) layout
        assert rb.observations.shape == (2 * N_STEPS, 3)
        obs = rb.observations.reshape(2, N_STEPS, 3)
        starts = rb.episode_starts.T
        for i in range(2):
            assert np.all(obs[i, :, 1] == i)  # env i's rows hold env i only
            step = np.rint(obs[i, :, 0] * 10).astype(int)
            # each env's own steps in order: 0, 1, 2, 3, 4, 0, 1, ... across resets
            assert list(step) == [t % 5 for t in range(N_STEPS)]
            assert list(starts[i]) == [float(s == 0) for s in step]
            episode = np.rint(obs[i, :, 2] * 10).astype(int)
            assert list(episode) == [t // 5 for t in range(N_STEPS)]
        assert model.num_timesteps == 2 * N_STEPS
        assert np.all(np.isfinite(rb.returns)) and np.all(np.isfinite(rb.advantages))
    finally:
        venv.close()


@pytest.mark.parametrize("shared", [True, False])
def test_an_action_is_sb3s_distribution_and_value_to_the_bit(shared):
    model = AsyncRolloutPPO(
        "MlpPolicy",
        CountingEnv(0),
        n_steps=N_STEPS,
        batch_size=N_STEPS,
        seed=5,
        device="cpu",
        policy_kwargs={"share_features_extractor": shared, "log_std_init": -0.5},
    )
    with torch.no_grad():  # trained-looking weights, not the initial ones
        for p in model.policy.parameters():
            p.add_(0.3 * torch.randn_like(p))
    obs = np.random.default_rng(0).uniform(-3, 3, (20, 3)).astype(np.float32)
    gen = model._generators(1)[0]
    acted = [policy_action(model.policy, o, gen) for o in obs]
    model._env_generators = None  # the same noise again, for SB3's own path
    for o, (action, value, log_prob) in zip(obs, acted, strict=True):
        obs_t = torch.as_tensor(o[None])
        with torch.no_grad():
            dist = model.policy.get_distribution(obs_t)
            gen = model._generators(1)[0]
            noise = torch.randn(dist.distribution.loc.shape, generator=gen)
            expected = dist.distribution.loc + dist.distribution.scale * noise
            assert np.array_equal(action, expected[0].numpy())
            assert log_prob == float(dist.log_prob(expected)[0])
            assert value == float(model.policy.predict_values(obs_t)[0, 0])
    # and the noise differs between draws (the test could fail)
    assert not np.array_equal(acted[0][0], acted[1][0])


def test_a_rollout_is_the_same_as_the_parent_choosing_every_action():
    model, venv = _model([0.0, 0.0])
    try:
        policy = copy.deepcopy(model.policy)  # the policy the rollout is taken with
        gens = [copy.deepcopy(g) for g in model._generators(2)]
        model.learn(total_timesteps=2 * N_STEPS)  # one rollout, then PPO's update
        rb = model.rollout_buffer
    finally:
        venv.close()
    low, high = model.action_space.low, model.action_space.high
    truncations = 0
    for i in range(2):  # replay env i here, every action chosen in this process
        env = CountingEnv(i)
        obs, _ = env.reset()
        start, rows = 1.0, []
        for _ in range(N_STEPS):
            action, value, log_prob = policy_action(policy, obs, gens[i])
            obs, reward, terminated, truncated, _ = env.step(np.clip(action, low, high))
            if truncated:  # a cut episode is bootstrapped with the value of where it ended
                truncations += 1
                with torch.no_grad():
                    end = policy.predict_values(torch.as_tensor(obs[None]))
                reward += model.gamma * float(end[0, 0])
            rows.append((action, value, log_prob, reward, start))
            start = float(terminated or truncated)
            if start:
                obs, _ = env.reset()
        # after the update the (step, env) rows are flattened env by env; the rewards and
        # episode starts keep their layout
        got = slice(i * N_STEPS, (i + 1) * N_STEPS)
        action, value, log_prob, reward, start = map(np.array, zip(*rows, strict=True))
        assert np.array_equal(rb.actions[got], action)
        assert np.array_equal(rb.values[got].ravel(), value.astype(np.float32))
        assert np.array_equal(rb.log_probs[got].ravel(), log_prob.astype(np.float32))
        assert np.array_equal(rb.rewards[:, i], reward.astype(np.float32))
        assert np.array_equal(rb.episode_starts[:, i], start.astype(np.float32))
    assert truncations > 0  # the bootstrap was exercised


@pytest.mark.slow
def test_the_policy_does_not_depend_on_which_worker_is_slower():
    results = []
    for delays in ([0.0, 0.006], [0.006, 0.0]):
        model, venv = _model(delays)
        try:
            model.learn(total_timesteps=4 * N_STEPS)  # two rollouts, one update between
            results.append(_parameters(model))
        finally:
            venv.close()
    assert all(torch.equal(a, b) for a, b in zip(*results, strict=True))
    # and the seed matters (the test could fail)
    model, venv = _model([0.0, 0.0], seed=4)
    try:
        model.learn(total_timesteps=4 * N_STEPS)
        assert not all(
            torch.equal(a, b) for a, b in zip(results[0], _parameters(model), strict=True)
        )
    finally:
        venv.close()


def test_a_dead_worker_is_a_clear_error():
    model, venv = _model([0.0, 0.0], die_at=5)
    try:
        with pytest.raises(WorkerDiedError, match="worker 1"):
            model.learn(total_timesteps=4 * N_STEPS)
    finally:
        venv.close()


def test_a_dead_worker_is_a_clear_error_in_lockstep_too():
    from stable_baselines3 import PPO

    model, venv = _model([0.0, 0.0], die_at=5, cls=PPO)  # SB3's own collect_rollouts
    try:
        with pytest.raises(WorkerDiedError, match="ended while stepping"):
            model.learn(total_timesteps=4 * N_STEPS)
    finally:
        venv.close()  # skips the dead worker: no BrokenPipeError hides the error


def test_ppo_in_worker_processes_collects_asynchronously_by_default():
    assert TrainConfig().collector == "async"
    assert TrainConfig(vec_env="dummy").collector == "lockstep"  # vc-gym train --n-envs 1
    assert TrainConfig(algo="sac").collector == "lockstep"
    # a config.json without the choice was trained in lockstep
    saved = {k: v for k, v in TrainConfig().to_dict().items() if k != "collector"}
    assert TrainConfig.from_dict(saved).collector == "lockstep"
    # the shipped policy's config is one of those
    from vc_gym.agents.learned import PRETRAINED_MODEL
    from vc_gym.training.config import read_train_config

    shipped = read_train_config(PRETRAINED_MODEL.parent / "config.json")
    assert shipped.collector == json.loads(
        (PRETRAINED_MODEL.parent / "config.json").read_text()
    ).get("collector", "lockstep")


def test_the_collector_is_checked():
    with pytest.raises(ValueError, match="collector must be one of"):
        TrainConfig(collector="fast")
    with pytest.raises(ValueError, match="needs algo 'ppo' and vec_env 'subproc'"):
        TrainConfig(collector="async", algo="sac")
    with pytest.raises(ValueError, match="needs algo 'ppo' and vec_env 'subproc'"):
        TrainConfig(collector="async", vec_env="dummy")


def test_a_model_loads_only_into_a_subclass_of_its_algorithm(tmp_path):
    from stable_baselines3 import SAC

    from vc_gym.training.safe_load import load_sb3_model

    with pytest.raises(ValueError, match="cls must be a subclass of PPO"):
        load_sb3_model("ppo", tmp_path / "model.zip", cls=SAC)


@pytest.mark.slow
def test_vc_gym_train_with_the_lockstep_collector(tmp_path):
    # TINY trains asynchronously (the default, test_training); this is SB3's collector
    config = replace(TINY, eval_freq=0, save_freq=0, collector="lockstep")
    summary = train(config, tmp_path, progress=False)
    assert summary["decisions_per_s"] > 0 and summary["episodes"] > 0
    # an ordinary PPO model.zip: the safe loader reads it (nothing of the collector pickled)
    agent = LearnedHomingAgent(tmp_path / "model.zip")
    # and a training run's own class loads it too (what --resume does)
    from vc_gym.training.safe_load import load_sb3_model

    assert isinstance(
        load_sb3_model("ppo", tmp_path / "model.zip", cls=AsyncRolloutPPO), AsyncRolloutPPO
    )
    obs = np.zeros(gym.make(agent.env_id, **agent.env_kwargs).observation_space.shape, np.float32)
    assert agent.predict(obs).shape == (3,)
