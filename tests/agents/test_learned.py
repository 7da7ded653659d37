"""Learned agents: tiny-budget training in worker processes, reload, evaluation."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.agents.learned import (
    LearnedHomingAgent,
    StopAction,
    TrainConfig,
    make_homing_env,
    train,
)
from vc_gym.cli import main
from vc_gym.experiments.evaluate import evaluate_agent

TINY = TrainConfig(
    timesteps=64, n_envs=2, learn_time_s=0.2, n_steps=32, batch_size=32, max_homing_s=3.0
)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    out = tmp_path_factory.mktemp("agent")
    summary = train(TINY, out, progress=False)  # SubprocVecEnv, 2 worker processes
    return out, summary


def test_train_writes_model_config_and_log(trained):
    out, summary = trained
    assert (out / "model.zip").is_file()
    assert TrainConfig.from_dict(json.loads((out / "config.json").read_text())) == TINY
    log = json.loads((out / "train_log.json").read_text())
    assert log["episodes"] == len(log["per_episode"]) == summary["episodes"] > 0
    assert (out / "learning_curve.png").read_bytes()[:4] == b"\x89PNG"


def test_reloaded_model_gives_the_same_actions(trained):
    out, _ = trained
    agent = LearnedHomingAgent(out / "model.zip")
    again = LearnedHomingAgent(out / "model.zip")
    env = agent.make_env()
    rng = np.random.default_rng(0)
    obs = rng.uniform(-2, 2, (20, *env.observation_space.shape)).astype(np.float32)
    a = np.stack([agent.predict(o) for o in obs])
    b = np.stack([again.predict(o) for o in obs])
    np.testing.assert_array_equal(a, b)
    assert a.shape == (20, 3) and np.all(np.abs(a) <= 1.0)
    assert len({tuple(x) for x in a.round(5)}) > 1  # depends on the observation
    env.close()


def test_evaluate_a_learned_agent_end_to_end(trained, tmp_path, capsys):
    out, _ = trained
    r = evaluate_agent(
        agent=str(out / "model.zip"),
        episodes=2,
        seed=1,
        learn_time_s=0.2,
        max_homing_s=5.0,
        workers=1,
        out_dir=tmp_path,
        progress=False,
    )
    assert len(r["per_episode"]) == 2 and r["agent"].endswith("model.zip")
    for ep in r["per_episode"]:
        assert ep["stopped"] or ep["timed_out"] or ep["fell"]
        assert ep["sim_time_s"] <= 5.0 + 1e-6
    assert (tmp_path / "stop_positions.png").read_bytes()[:4] == b"\x89PNG"
    code = main(
        [
            "evaluate",
            "--agent",
            str(out / "model.zip"),
            "--episodes",
            "1",
            "--workers",
            "1",
            "--learn-time",
            "0.2",
            "--max-homing",
            "5",
            "--json",
        ]
    )
    assert code == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert result["episodes"] == 1 and "per_episode" not in result


def test_stop_action_holds_still_until_the_task_stops():
    env = make_homing_env(TINY, learn_time_s=0.2, stop_time_s=1.0)
    assert isinstance(env, StopAction) and env.action_space.shape == (3,)
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    stop = np.array([0.0, 0.0, 1.0], np.float32)
    turn_and_stop = np.array([0.0, 1.0, 1.0], np.float32)
    for _ in range(env.min_walk_steps):  # stop requests while the filters settle: ignored
        _, r, terminated, _, info = env.step(turn_and_stop)
        assert not terminated and info["still_time_s"] == 0.0
    env.reset(seed=0, options={"pose": (0.1, 0.0, 0.0)})
    env.min_walk_steps = 0
    obs, r, terminated, truncated, info = env.step(stop)
    assert terminated and info["stopped"] and info["success"]
    assert r == pytest.approx(10.0, abs=1e-3)  # the success bonus, summed over the hold
    assert info["still_time_s"] == pytest.approx(1.0)
    env.reset(seed=0, options={"pose": (1.0, 0.0, 180.0)})
    _, r, terminated, _, info = env.step(np.array([1.0, 0.0, -1.0], np.float32))
    assert not terminated and r > 0.2  # walked towards home (0.4 m/s for 0.1 s, from rest)
    assert r == pytest.approx(10.0 * (1.0 - info["home_error_m"]), abs=1e-6)
    with pytest.raises(ValueError):
        env.step(np.array([np.nan, 0.0, 0.0]))
    env.close()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"algo": "dqn"},
        {"timesteps": 0},
        {"n_envs": 1.5},
        {"gamma": 1.5},
        {"net_arch": (0,)},
        {"vec_env": "ray"},
        {"learning_rate": float("nan")},
    ],
)
def test_bad_train_config(kwargs):
    with pytest.raises(ValueError):
        TrainConfig(**kwargs)


def test_config_file_round_trip_and_errors(tmp_path):
    assert TrainConfig.from_dict(TINY.to_dict()) == TINY
    with pytest.raises(ValueError, match="unknown"):
        TrainConfig.from_dict({**TINY.to_dict(), "reward": 3})
    with pytest.raises(ValueError, match="schema"):
        TrainConfig.from_dict({**TINY.to_dict(), "schema": 99})


def test_bad_model_files_are_clear_errors(tmp_path, capsys):
    with pytest.raises(ValueError, match="model"):
        LearnedHomingAgent(tmp_path / "missing.zip")
    (tmp_path / "model.zip").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="config.json"):
        LearnedHomingAgent(tmp_path / "model.zip")
    (tmp_path / "config.json").write_text(json.dumps(TINY.to_dict()))
    with pytest.raises(ValueError, match="cannot load"):
        LearnedHomingAgent(tmp_path / "model.zip")
    assert main(["evaluate", "--agent", str(tmp_path / "model.zip"), "--episodes", "1"]) == 2
    assert "cannot load" in capsys.readouterr().err
    assert main(["evaluate", "--agent", "nowhere/model.zip", "--episodes", "1"]) == 2


def test_shipped_policy_loads_and_walks_towards_home_ahead():
    from vc_gym.agents.learned import PRETRAINED_MODEL

    agent = LearnedHomingAgent(PRETRAINED_MODEL)
    assert agent.config.algo == "ppo" and agent.config.scene == "robolab"
    # home 1.5 m straight ahead, heading known (spread 9 deg), goodness as at home
    features = np.array([0.75, 0.0, 1.0, 0.0, 0.05, -0.75, 0.0, 0, 0, 0, 0, 0.0], np.float32)
    forward, _, stop = agent.predict(features)
    assert forward > 0.5 and stop <= 0.5
