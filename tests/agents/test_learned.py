"""Learned agents: loading what training wrote, and the shipped policy."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.agents.learned import LearnedHomingAgent
from vc_gym.cli import main
from vc_gym.experiments.episode import check_agent_env


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
    from vc_gym.envs.homing import HomingFeatures, PreviousAction

    agent = LearnedHomingAgent(PRETRAINED_MODEL)
    assert agent.algo == "ppo" and agent.scene == "robolab"
    n = agent.model.observation_space.shape[0]
    position_std = bool(agent.env_kwargs.get("position_std"))
    previous = PreviousAction.WIDTH if agent.env_kwargs.get("previous_action") else 0
    n_spots = n - 8 - previous - (HomingFeatures.POSITION_STD_WIDTH if position_std else 0)
    # home 1.5 m straight ahead, heading known (spread 9 deg), every spot's goodness 1, the
    # head straight, no action yet (as after a reset)
    features = np.zeros(n, np.float32)
    features[HomingFeatures.HOME_VECTOR] = (0.75, 0.0)
    features[HomingFeatures.HEADING] = (1.0, 0.0)
    features[HomingFeatures.SPREAD] = 0.05
    features[HomingFeatures.POSITION] = (-0.75, 0.0)
    if position_std:  # the position known to 0.2 m
        spread = HomingFeatures.position_std_slice(n_spots)
        features[spread] = 0.2 / HomingFeatures.POSITION_STD_SCALE_M
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
        ({"max_forward": -1}, "max_forward"),
        ({"stop_time_s": "long"}, "stop_time_s"),
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
        check_agent_env(agent, str(agent.config_path))
    # the command refuses it before any work, and leaves no output folder behind
    out = tmp_path / "run"
    argv = ["evaluate", "--agent", str(tmp_path / "agent" / "model.zip"), "--out", str(out)]
    assert main(argv) == 2
    assert str(cfg) in capsys.readouterr().err and not out.exists()


def test_shipped_policy_was_trained_with_the_default_settings():
    # README: the shipped policy is `vc-gym train --seed 0`, byte for byte; a change of
    # TrainConfig's defaults must re-ship it (or say why not)
    from vc_gym.agents.learned import PRETRAINED_MODEL
    from vc_gym.training.config import TrainConfig, read_train_config
    from vc_gym.training.model_file import reproducible_model_bytes

    shipped = read_train_config(PRETRAINED_MODEL.parent / "config.json")
    assert shipped == TrainConfig(seed=0)
    # and its model.zip is in the form vc-gym train writes, which a rerun reproduces
    saved = PRETRAINED_MODEL.read_bytes()
    assert reproducible_model_bytes(saved) == saved


def _copied_agent(tmp_path, change):
    import shutil

    from vc_gym.agents.learned import PRETRAINED_MODEL

    shutil.copytree(PRETRAINED_MODEL.parent, tmp_path / "agent")
    cfg = tmp_path / "agent" / "config.json"
    data = json.loads(cfg.read_text())
    data["env"].update(change)
    cfg.write_text(json.dumps(data))
    return tmp_path / "agent" / "model.zip", cfg


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"tracker": {"type": "os:system", "command": "touch {marker}"}}, "import path"),
        ({"tracker": "os:abort"}, "import path"),
        ({"tracker": "this:x"}, "import path"),
        ({"tracker": {"type": "grid", "rule": {"deep": [[[[[[[[[[1]]]]]]]]]]}}}, "nested"),
        ({"tracker": 3}, "registered name"),
        ({"tracker": "nope"}, "unknown tracker 'nope'"),
        ({"scene": "nowhere"}, "env.scene.*unknown scene 'nowhere'"),
        ({"scene": "os:system"}, "env.scene"),
        ({"extra_kw": 3}, "extra_kw"),
        ({"learner": "os:system"}, "learner"),
        ({"atlas_file": "/etc/passwd"}, "atlas_file"),
    ],
)
def test_a_config_that_names_code_is_refused_before_anything_runs(tmp_path, change, match):
    marker = tmp_path / "ran"
    tracker = change.get("tracker")
    if isinstance(tracker, dict) and "command" in tracker:
        tracker["command"] = tracker["command"].format(marker=marker)
    model, cfg = _copied_agent(tmp_path, change)
    with pytest.raises(ValueError, match=match) as err:
        LearnedHomingAgent(model)
    assert str(cfg) in str(err.value)
    assert not marker.exists()


def test_the_command_refuses_a_config_that_names_code(tmp_path, capsys):
    marker = tmp_path / "ran"
    change = {"tracker": {"type": "os:system", "command": f"touch {marker}"}}
    model, cfg = _copied_agent(tmp_path, change)
    out = tmp_path / "run"
    assert main(["evaluate", "--agent", str(model), "--episodes", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(cfg) in err and "import path" in err
    assert not marker.exists() and not out.exists()


def test_an_import_path_is_read_when_the_user_allows_it(tmp_path):
    spec = "vc_gym.localization.grid_tracker:GridTracker"
    model, _ = _copied_agent(tmp_path, {"tracker": spec})
    with pytest.raises(ValueError, match="import path"):
        LearnedHomingAgent(model)
    agent = LearnedHomingAgent(model, allow_imports=True)
    assert agent.env_kwargs["tracker"] == spec


def test_a_huge_config_is_refused_unread(tmp_path):
    from vc_gym.config_files import MAX_SETTINGS_BYTES

    model, cfg = _copied_agent(tmp_path, {})
    data = json.loads(cfg.read_text())
    data["padding"] = "x" * (MAX_SETTINGS_BYTES + 1)
    cfg.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="more than a settings file may hold"):
        LearnedHomingAgent(model)


def test_the_command_line_can_allow_import_paths(tmp_path, monkeypatch, capsys):
    import functools

    import vc_gym.experiments.studies.homing as homing

    seen = {}

    @functools.wraps(homing.run_homing)  # the command checks its flags against this signature
    def fake_run_homing(out_dir, opts=None, **kwargs):
        seen.update(kwargs)
        LearnedHomingAgent(kwargs["agent"], kwargs.get("allow_imports", False))
        return {"overall": {}, "failed_jobs": []}

    monkeypatch.setattr(homing, "run_homing", fake_run_homing)
    model, _ = _copied_agent(tmp_path, {"tracker": "vc_gym.localization.grid_tracker:GridTracker"})
    argv = ["evaluate", "--agent", str(model), "--episodes", "1", "--out", str(tmp_path / "r")]
    assert main(argv) == 2
    assert "import path" in capsys.readouterr().err
    main([*argv, "--allow-imports"])
    assert seen["allow_imports"] is True
