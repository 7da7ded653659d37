"""The configuration of a training run: fields checked, saved and read back, settings files."""

from __future__ import annotations

import json
from dataclasses import replace

import gymnasium as gym
import pytest
from tiny_configs import TINY

from vc_gym.training.config import TrainConfig, read_train_config


def test_config_file_and_command_line(tmp_path):
    cfg = tmp_path / "ppo.yml"
    cfg.write_text("algo: ppo\nnet_arch: [32, 32]\nlearning_rate: 0.001\nscene: office\n")
    config = read_train_config(cfg, timesteps=500)
    assert config.net_arch == (32, 32) and config.learning_rate == 0.001
    assert config.scene == "office" and config.timesteps == 500 and config.gamma == 0.99
    # fields a settings file leaves out take the defaults (a saved config.json's take
    # the values that turn their feature off, test_stops_are_checked_in_training...)
    assert config.confirm_stop_m == 0.25 and config.collector == "async"
    # a run's own config.json reads back as the same config
    saved = tmp_path / "config.json"
    saved.write_text(json.dumps(TINY.to_dict()))
    assert read_train_config(saved) == TINY
    bad = tmp_path / "bad.yml"
    bad.write_text("reward: 3\n")
    with pytest.raises(ValueError, match="bad.yml.*unknown"):
        read_train_config(bad)


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
        {"demo_episodes": -1},
        {"algo": "sac", "demo_episodes": 5},
        {"confirm_stop_m": 0.0},
        {"confirm_stop_m": float("inf")},
        {"closeness_bonus": -1.0},
        {"closeness_bonus": float("nan")},
        {"min_walk_m": -0.5},
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


def test_stops_are_checked_in_training_and_old_configs_keep_their_final_stops():
    assert TrainConfig().confirm_stop_m == 0.25 and TrainConfig().stop_time_s == 5.0
    assert TINY.env_kwargs()["confirm_stop_m"] == 0.25
    assert TrainConfig.from_dict(TINY.to_dict()) == TINY
    final = replace(TINY, confirm_stop_m=None)
    assert "confirm_stop_m" not in final.env_kwargs()
    assert TrainConfig.from_dict(final.to_dict()) == final
    # a config.json without the field: its stops are final
    saved_before = {k: v for k, v in final.to_dict().items() if k != "confirm_stop_m"}
    assert TrainConfig.from_dict(saved_before) == final


@pytest.mark.parametrize(("name", "value"), [("closeness_bonus", 10.0), ("min_walk_m", 0.5)])
def test_optional_env_settings_and_old_configs_without_them(name, value):
    assert getattr(TrainConfig(), name) == 0.0
    given = replace(TINY, **{name: value})
    assert given.env_kwargs()[name] == value
    assert TrainConfig.from_dict(given.to_dict()) == given
    plain = replace(TINY, **{name: 0.0})
    assert name not in plain.env_kwargs()
    assert TrainConfig.from_dict(plain.to_dict()) == plain
    # a config.json without the field: trained without it
    saved_before = {k: v for k, v in plain.to_dict().items() if k != name}
    assert TrainConfig.from_dict(saved_before) == plain
    # what the agent's env is built with
    env = gym.make("vc_gym/Homing-v0", **given.env_kwargs())
    assert env.get_wrapper_attr(name) == value
    env.close()


def test_places_are_checked_and_saved():
    assert TINY.place_seeds == (0,) and TINY.places == ()
    config = replace(TINY, places=[3, 1])
    assert config.places == (3, 1) and config.place_seeds == (3, 1)
    assert TrainConfig.from_dict(json.loads(json.dumps(config.to_dict()))) == config
    assert [p.name for p in config.atlas_files("run")] == [
        "atlas-place3.npz",
        "atlas-place1.npz",
    ]
    for bad in ([1, 1], [-1], "12", [0.5], 3, list(range(17))):
        with pytest.raises(ValueError, match="places"):
            replace(TINY, places=bad)


def test_goal_correction_settings():
    # in the paper's mode the default goal is measured and centred (README, Learned agents:
    # learning seeds 30-32); the other modes normalise at the true home and measure none
    paper = TrainConfig(mode="paper")
    assert paper.home_offset_episodes == 10 and paper.home_offset_places == 3
    assert paper.home_offset_centre is True and paper.home_offset_m is None
    for mode in ("pose-home", "check-home"):
        assert TrainConfig(mode=mode).home_offset_episodes == 0
        assert TrainConfig(mode=mode).home_offset_centre is False
    assert TrainConfig().home_offset_episodes == 0  # the default mode is pose-home
    assert TrainConfig(mode="paper", home_offset_m=(0.1, 0.0)).home_offset_episodes == 0
    assert "home_offset_m" not in paper.env_kwargs()  # until it is measured
    assert TrainConfig(seed=2).home_offset_seeds == (2, 2_000_032, 2_000_033, 2_000_034)
    given = replace(TINY, home_offset_m=(0.05, -0.1))
    assert given.env_kwargs()["home_offset_m"] == [0.05, -0.1]
    assert TrainConfig.from_dict(json.loads(json.dumps(given.to_dict()))) == given
    assert "home_offset_m" not in TINY.env_kwargs()
    # a config.json without the fields: trained towards the tracker's home
    saved_before = {
        k: v for k, v in TrainConfig().to_dict().items() if not k.startswith("home_offset")
    }
    old = TrainConfig.from_dict(saved_before)
    assert old.home_offset_episodes == 0 and old.home_offset_m is None
    assert old.home_offset_centre is False
    centred = replace(TINY, home_offset_episodes=10, home_offset_centre=True)
    assert TrainConfig.from_dict(json.loads(json.dumps(centred.to_dict()))) == centred
    for bad in (
        {"home_offset_episodes": -1},
        {"home_offset_places": 17},
        {"home_offset_episodes": 1, "home_offset_places": 0},  # 1 episode: too few
        {"home_offset_m": (2.0, 0.0)},
        {"home_offset_m": (float("nan"), 0.0)},
        {"home_offset_m": (0.1,)},
        {"home_offset_m": "0.1,0.2"},
        {"home_offset_centre": "yes"},
        {"home_offset_centre": 1},
        {"home_offset_episodes": 0, "home_offset_centre": True},  # nothing measured to centre
    ):
        with pytest.raises(ValueError, match="home_offset"):
            TrainConfig(**bad)


def test_mode_and_position_spread():
    # the default recipe: pose-home's places and tracker, the position's spread in view
    config = TrainConfig()
    assert config.mode == "pose-home" and config.tracker == "pose-grid"
    env = config.env_kwargs()
    assert env["normalise_at"] == "start" and env["around_m"] == 0.5
    assert env["position_std"] is True and env["tracker"] == "pose-grid"
    paper = TrainConfig(mode="paper", position_std=False)
    assert paper.tracker == "grid"
    assert not {"normalise_at", "around_m", "position_std"} & set(paper.env_kwargs())
    assert TrainConfig(mode="check-home").env_kwargs()["normalise_at"] == "start"
    assert TrainConfig(mode="pose-home", tracker="grid").tracker == "grid"  # given wins
    with pytest.warns(DeprecationWarning):
        assert TrainConfig(mode="improved").mode == "check-home"
    for bad in ("best", None, 3):
        with pytest.raises(ValueError, match="mode"):
            TrainConfig(mode=bad)
    for bad in ("yes", 1, None):
        with pytest.raises(ValueError, match="position_std"):
            TrainConfig(position_std=bad)
    # round trip, and a config.json saved before the fields: the paper's places, no spread
    assert TrainConfig.from_dict(json.loads(json.dumps(config.to_dict()))) == config
    before = {k: v for k, v in paper.to_dict().items() if k not in ("mode", "position_std")}
    old = TrainConfig.from_dict(before)
    assert old.mode == "paper" and old.position_std is False and old.tracker == "grid"


def test_the_expert_walks_at_the_scripted_agents_speed_by_default():
    assert TrainConfig().expert_speed_m_s == 0.25
    assert TrainConfig(expert_speed_m_s=0.4).expert_speed_m_s == 0.4 == TrainConfig().max_forward
    for bad in (0.0, -0.1, float("nan"), "fast", 0.41):
        with pytest.raises(ValueError, match="expert_speed_m_s"):
            TrainConfig(expert_speed_m_s=bad)
    assert TrainConfig(max_forward=0.3, expert_speed_m_s=0.3).expert_speed_m_s == 0.3
    # a config.json saved before the field: the scripted agent's 0.25 m/s
    before = {k: v for k, v in TrainConfig().to_dict().items() if k != "expert_speed_m_s"}
    assert TrainConfig.from_dict(before).expert_speed_m_s == 0.25
