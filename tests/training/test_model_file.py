"""A trained policy saved so that the same training gives the same bytes."""

from __future__ import annotations

import io
import json
import time
import zipfile

import numpy as np
import pytest
from tiny_configs import tiny_config

from vc_gym.training.model_file import reproducible_model_bytes, save_reproducible_model
from vc_gym.training.safe_load import load_sb3_model
from vc_gym.training.train import train


def _ppo(seed: int = 0):
    import gymnasium as gym
    from stable_baselines3 import PPO

    env = gym.make("Pendulum-v1")
    # a Homing-v0-shaped policy is not needed to show what the writer keeps
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=32, seed=seed, device="cpu")
    model.learn(total_timesteps=32)
    return model


def test_two_saves_of_a_policy_at_different_times_are_the_same_bytes(tmp_path, monkeypatch):
    model = _ppo()
    save_reproducible_model(model, tmp_path / "a.zip")
    plain = io.BytesIO()
    model.save(plain)
    now = time.time
    monkeypatch.setattr(time, "time", lambda: now() + 3601.0)  # an hour and a second later
    model.start_time += 3601  # as the wall clock moved on
    save_reproducible_model(model, tmp_path / "b.zip")
    assert (tmp_path / "a.zip").read_bytes() == (tmp_path / "b.zip").read_bytes()
    with zipfile.ZipFile(tmp_path / "a.zip") as z:
        data = json.loads(z.read("data"))
        assert {i.date_time for i in z.infolist()} == {(1980, 1, 1, 0, 0, 0)}
        assert "- OS:" not in z.read("system_info.txt").decode()
        assert z.read("policy.pth") == zipfile.ZipFile(plain).read("policy.pth")
    assert not {"start_time", "ep_info_buffer", "ep_success_buffer"} & set(data)
    assert " at 0x" not in json.dumps(data)
    assert data["observation_space"]["_shape"] == [3]  # what the safe loader reads stays


def test_the_saved_policy_acts_as_the_trained_one(tmp_path):
    from stable_baselines3 import PPO

    model = _ppo()
    save_reproducible_model(model, tmp_path / "m.zip")
    loaded = PPO.load(tmp_path / "m.zip", device="cpu")
    obs = np.array([0.3, -0.2, 0.5], np.float32)
    np.testing.assert_array_equal(
        loaded.predict(obs, deterministic=True)[0], model.predict(obs, deterministic=True)[0]
    )


def test_not_a_model_zip_is_refused():
    for bad in (b"", b"PK\x03\x04 not a zip", _zip({"policy.pth": b"x"}), _zip({"data": b"[1]"})):
        with pytest.raises(ValueError, match="not a stable-baselines3 model zip"):
            reproducible_model_bytes(bad)


def _zip(entries: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name, content in entries.items():
            z.writestr(name, content)
    return buf.getvalue()


@pytest.mark.slow
def test_the_same_training_run_writes_the_same_model_zip(tmp_path):
    # the shipped policy is checked this way: vc-gym train with its settings writes it again
    config = tiny_config(n_envs=2, eval_freq=0, save_freq=0)
    first = train(config, tmp_path / "a", progress=False)
    second = train(config, tmp_path / "b", progress=False)
    assert first["episodes"] == second["episodes"]
    saved = (tmp_path / "a" / "model.zip").read_bytes()
    assert saved == (tmp_path / "b" / "model.zip").read_bytes()
    assert load_sb3_model("ppo", tmp_path / "a" / "model.zip") is not None
