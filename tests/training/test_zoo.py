"""RL Baselines3 Zoo trains vc_gym/Homing-v0 with the hyperparameters we ship, and
``vc-gym evaluate`` evaluates the model it saved."""

from __future__ import annotations

import ast
import json
import subprocess
import sys

import numpy as np
import pytest

from vc_gym.cli import main
from vc_gym.envs import PlaceCache
from vc_gym.hyperparams import zoo_hyperparams
from vc_gym.training.config import TrainConfig
from vc_gym.training.safe_load import UnsafeModelError, _constant_schedule


def _policy_kwargs(text: str) -> dict:
    call = ast.parse(text, mode="eval").body
    assert isinstance(call, ast.Call) and call.func.id == "dict"
    return {k.arg: ast.literal_eval(k.value) for k in call.keywords}


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_shipped_hyperparameters_are_vc_gym_train_defaults(algo):
    hp = zoo_hyperparams(algo)["vc_gym/Homing-v0"]
    d = TrainConfig(algo=algo)
    assert hp["n_envs"] == d.n_envs and hp["n_timesteps"] == d.timesteps
    assert hp["batch_size"] == d.batch_size and hp["learning_rate"] == d.learning_rate
    assert hp["gamma"] == d.gamma
    if algo == "ppo":
        assert hp["n_steps"] == d.n_steps
    pk = _policy_kwargs(hp["policy_kwargs"])
    assert pk == {"net_arch": list(d.net_arch), "log_std_init": d.log_std_init}
    env = hp["env_kwargs"]
    assert env["stop_time_s"] == d.stop_time_s and env["learn_time_s"] == d.learn_time_s
    assert env["confirm_stop_m"] == d.confirm_stop_m
    assert env.get("closeness_bonus", 0.0) == d.closeness_bonus
    assert env.get("min_walk_m", 0.0) == d.min_walk_m
    assert env.get("previous_action", False) == d.previous_action
    assert env["scene"] == d.scene and env["learning_seed"] == 0
    assert "atlas_file" not in env  # the place cache shares the place, outside the run
    with pytest.raises(ValueError, match="ppo and sac"):
        zoo_hyperparams("dqn")


def test_the_zoos_constant_learning_rate_loads_as_its_value():
    entry = {":type:": "<class 'stable_baselines3.common.utils.ConstantSchedule'>", "val": "3e-4"}
    assert _constant_schedule(entry, "learning_rate") == 3e-4
    for bad in ({**entry, "val": "nan"}, {**entry, "val": "5"}, {**entry, ":type:": "x"}):
        with pytest.raises(UnsafeModelError, match="learning_rate"):
            _constant_schedule(bad, "learning_rate")


@pytest.mark.slow
def test_a_tiny_zoo_training_run_then_vc_gym_evaluate(tmp_path, monkeypatch, capsys):
    pytest.importorskip("rl_zoo3")
    from stable_baselines3 import PPO

    work = tmp_path / "work"
    work.mkdir()
    cmd = [
        sys.executable, "-m", "rl_zoo3.train",
        "--algo", "ppo", "--env", "vc_gym/Homing-v0", "--gym-packages", "vc_gym",
        "-conf", "vc_gym.hyperparams.ppo",
        "-n", "64", "--hyperparams", "n_steps:32", "batch_size:32",
        "--env-kwargs", "learn_time_s:0.2", "max_homing_s:3.0", "stop_time_s:0.1",
        "learning_seed:0", "previous_action:True",
        "-f", "logs", "--eval-freq", "-1", "--seed", "0",
    ]  # fmt: skip
    cache = tmp_path / "cache"  # its own: the suite's workers share theirs
    monkeypatch.setenv("VC_GYM_CACHE", str(cache))
    done = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    run = work / "logs" / "ppo" / "vc_gym-Homing-v0_1"
    # the two envs shared one place, learned once into the cache: nothing else in the
    # working folder, no lock file
    assert [p.name for p in work.iterdir()] == ["logs"]
    assert len(PlaceCache(cache).places()) == 1
    assert (run / "0.monitor.csv").is_file() and (run / "1.monitor.csv").is_file()
    model = PPO.load(run / "vc_gym-Homing-v0.zip", device="cpu")
    again = PPO.load(run / "vc_gym-Homing-v0.zip", device="cpu")
    obs = np.random.default_rng(0).uniform(-2, 2, (10, *model.observation_space.shape))
    a = model.predict(obs.astype(np.float32), deterministic=True)[0]
    b = again.predict(obs.astype(np.float32), deterministic=True)[0]
    np.testing.assert_array_equal(a, b)
    assert a.shape == (10, 3)

    out = tmp_path / "evaluation"
    argv = ["evaluate", "--agent", str(run / "vc_gym-Homing-v0.zip"), "--episodes", "1"]
    argv += ["--learn-time", "0.2", "--max-homing", "2", "--workers", "1", "--out", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    staged = json.loads((out / "agent" / "config.json").read_text())
    # the Zoo run's env settings, less the training's place
    assert staged["env"] == {
        "learn_time_s": 0.2,
        "max_homing_s": 3.0,
        "stop_time_s": 0.1,
        "previous_action": True,
    }
    results = json.loads((out / "results.json").read_text())
    assert results["overall"]["episodes"] == 1 and results["failed_jobs"] == []
    assert results["per_episode"][0]["decisions"] >= 1
