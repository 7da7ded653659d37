"""Training learned agents: tiny-budget training in worker processes, reload, evaluation."""

from __future__ import annotations

import json
from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest
from shared_places import POSE_HOME_SEED
from tiny_configs import TINY

from vc_gym.agents.learned import LearnedHomingAgent
from vc_gym.cli import build_parser, main
from vc_gym.experiments.studies import ExperimentOptions
from vc_gym.experiments.studies.homing import run_homing
from vc_gym.jobs.backends import LocalBackend
from vc_gym.training.config import TrainConfig
from vc_gym.training.train import train


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    out = tmp_path_factory.mktemp("agent")
    tb = out / "tb"
    summary = train(TINY, out, progress=False, tensorboard_log=tb)  # 2 worker processes
    return out, summary


@pytest.mark.slow
def test_train_writes_model_config_and_log(trained):
    out, summary = trained
    assert (out / "model.zip").is_file()
    saved = json.loads((out / "config.json").read_text())
    assert TrainConfig.from_dict(saved) == TINY
    assert saved["env"] == TINY.env_kwargs() and saved["env"]["tracker"] == "grid"
    log = json.loads((out / "train_log.json").read_text())
    assert log["episodes"] == len(log["per_episode"]) == summary["episodes"] > 0
    assert (out / "learning_curve.png").read_bytes()[:4] == b"\x89PNG"
    # the place was learned once, in the parent, and shared by both workers
    assert (out / "atlas.npz").is_file()
    assert summary["decisions_per_s"] > 0
    assert summary["task_steps_per_s"] >= summary["decisions_per_s"]


@pytest.mark.slow
def test_train_writes_what_an_sb3_user_expects(trained):
    out, summary = trained
    # SB3's per-worker monitor logs: a JSON header line, a CSV header, one row per episode
    for rank in (0, 1):
        lines = (out / "monitor" / f"{rank}.monitor.csv").read_text().splitlines()
        assert lines[0].startswith("#{") and lines[1].startswith("r,l,t")
    rows = sum(
        len((out / "monitor" / f"{r}.monitor.csv").read_text().splitlines()) - 2 for r in (0, 1)
    )
    assert rows == summary["episodes"]
    # evaluations on held-out kidnappings (every 32 decisions), the best model kept
    with np.load(out / "eval" / "evaluations.npz") as ev:
        assert list(ev["timesteps"]) == [32, 64] and ev["results"].shape == (2, 2)
    assert summary["best_model"] == str(out / "best" / "best_model.zip")
    assert sorted(p.name for p in (out / "checkpoints").iterdir()) == [
        "model_32_steps.zip",
        "model_64_steps.zip",
    ]
    assert any(p.name.startswith("events.out.tfevents") for p in (out / "tb").rglob("*"))


@pytest.mark.slow
def test_resume_continues_from_the_latest_checkpoint(trained, tmp_path, capsys):
    import shutil

    out, first = trained
    run = tmp_path / "run"
    shutil.copytree(out, run)
    code = main(["train", "--resume", str(run), "--timesteps", "96", "--json"])
    assert code == 0
    s = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert s["resumed_from"] == str(run / "checkpoints" / "model_64_steps.zip")
    assert (run / "checkpoints" / "model_96_steps.zip").is_file()
    log = json.loads((run / "train_log.json").read_text())["per_episode"]
    assert (
        log[: first["episodes"]] == json.loads((out / "train_log.json").read_text())["per_episode"]
    )
    # PPO ends on whole rollouts (2 envs x 32 steps): 96 asked, 128 done
    assert len(log) >= first["episodes"] and all(e["timestep"] <= 128 for e in log)
    assert TrainConfig.from_dict(json.loads((run / "config.json").read_text())).timesteps == 96
    # the settings of a run are kept: only --timesteps may change
    assert main(["train", "--resume", str(run), "--seed", "3"]) == 2
    assert "only --timesteps" in capsys.readouterr().err


@pytest.mark.slow
def test_the_speed_benchmark_reports_training_next_to_the_env():
    from vc_gym.experiments.benchmarks.train import bench_train

    r = bench_train(  # on the place the demo test learns (the default mode, pose-home)
        timesteps=32, n_envs=1, env_steps=10, learn_time_s=0.2, seed=POSE_HOME_SEED, progress=False
    )
    # the env is timed before the first training and after each (2 collectors)
    rounds, task_rounds = r["env_rounds_decisions_per_s"], r["env_rounds_task_steps_per_s"]
    assert r["n_envs"] == 1 and len(rounds) == len(task_rounds) == 3
    assert r["env_decisions_per_s"] == pytest.approx(np.median(rounds), rel=0.01)
    assert r["env_task_steps_per_decision"] >= 1.0
    assert list(r["collectors"]) == ["lockstep", "async"]  # the order they trained in
    for k, c in enumerate(r["collectors"].values()):
        # each collector against the rounds either side of its training
        assert c["env_decisions_per_s"] == pytest.approx(np.mean(rounds[k : k + 2]), rel=0.01)
        assert c["env_task_steps_per_s"] == pytest.approx(np.mean(task_rounds[k : k + 2]), rel=0.01)
        assert c["train_decisions_per_s"] > 0
        assert c["efficiency"] == pytest.approx(
            c["train_decisions_per_s"] / c["env_decisions_per_s"], rel=0.01
        )
        # a decision is at least one task-env step (a stop that stands is many)
        assert c["train_task_steps_per_decision"] >= 1.0
        assert c["task_step_efficiency"] == pytest.approx(
            c["train_task_steps_per_s"] / c["env_task_steps_per_s"], rel=0.01
        )
        assert c["decisions_over_task_steps"] == pytest.approx(
            c["train_decisions_per_s"] / c["env_task_steps_per_s"], rel=0.01
        )
    assert r["async_over_lockstep"] == pytest.approx(
        r["collectors"]["async"]["train_decisions_per_s"]
        / r["collectors"]["lockstep"]["train_decisions_per_s"],
        rel=0.01,
    )
    with pytest.raises(ValueError, match="collectors"):
        bench_train(timesteps=32, collectors=("fast",), progress=False)


@pytest.mark.slow
def test_reloaded_model_gives_the_same_actions(trained):
    out, _ = trained
    agent = LearnedHomingAgent(out / "model.zip")
    again = LearnedHomingAgent(out / "model.zip")
    env = gym.make(agent.env_id, **agent.env_kwargs)
    rng = np.random.default_rng(0)
    obs = rng.uniform(-2, 2, (20, *env.observation_space.shape)).astype(np.float32)
    a = np.stack([agent.predict(o) for o in obs])
    b = np.stack([again.predict(o) for o in obs])
    np.testing.assert_array_equal(a, b)
    assert a.shape == (20, 3) and np.all(np.abs(a) <= 1.0)
    assert len({tuple(x) for x in a.round(5)}) > 1  # depends on the observation
    env.close()


@pytest.mark.slow
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


@pytest.mark.slow
def test_warm_start_clones_the_expert_and_is_evaluated_before_ppo(tmp_path):
    config = replace(TINY, demo_episodes=2, save_freq=0, vec_env="dummy", collector="lockstep")
    summary = train(config, tmp_path, progress=False)
    warm = json.loads((tmp_path / "warm_start.json").read_text())
    assert warm == summary["warm_start"]
    assert warm["demo_episodes"] == 2 and warm["demo_decisions"] >= 2 * 20  # >= min walk each
    assert np.isfinite(warm["action_mse"]) and np.isfinite(warm["value_mse"])
    with np.load(tmp_path / "eval" / "evaluations.npz") as ev:
        assert list(ev["timesteps"]) == [0, 32, 64]  # the clone, then PPO's evaluations


@pytest.mark.slow
def test_a_sweep_over_seeds_trains_each_and_summarises(tmp_path, capsys):
    cfg = tmp_path / "tiny.json"
    cfg.write_text(json.dumps({**TINY.to_dict(), "save_freq": 0, "eval_freq": 64}))
    out = tmp_path / "sweep"
    argv = ["train", "--seeds", "0,1", "--config", str(cfg), "--out", str(out), "--json"]
    assert main(argv) == 0
    r = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert set(r["runs"]) == {"seed-0", "seed-1"} and r["settings"]["seeds"] == [0, 1]
    for s in (0, 1):
        saved = json.loads((out / f"seed-{s}" / "config.json").read_text())
        assert saved["seed"] == s and (out / f"seed-{s}" / "model.zip").is_file()
    returns = [r["runs"][k]["eval_final_mean_return"] for k in ("seed-0", "seed-1")]
    summary = r["over_seeds"]["eval_final_mean_return"]
    assert summary["n"] == 2 and summary["mean"] == pytest.approx(np.mean(returns), abs=1e-3)
    assert summary["std"] == pytest.approx(np.std(returns, ddof=1), abs=1e-3)
    assert r["runs"]["seed-0"]["home_offset_x_m"] is None  # trained towards the tracker's home
    assert r["over_seeds"]["home_offset_x_m"]["n"] == 0
    before = (out / "results.json").read_bytes()
    assert main(argv) == 0  # resumed: nothing trained again, the same figures
    assert (out / "results.json").read_bytes() == before
    assert main([*argv[:-1], "--seed", "3"]) == 2


@pytest.mark.slow
def test_agents_experiment_compares_on_the_same_kidnappings(trained, tmp_path, capsys):
    out, _ = trained
    model = str(out / "model.zip")
    code = main(
        ["experiment", "agents", "--quick", "--agent", f"scripted,{model}", "--out",
         str(tmp_path / "cmp"), "--episodes", "2", "--max-homing", "4"]
    )  # fmt: skip
    assert code == 0
    res = json.loads((tmp_path / "cmp" / "results.json").read_text())
    label = out.name
    assert list(res["agents"]) == ["scripted", label]
    assert res["agents"]["scripted"]["episodes"] == res["agents"][label]["episodes"] == 2
    starts = [
        [e["start_pose"] for e in json.loads((tmp_path / "cmp" / a / "results.json").read_text())[
            "per_episode"]]
        for a in ("scripted", label)
    ]  # fmt: skip
    assert starts[0] == starts[1]  # the same kidnappings
    assert res["paired_with_scripted"][label]["episodes"] == 2
    assert res["learned_over_agents"]["agents"] == 1
    assert (tmp_path / "cmp" / "agents.png").read_bytes()[:4] == b"\x89PNG"
    assert f"{label} vs scripted" in capsys.readouterr().out
    bad = ["experiment", "agents", "--quick", "--agent", model, "--out", str(tmp_path / "x")]
    assert main(bad) == 2 and "'scripted'" in capsys.readouterr().err


@pytest.mark.parametrize(("field", "value"), [("scene", "nope"), ("tracker", "nope")])
def test_a_bad_scene_or_tracker_in_a_config_file_fails_before_the_run_folder(
    tmp_path, capsys, field, value
):
    # refused before any worker starts and before the run folder is made
    cfg = tmp_path / "bad.json"
    cfg.write_text(json.dumps({field: value, "timesteps": 64}))
    out = tmp_path / "run"
    assert main(["train", "--config", str(cfg), "--out", str(out)]) == 2
    assert value in capsys.readouterr().err and not out.exists()


@pytest.mark.slow
def test_training_over_a_pool_of_places(tmp_path):
    config = replace(
        TINY,
        places=(0, 1),
        n_envs=1,
        vec_env="dummy",
        collector="lockstep",
        timesteps=32,
        eval_freq=0,
        save_freq=0,
    )
    summary = train(config, tmp_path, progress=False)
    # each place learned once, in its own file; the policy trained on both
    assert (tmp_path / "atlas-place0.npz").is_file() and (tmp_path / "atlas-place1.npz").is_file()
    assert not (tmp_path / "atlas.npz").exists()
    assert summary["episodes"] > 0
    saved = json.loads((tmp_path / "config.json").read_text())
    assert saved["places"] == [0, 1] and TrainConfig.from_dict(saved) == config
    # the agent's env is the task env of one place: the env arguments are the same
    agent = LearnedHomingAgent(tmp_path / "model.zip")
    assert agent.env_kwargs == config.env_kwargs()


@pytest.mark.slow
def test_the_goal_correction_is_measured_kept_and_used(tmp_path):
    config = replace(
        TINY,
        timesteps=32,
        max_homing_s=20.0,  # the expert gets home and stops
        eval_freq=0,
        vec_env="dummy",
        collector="lockstep",
        home_offset_episodes=3,
        home_offset_places=1,  # TINY keeps a checkpoint every 32 decisions
        home_offset_centre=True,
    )
    assert config.home_offset_seeds == (0, 2_000_000)
    summary = train(config, tmp_path, progress=False)
    measured = json.loads((tmp_path / "home_offset.json").read_text())
    assert summary["home_offset"] == measured and measured["episodes"] == 12  # two rounds
    assert measured["first_offset_m"] is not None and len(measured["slope"]) == 2
    assert (
        len(measured["per_place_m"]) == 2 and (tmp_path / "home-offset-place2000000.npz").is_file()
    )
    saved = json.loads((tmp_path / "config.json").read_text())
    assert saved["home_offset_m"] == measured["home_offset_m"]
    assert saved["env"]["home_offset_m"] == measured["home_offset_m"]
    agent = LearnedHomingAgent(tmp_path / "model.zip")  # evaluated going to the same goal
    env = gym.make(agent.env_id, **agent.env_kwargs)
    assert env.get_wrapper_attr("home_offset_m") == pytest.approx(measured["home_offset_m"])
    env.close()
    # resumed with the same settings: the run's measured goal is kept, not measured again
    resumed = train(replace(config, timesteps=64), tmp_path, progress=False, resume=True)
    assert resumed["home_offset"] is None and resumed["resumed_from"] is not None
    again = json.loads((tmp_path / "config.json").read_text())
    assert again["home_offset_m"] == measured["home_offset_m"] and again["timesteps"] == 64


def test_the_command_line_asks_for_a_centred_goal():
    assert build_parser().parse_args(["train", "--home-offset-centre"]).home_offset_centre
    assert build_parser().parse_args(["train"]).home_offset_centre is None  # the config's
    off = build_parser().parse_args(["train", "--no-home-offset-centre", "--no-previous-action"])
    assert off.home_offset_centre is False and off.previous_action is False


@pytest.mark.slow
def test_previous_action_trains_a_policy_that_sees_its_last_action(tmp_path):
    config = replace(
        TINY,
        previous_action=True,
        timesteps=32,
        eval_freq=0,
        save_freq=0,
        vec_env="dummy",
        collector="lockstep",
        demo_episodes=1,  # the expert reads its last action too
        max_homing_s=20.0,
    )
    assert config.env_kwargs()["previous_action"] is True
    assert "previous_action" not in replace(TINY, previous_action=False).env_kwargs()
    assert TrainConfig.from_dict(json.loads(json.dumps(config.to_dict()))) == config
    summary = train(config, tmp_path, progress=False)
    assert summary["warm_start"]["demo_episodes"] == 1
    agent = LearnedHomingAgent(tmp_path / "model.zip")
    env = gym.make(agent.env_id, **agent.env_kwargs)
    # 8 features + 4 spots, the position's spread (2, on by default), the last action (3)
    assert env.observation_space.shape == (8 + 4 + 2 + 3,)
    obs, _ = env.reset(seed=3)
    assert agent.predict(obs).shape == (3,)
    env.close()
    # a config.json without the field: trained without it
    before = replace(TINY, previous_action=False).to_dict()  # its env has no such key
    saved_before = {k: v for k, v in before.items() if k != "previous_action"}
    assert TrainConfig.from_dict(saved_before).previous_action is False
    with pytest.raises(ValueError, match="previous_action"):
        TrainConfig(previous_action="yes")


def test_names_read_from_train_that_moved_warn_and_are_the_same_objects():
    from vc_gym.training import train as train_module

    assert {"read_train_config", "latest_checkpoint", "checkpoints"} <= set(train_module.MOVED)
    for name, module in train_module.MOVED.items():
        moved = rf"training\.train\.{name} moved to {module.__name__}\.{name}"
        with pytest.warns(DeprecationWarning, match=moved):
            assert getattr(train_module, name) is getattr(module, name)
    with pytest.raises(AttributeError, match="no_such_name"):
        train_module.no_such_name  # noqa: B018


def test_what_the_command_line_imports_from_train_still_imports():
    from vc_gym.training import config, run_folder

    with pytest.warns(DeprecationWarning):
        from vc_gym.training.train import (
            TrainConfig,
            check_names,
            latest_checkpoint,
            read_train_config,
        )
    assert TrainConfig is config.TrainConfig and check_names is config.check_names
    assert read_train_config is config.read_train_config
    assert latest_checkpoint is run_folder.latest_checkpoint
