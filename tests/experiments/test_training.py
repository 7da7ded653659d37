"""Training learned agents: tiny-budget training in worker processes, reload, evaluation."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.agents.learned import LearnedHomingAgent
from vc_gym.cli import main
from vc_gym.experiments.runner import LocalBackend
from vc_gym.experiments.studies import ExperimentOptions
from vc_gym.experiments.studies.homing import run_homing
from vc_gym.experiments.training import TrainConfig, train

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
    saved = json.loads((out / "config.json").read_text())
    assert TrainConfig.from_dict(saved) == TINY
    assert saved["env"] == TINY.env_kwargs() and saved["env"]["tracker"] == "grid"
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
    r = run_homing(
        tmp_path / "homing",
        ExperimentOptions(seed=1, backend=LocalBackend(1), progress=False),
        agent=str(out / "model.zip"),
        episodes=2,
        learn_time_s=0.2,
        max_homing_s=5.0,
        field=False,
    )
    assert len(r["per_episode"]) == 2 and r["settings"]["agent"] == out.name
    for ep in r["per_episode"]:
        assert ep["stopped"] or ep["timed_out"] or ep["fell"]
        assert ep["sim_time_s"] <= 5.0 + 1e-6
    assert (tmp_path / "homing" / "stop_positions.png").read_bytes()[:4] == b"\x89PNG"
    code = main(
        [
            "evaluate",
            "--out",
            str(tmp_path / "evaluate"),
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
    assert result["overall"]["episodes"] == 1 and "per_episode" not in result


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
    with pytest.raises(ValueError, match="does not match"):
        TrainConfig.from_dict({**TINY.to_dict(), "env": {"scene": "office"}})
    schema1 = {k: v for k, v in TINY.to_dict().items() if k not in ("env", "tracker")}
    assert TrainConfig.from_dict({**schema1, "schema": 1}) == TINY
