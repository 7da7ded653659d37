"""Learned agents: loading what training wrote, and the shipped policy."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.agents.learned import LearnedHomingAgent
from vc_gym.cli import main


def test_bad_model_files_are_clear_errors(tmp_path, capsys):
    with pytest.raises(ValueError, match="model"):
        LearnedHomingAgent(tmp_path / "missing.zip")
    (tmp_path / "model.zip").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="config.json"):
        LearnedHomingAgent(tmp_path / "model.zip")
    (tmp_path / "config.json").write_text(json.dumps({"schema": 2, "algo": "ppo", "env": {}}))
    with pytest.raises(ValueError, match="cannot load"):
        LearnedHomingAgent(tmp_path / "model.zip")
    assert main(["evaluate", "--agent", str(tmp_path / "model.zip"), "--episodes", "1"]) == 2
    assert "cannot load" in capsys.readouterr().err
    assert main(["evaluate", "--agent", "nowhere/model.zip", "--episodes", "1"]) == 2


def test_shipped_policy_loads_and_walks_towards_home_ahead():
    from vc_gym.agents.learned import PRETRAINED_MODEL

    agent = LearnedHomingAgent(PRETRAINED_MODEL)
    assert agent.algo == "ppo" and agent.scene == "robolab"
    # home 1.5 m straight ahead, heading known (spread 9 deg), goodness as at home
    features = np.array([0.75, 0.0, 1.0, 0.0, 0.05, -0.75, 0.0, 0, 0, 0, 0, 0.0], np.float32)
    if agent.env_kwargs.get("previous_action"):  # and no action yet, as after a reset
        features = np.concatenate([features, np.zeros(3, np.float32)])
    forward, _, stop = agent.predict(features)
    assert forward > 0.5 and stop <= 0.5


@pytest.mark.parametrize(
    ("config", "match"),
    [
        ("{not json", "JSON"),
        ('{"schema": 3, "algo": "ppo"}', "schema"),
        ('{"schema": 2, "algo": "dqn", "env": {}}', "algo"),
        ('{"schema": 2, "algo": "ppo", "env": [1, 2]}', "env"),
    ],
)
def test_bad_configs_are_clear_errors(tmp_path, config, match):
    (tmp_path / "model.zip").write_bytes(b"PK")
    (tmp_path / "config.json").write_text(config)
    with pytest.raises(ValueError, match=match):
        LearnedHomingAgent(tmp_path / "model.zip")


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"extra_kw": 3}, "unexpected keyword argument 'extra_kw'"),
        ({"scene": "nowhere"}, "unknown scene 'nowhere'"),
        ({"max_forward": -1}, "max_forward"),
    ],
)
def test_env_arguments_the_env_refuses_name_the_config_file(tmp_path, capsys, change, match):
    import shutil

    from vc_gym.agents.learned import PRETRAINED_MODEL

    shutil.copytree(PRETRAINED_MODEL.parent, tmp_path / "agent")
    cfg = tmp_path / "agent" / "config.json"
    data = json.loads(cfg.read_text())
    data["env"].update(change)
    cfg.write_text(json.dumps(data))
    agent = LearnedHomingAgent(tmp_path / "agent" / "model.zip")
    with pytest.raises(ValueError, match=f"{cfg}: its env arguments .*{match}"):
        agent.check_env()
    # the command refuses it before any work, and leaves no output folder behind
    out = tmp_path / "run"
    argv = ["evaluate", "--agent", str(tmp_path / "agent" / "model.zip"), "--out", str(out)]
    assert main(argv) == 2
    assert str(cfg) in capsys.readouterr().err and not out.exists()


def test_shipped_policy_was_trained_with_the_default_settings():
    # README: the shipped policy is seed 2 of `vc-gym train --seeds 0,1,2 --workers 1`;
    # a change of TrainConfig's defaults must re-ship it (or say why not)
    from dataclasses import replace

    from vc_gym.agents.learned import PRETRAINED_MODEL
    from vc_gym.experiments.training import TrainConfig, read_train_config

    shipped = read_train_config(PRETRAINED_MODEL.parent / "config.json")
    # the run measured its goal (centred); everything it was given is the defaults
    assert shipped.home_offset_m is not None and max(map(abs, shipped.home_offset_m)) < 0.3
    assert replace(shipped, home_offset_m=None) == TrainConfig(seed=2)
