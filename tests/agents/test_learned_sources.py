"""A learned agent's settings from wherever its model was trained: vc-gym train's
config.json, an RL Zoo run folder, the model alone plus flags."""

from __future__ import annotations

import json
from collections import OrderedDict

import gymnasium as gym
import pytest
import yaml

from vc_gym.agents.learned import (
    LearnedHomingAgent,
    homing_spaces,
    parse_env_kwargs,
)
from vc_gym.cli import main
from vc_gym.training.zoo_run import read_zoo_file


class _SpacesOnly(gym.Env):
    """An env that only has ``vc_gym/Homing-v0``'s spaces, to build a policy for them."""

    def __init__(self, env_kwargs):
        self.observation_space, self.action_space = homing_spaces(env_kwargs)


def _save_policy(path, env_kwargs):
    """A fresh PPO policy of ``vc_gym/Homing-v0`` with ``env_kwargs``, saved to ``path``
    as stable-baselines3 saves one (no config.json beside it)."""
    from stable_baselines3 import PPO

    path.parent.mkdir(parents=True, exist_ok=True)
    PPO("MlpPolicy", _SpacesOnly(env_kwargs), n_steps=64, batch_size=32, seed=0).save(path)
    return path


@pytest.fixture
def bare_model(tmp_path):
    """A PPO policy saved alone (no config.json): 15 features, previous action."""
    return _save_policy(tmp_path / "bare" / "homing_ppo.zip", {"previous_action": True})


def _zoo_run(tmp_path, env_kwargs, args=None, config=None):
    """A model in an RL Zoo run folder, with the files the Zoo writes (OrderedDict dumps)."""
    run = tmp_path / "logs" / "ppo" / "vc_gym-Homing-v0_1"
    params = run / "vc_gym-Homing-v0"
    params.mkdir(parents=True)
    _save_policy(run / "vc_gym-Homing-v0.zip", {"previous_action": True})
    saved = OrderedDict([("batch_size", 64), ("env_kwargs", env_kwargs), *(config or {}).items()])
    (params / "config.yml").write_text(yaml.dump(saved))
    argv = OrderedDict([("algo", "ppo"), ("env", "vc_gym/Homing-v0"), *(args or {}).items()])
    (params / "args.yml").write_text(yaml.dump(argv))
    return run / "vc_gym-Homing-v0.zip"


def test_a_model_saved_alone_is_read_from_its_weights_and_spaces(bare_model):
    agent = LearnedHomingAgent(bare_model)
    assert agent.settings_source == "model" and agent.algo == "ppo"
    assert agent.env_kwargs == {"previous_action": True}  # 15 observations
    assert agent.model.observation_space == homing_spaces({"previous_action": True})[0]


def test_a_model_saved_alone_of_other_settings_needs_them_given(tmp_path):
    from vc_gym.training.config import TrainConfig

    kwargs = TrainConfig().env_kwargs()  # vc-gym train's default env: 38 features
    path = _save_policy(tmp_path / "bare" / "default.zip", kwargs)
    with pytest.raises(ValueError, match="observation space.*--env-kwargs"):
        LearnedHomingAgent(path)
    agent = LearnedHomingAgent(path, env_kwargs=kwargs)
    assert agent.model.observation_space == homing_spaces(kwargs)[0]


def test_flags_go_on_top_and_are_checked(bare_model):
    agent = LearnedHomingAgent(bare_model, env_kwargs={"confirm_stop_m": 0.25, "scene": "office"})
    assert agent.env_kwargs == {"confirm_stop_m": 0.25, "scene": "office", "previous_action": True}
    with pytest.raises(ValueError, match="observation space"):
        LearnedHomingAgent(bare_model, env_kwargs={"previous_action": False})
    with pytest.raises(ValueError, match="not arguments of vc_gym/Homing-v0"):
        LearnedHomingAgent(bare_model, env_kwargs={"speed": 1.0})
    with pytest.raises(ValueError, match="may not set"):
        LearnedHomingAgent(bare_model, env_kwargs={"render_mode": "rgb_array"})
    with pytest.raises(ValueError, match="unknown scene"):
        LearnedHomingAgent(bare_model, env_kwargs={"scene": "nowhere"})
    with pytest.raises(ValueError, match="import path"):
        LearnedHomingAgent(bare_model, env_kwargs={"tracker": "os:system"})


def test_env_kwargs_flags_are_read_as_json_never_evaluated():
    got = parse_env_kwargs(
        ["previous_action=true", "confirm_stop_m=0.25", "home_offset_m=[0.1, 0.0]"]
        + ["scene=office", "head_scan=False", "tracker=__import__('os')"]
    )
    assert got == {
        "previous_action": True,
        "confirm_stop_m": 0.25,
        "home_offset_m": [0.1, 0.0],
        "scene": "office",
        "head_scan": False,
        "tracker": "__import__('os')",  # text, refused later as no registered tracker
    }
    for bad in (["scene"], ["=1"], ["a=1", "a=2"]):
        with pytest.raises(ValueError, match="--env-kwargs"):
            parse_env_kwargs(bad)


def test_a_zoo_run_folder_gives_the_settings(tmp_path):
    model = _zoo_run(
        tmp_path,
        {
            "confirm_stop_m": 0.25,
            "previous_action": True,
            "learning_seed": 0,
            "atlas_file": "vc_gym_place.npz",
        },
    )
    agent = LearnedHomingAgent(model)
    assert agent.settings_source == "rl-zoo" and agent.algo == "ppo"
    # the training's place is not the evaluation's: learning_seed and atlas_file dropped
    assert agent.env_kwargs == {"confirm_stop_m": 0.25, "previous_action": True}
    assert agent.config_path.name == "config.yml"


@pytest.mark.parametrize(
    ("args", "config", "match"),
    [
        ({"env": "CartPole-v1"}, None, "trained on 'CartPole-v1'"),
        ({"algo": "dqn"}, None, "algo 'dqn'"),
        (None, {"normalize": True}, "normalize"),
    ],
)
def test_a_zoo_run_of_something_else_is_refused(tmp_path, args, config, match):
    model = _zoo_run(tmp_path, {}, args=args, config=config)
    with pytest.raises(ValueError, match=match):
        LearnedHomingAgent(model)


def test_zoo_files_never_run_code(tmp_path):
    marker = tmp_path / "ran"
    hostile = tmp_path / "config.yml"
    hostile.write_text(f'!!python/object/apply:os.system ["touch {marker}"]\n')
    with pytest.raises(ValueError, match="not a readable Zoo run file"):
        read_zoo_file(hostile)
    assert not marker.exists()
    hostile.write_text("a: &x [1]\nb: *x\n")
    with pytest.raises(ValueError, match="aliases"):
        read_zoo_file(hostile)
    hostile.write_text("!!python/object/apply:collections.OrderedDict\n- - [a, 1]\n  - [a, 2]\n")
    with pytest.raises(ValueError, match="twice"):
        read_zoo_file(hostile)
    hostile.write_bytes(b"x: " + b"1" * 1_000_001)
    with pytest.raises(ValueError, match="larger"):
        read_zoo_file(hostile)


@pytest.mark.slow
def test_evaluate_runs_a_model_saved_alone_with_flags(bare_model, tmp_path, capsys):
    out = tmp_path / "out"
    common = ["--episodes", "1", "--learn-time", "0.2", "--max-homing", "2", "--workers", "1"]
    argv = ["evaluate", "--agent", str(bare_model), *common, "--out", str(out)]
    assert main([*argv, "--env-kwargs", "confirm_stop_m=0.25"]) == 0, capsys.readouterr().err
    staged = json.loads((out / "agent" / "config.json").read_text())
    assert staged["algo"] == "ppo"
    assert staged["env"] == {"confirm_stop_m": 0.25, "previous_action": True}
    assert (out / "results.json").is_file()
    # another agent in the same folder is refused, not mixed in
    assert main([*argv, "--env-kwargs", "confirm_stop_m=0.3"]) == 2
    assert "another agent" in capsys.readouterr().err
    # and the scripted agent has no env arguments to set
    assert main(["evaluate", "--env-kwargs", "scene=office", "--out", str(tmp_path / "s")]) == 2
