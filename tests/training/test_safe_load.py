"""Loading a model.zip never runs code from it (no unpickling), and refuses what is not ours."""

from __future__ import annotations

import base64
import json
import pickle
import zipfile

import numpy as np
import pytest

from vc_gym.agents.learned import PRETRAINED_MODEL
from vc_gym.training.safe_load import MAX_ENTRY_BYTES, UnsafeModelError, load_sb3_model


class _Payload:
    """Unpickling this writes a marker file: proof that code from the file ran."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _rewrite(src, dst, edit_data=None, extra=None):
    """Copy a model zip, editing its ``data`` JSON and adding entries."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            content = zin.read(info.filename)
            if info.filename == "data" and edit_data is not None:
                data = json.loads(content)
                edit_data(data)
                content = json.dumps(data).encode()
            zout.writestr(info.filename, content)
        for name, content in (extra or {}).items():
            zout.writestr(name, content)
    return dst


def _pickled(marker):
    return {":type:": "<class 'x'>", ":serialized:": base64.b64encode(
        pickle.dumps(_Payload(marker))
    ).decode()}  # fmt: skip


def test_the_shipped_policy_loads_the_same_as_sb3_would():
    from stable_baselines3 import PPO

    safe = load_sb3_model("ppo", PRETRAINED_MODEL)
    plain = PPO.load(PRETRAINED_MODEL, device="cpu")
    n_features = plain.observation_space.shape[0]
    assert safe.observation_space == plain.observation_space
    obs = np.random.default_rng(0).uniform(-2, 2, (8, n_features)).astype(np.float32)
    np.testing.assert_array_equal(
        safe.predict(obs, deterministic=True)[0], plain.predict(obs, deterministic=True)[0]
    )
    assert safe.lr_schedule(1.0) == plain.lr_schedule(1.0)
    assert safe.clip_range(1.0) == plain.clip_range(1.0)


@pytest.mark.parametrize("key", ["lr_schedule", "observation_space", "my_extra_object"])
def test_a_pickled_payload_never_runs(tmp_path, key):
    marker = tmp_path / "ran"

    def plant(data):
        if key in data:
            data[key][":serialized:"] = _pickled(marker)[":serialized:"]
        else:
            data[key] = _pickled(marker)

    hostile = _rewrite(PRETRAINED_MODEL, tmp_path / "model.zip", plant)
    try:
        load_sb3_model("ppo", hostile)  # known keys are rebuilt from their plain fields
    except UnsafeModelError as exc:
        assert key == "my_extra_object" and "unpickled" in str(exc)
    assert not marker.exists()


@pytest.mark.parametrize(
    ("edit", "extra", "message"),
    [
        (
            lambda d: d["lr_schedule"].update(value_schedule="LinearSchedule(1, 0)"),
            None,
            "constant",
        ),
        (lambda d: d["observation_space"].update(high="[5. 5.]"), None, "bounds"),
        (lambda d: d["action_space"].update(_shape=[7]), None, "Box"),
        (None, {"evil.py": b"import os"}, "unexpected entries"),
        (None, {"data": b"{}"}, "twice"),  # a second 'data' entry hiding behind the first
    ],
)
@pytest.mark.filterwarnings("ignore:Duplicate name")
def test_files_that_are_not_our_agents_are_refused(tmp_path, edit, extra, message):
    bad = _rewrite(PRETRAINED_MODEL, tmp_path / "model.zip", edit, extra)
    with pytest.raises(UnsafeModelError, match=message) as err:
        load_sb3_model("ppo", bad)
    assert str(bad) in str(err.value)


def test_huge_and_garbage_files_are_refused(tmp_path):
    big = tmp_path / "big.zip"
    with zipfile.ZipFile(big, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("data", "{}")
        z.writestr("policy.pth", b"\0" * (MAX_ENTRY_BYTES + 1))  # compresses to ~60 kB
    with pytest.raises(UnsafeModelError, match="larger"):
        load_sb3_model("ppo", big)
    junk = tmp_path / "junk.zip"
    junk.write_bytes(b"not a zip")
    with pytest.raises(UnsafeModelError, match="readable"):
        load_sb3_model("ppo", junk)
    with pytest.raises(ValueError, match="algo"):
        load_sb3_model("dqn", PRETRAINED_MODEL)


def test_an_env_id_in_data_is_never_made(tmp_path, monkeypatch):
    import gymnasium

    made = []
    monkeypatch.setattr(gymnasium, "make", lambda *a, **k: made.append(a))
    bad = _rewrite(
        PRETRAINED_MODEL,
        tmp_path / "model.zip",
        lambda d: d.update(env="vc_gym_no_such_module:Foo-v0"),
    )
    model = load_sb3_model("ppo", bad)
    assert made == [] and model.env is None


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d["policy_kwargs"].update(net_arch=[10_000, 10_000]), "layer sizes"),
        (lambda d: d["policy_kwargs"].update(net_arch=[64] * 20), "at most"),
        (lambda d: d["policy_kwargs"].update(net_arch="64"), "list"),
        (lambda d: d["policy_kwargs"].update(net_arch=[128, 128]), "do not match"),
        (lambda d: d["policy_kwargs"].update(net_arch=[64]), "do not match"),
        (lambda d: d["policy_kwargs"].update(activation_fn="os:system"), "activation_fn"),
        (lambda d: d["policy_kwargs"].update(log_std_init=1e300), "log_std_init"),
        (lambda d: d.update(n_steps=10**9), "n_steps"),
        (lambda d: d.update(n_envs=100_000), "n_envs"),
        (lambda d: d.update(batch_size=-1), "batch_size"),
        (lambda d: d.update(gamma="0.9"), "gamma"),
        (lambda d: d.update(learning_rate=float("nan")), "learning_rate"),
        (lambda d: d.update(rollout_buffer_kwargs={"device": "cuda"}), "rollout_buffer_kwargs"),
    ],
)
def test_plain_fields_out_of_bounds_are_refused_before_building(tmp_path, edit, message):
    bad = _rewrite(PRETRAINED_MODEL, tmp_path / "model.zip", edit)
    with pytest.raises(UnsafeModelError, match=message) as err:
        load_sb3_model("ppo", bad)
    assert str(bad) in str(err.value)


def test_unknown_plain_fields_are_dropped_unread(tmp_path):
    bad = _rewrite(
        PRETRAINED_MODEL, tmp_path / "model.zip", lambda d: d.update(my_attribute=[1, 2, 3])
    )
    assert not hasattr(load_sb3_model("ppo", bad), "my_attribute")


def test_a_huge_data_entry_is_refused(tmp_path):
    from vc_gym.training.safe_load import MAX_DATA_BYTES

    bad = _rewrite(
        PRETRAINED_MODEL, tmp_path / "model.zip", lambda d: d.update(pad="x" * MAX_DATA_BYTES)
    )
    with pytest.raises(UnsafeModelError, match="'data' entry is larger"):
        load_sb3_model("ppo", bad)


def test_weights_that_are_not_tensors_are_refused(tmp_path):
    import io

    import torch

    buf = io.BytesIO()
    torch.save({"log_std": [1, 2, 3]}, buf)
    bad = _rewrite(PRETRAINED_MODEL, tmp_path / "model.zip")
    with zipfile.ZipFile(PRETRAINED_MODEL) as zin, zipfile.ZipFile(bad, "w") as zout:
        for info in zin.infolist():
            content = buf.getvalue() if info.filename == "policy.pth" else zin.read(info)
            zout.writestr(info.filename, content)
    with pytest.raises(UnsafeModelError, match="policy.pth"):
        load_sb3_model("ppo", bad)


def test_a_sac_agent_loads_and_its_network_is_checked(tmp_path):
    import gymnasium as gym
    from gymnasium import spaces
    from stable_baselines3 import SAC

    class Features(gym.Env):
        observation_space = spaces.Box(-10.0, 10.0, (15,), np.float32)
        action_space = spaces.Box(-1.0, 1.0, (3,), np.float32)

        def reset(self, seed=None, options=None):
            super().reset(seed=seed)
            return np.zeros(15, np.float32), {}

        def step(self, action):
            return np.zeros(15, np.float32), 0.0, False, False, {}

    sac = SAC("MlpPolicy", Features(), policy_kwargs={"net_arch": [32, 16]}, buffer_size=64)
    sac.save(tmp_path / "sac.zip")
    loaded = load_sb3_model("sac", tmp_path / "sac.zip")
    obs = np.linspace(-1, 1, 15, dtype=np.float32)
    np.testing.assert_array_equal(
        loaded.predict(obs, deterministic=True)[0], sac.predict(obs, deterministic=True)[0]
    )
    bad = _rewrite(
        tmp_path / "sac.zip",
        tmp_path / "bad.zip",
        lambda d: d["policy_kwargs"].update(net_arch={"pi": [32, 16], "qf": [8]}),
    )
    with pytest.raises(UnsafeModelError, match="do not match"):
        load_sb3_model("sac", bad)


@pytest.mark.parametrize("entry", ["policy.pth", "policy.optimizer.pth", "pytorch_variables.pth"])
def test_a_pickled_tensor_file_is_refused_without_suggesting_to_unpickle(tmp_path, entry):
    marker = tmp_path / "ran"
    bad = tmp_path / "model.zip"
    with zipfile.ZipFile(PRETRAINED_MODEL) as zin, zipfile.ZipFile(bad, "w") as zout:
        for info in zin.infolist():
            content = zin.read(info)
            if info.filename == entry:
                import io

                import torch

                buf = io.BytesIO()
                torch.save({"x": _Payload(marker)}, buf)
                content = buf.getvalue()
            zout.writestr(info.filename, content)
    with pytest.raises(UnsafeModelError, match="cannot be loaded safely") as err:
        load_sb3_model("ppo", bad)
    assert "weights_only" not in str(err.value) and not marker.exists()
