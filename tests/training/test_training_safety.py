"""Training runs that cannot be mixed up, torn or made to run code.

A new run refuses a folder holding a run; checkpoints, the best model and the evaluations
are written atomically and a resume skips a checkpoint that does not load; every
TrainConfig field is type-checked; a tracker or scene read from a file is a registered
plug-in (import paths only with ``allow_imports``); an interrupted run stays resumable.
"""

from __future__ import annotations

import json
import shutil
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from tiny_configs import TINY_LOCAL

from vc_gym.cli import build_parser, main
from vc_gym.training import run_folder
from vc_gym.training.config import MAX_N_ENVS, TrainConfig, check_names, read_train_config
from vc_gym.training.run_folder import check_new_run_dir, latest_checkpoint
from vc_gym.training.safe_load import MAX_LAYER_WIDTH, MAX_LAYERS
from vc_gym.training.train import continue_run, train


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    summary = train(TINY_LOCAL, out, progress=False)
    return out, summary


def _copy(run_dir: Path, to: Path) -> Path:
    shutil.copytree(run_dir, to)
    return to


def _hidden_files(folder: Path) -> list[Path]:
    """Temporary files of the atomic writers left anywhere below ``folder``."""
    return [p for p in folder.rglob(".*") if p.is_file() and not p.name.endswith(".lock")]


# --- 1. a new run refuses a folder that holds a run ---------------------------------------


@pytest.mark.parametrize("held", ["config.json", "model.zip", "train_log.json", "checkpoints"])
def test_a_new_run_refuses_a_folder_holding_a_run_before_writing(tmp_path, held):
    out = tmp_path / "run"
    out.mkdir()
    target = out / held
    if held == "checkpoints":
        target.mkdir()
        (target / "model_32_steps.zip").write_bytes(b"old")
    else:
        target.write_text('{"old": true}')
    before = sorted((p.relative_to(out), p.read_bytes() if p.is_file() else None)
                    for p in out.rglob("*"))  # fmt: skip
    with pytest.raises(ValueError, match=rf"--out {out}: holds a training run.*--resume"):
        train(TINY_LOCAL, out, progress=False)
    after = sorted((p.relative_to(out), p.read_bytes() if p.is_file() else None)
                   for p in out.rglob("*"))  # fmt: skip
    assert after == before


@pytest.mark.slow
def test_the_command_line_refuses_an_existing_run_and_keeps_its_config(run, tmp_path, capsys):
    out = _copy(run[0], tmp_path / "run")
    config = (out / "config.json").read_bytes()
    model = (out / "model.zip").read_bytes()
    for extra in (["--timesteps", "96"], ["--seed", "3", "--n-envs", "1"]):
        assert main(["train", "--out", str(out), *extra]) == 2
        err = capsys.readouterr().err
        assert "holds a training run" in err and f"--resume {out}" in err
        assert (out / "config.json").read_bytes() == config
        assert (out / "model.zip").read_bytes() == model


def test_a_folder_with_only_atlases_or_other_files_may_take_a_new_run(tmp_path):
    check_new_run_dir(tmp_path / "missing")
    (tmp_path / "atlas.npz").write_bytes(b"")
    (tmp_path / "notes.txt").write_text("mine")
    check_new_run_dir(tmp_path)
    (tmp_path / "best").mkdir()
    with pytest.raises(ValueError, match="best"):
        check_new_run_dir(tmp_path)


@pytest.mark.slow
def test_a_sweep_refuses_a_single_runs_folder(run, tmp_path):
    from vc_gym.jobs.backends import LocalBackend
    from vc_gym.training.sweep import run_train_sweep

    out = _copy(run[0], tmp_path / "run")
    with pytest.raises(ValueError, match="not a sweep"):
        run_train_sweep(out, TINY_LOCAL, [0], LocalBackend(1), progress=False)
    assert not (out / "jobs").exists()


@pytest.mark.slow
def test_a_sweep_job_goes_on_from_its_own_checkpoint_and_refuses_another_run(run, tmp_path):
    from vc_gym.training.sweep import train_job

    # an earlier attempt of this job, cut short after its last checkpoint
    seed0 = _copy(run[0], tmp_path / "seed-0")
    (seed0 / "model.zip").unlink()
    train_job(TINY_LOCAL.to_dict(), str(seed0))
    log = json.loads((seed0 / "train_log.json").read_text())
    assert log["resumed_from"] == str(seed0 / "checkpoints" / "model_64_steps.zip")
    assert (seed0 / "model.zip").is_file()
    # a folder holding a run of other settings is left alone
    other = _copy(run[0], tmp_path / "seed-1")
    config = (other / "config.json").read_bytes()
    with pytest.raises(ValueError, match="other settings"):
        train_job(replace(TINY_LOCAL, seed=1).to_dict(), str(other))
    assert (other / "config.json").read_bytes() == config
    stray = tmp_path / "stray"
    stray.mkdir()
    (stray / "model.zip").write_bytes(b"x")
    with pytest.raises(ValueError, match="no config.json"):
        continue_run(TINY_LOCAL, stray)


@pytest.mark.slow
def test_a_sweep_job_without_a_checkpoint_starts_over_in_its_folder(run, tmp_path):
    seed0 = tmp_path / "seed-0"
    seed0.mkdir()
    shutil.copy(run[0] / "config.json", seed0 / "config.json")
    shutil.copy(run[0] / "atlas.npz", seed0 / "atlas.npz")
    config = replace(TINY_LOCAL, timesteps=32, eval_freq=0, save_freq=0)
    (seed0 / "config.json").write_text(json.dumps(config.to_dict()))
    summary = continue_run(config, seed0)
    assert summary["resumed_from"] is None and (seed0 / "model.zip").is_file()


# --- 2. checkpoints whole or not at all; a resume skips one that does not load -----------


class _TornSave:
    """A model whose ``save`` writes half a file and is then interrupted (a name without a
    suffix gets ``.zip``, as SB3's ``save`` does)."""

    num_timesteps = 64

    def save(self, path):
        path = Path(path)
        path = path if path.suffix else path.with_suffix(".zip")
        path.write_bytes(b"PK\x03\x04 half a zip")
        raise KeyboardInterrupt


def test_an_interrupted_checkpoint_leaves_no_torn_file(tmp_path):
    from vc_gym.training.callbacks import AtomicCheckpoint

    cb = AtomicCheckpoint(1, tmp_path / "checkpoints", "model")
    cb.init_callback(_TornSave())
    cb.num_timesteps = 64
    (tmp_path / "checkpoints" / "model_64_steps.zip").write_bytes(b"whole")
    with pytest.raises(KeyboardInterrupt):
        cb.on_step()
    assert (tmp_path / "checkpoints" / "model_64_steps.zip").read_bytes() == b"whole"
    assert sorted(p.name for p in (tmp_path / "checkpoints").iterdir()) == ["model_64_steps.zip"]


def test_an_interrupted_best_model_or_evaluation_leaves_the_old_one(tmp_path, monkeypatch):
    import gymnasium as gym
    from stable_baselines3.common import callbacks
    from stable_baselines3.common.vec_env import DummyVecEnv

    from vc_gym.training.callbacks import HeldOutEvaluation

    class Model(_TornSave):
        logger = type("L", (), {"record": lambda *a, **k: None, "dump": lambda *a, **k: None})()

        def get_env(self):
            return env

        def get_vec_normalize_env(self):
            return None

    env = DummyVecEnv([lambda: gym.make("CartPole-v1")])
    monkeypatch.setattr(callbacks, "evaluate_policy", lambda *a, **k: ([1.0], [3]))
    cb = HeldOutEvaluation(
        env, seed=0, eval_freq=1, best_model_save_path=str(tmp_path / "best"),
        log_path=str(tmp_path / "eval"), verbose=0,
    )  # fmt: skip
    cb.init_callback(Model())
    (tmp_path / "best" / "best_model.zip").write_bytes(b"old best")
    with pytest.raises(KeyboardInterrupt):
        cb.on_step()
    assert (tmp_path / "best" / "best_model.zip").read_bytes() == b"old best"
    with np.load(tmp_path / "eval" / "evaluations.npz") as ev:  # renamed into place whole
        assert list(ev["timesteps"]) == [64]
    assert _hidden_files(tmp_path) == []
    env.close()


@pytest.mark.slow
def test_resume_skips_a_truncated_newest_checkpoint(run, tmp_path, capsys):
    out = _copy(run[0], tmp_path / "run")
    newest = out / "checkpoints" / "model_64_steps.zip"
    newest.write_bytes(newest.read_bytes()[: newest.stat().st_size // 2])
    s = train(replace(TINY_LOCAL, timesteps=96), out, progress=False, resume=True)
    assert s["resumed_from"] == str(out / "checkpoints" / "model_32_steps.zip")
    assert [k["checkpoint"] for k in s["skipped_checkpoints"]] == [str(newest)]
    assert f"skipping checkpoint {newest}" in capsys.readouterr().err
    # training from 32 wrote the checkpoint at 64 again, whole
    assert (out / "checkpoints" / "model_96_steps.zip").is_file()
    again = train(replace(TINY_LOCAL, timesteps=96), out, progress=False, resume=True)
    assert again["skipped_checkpoints"] == []


@pytest.mark.slow
def test_resume_without_a_loadable_checkpoint_says_why(run, tmp_path):
    out = _copy(run[0], tmp_path / "run")
    for p in (out / "checkpoints").iterdir():
        p.write_bytes(b"torn")
    with pytest.raises(ValueError, match="no checkpoint loads.*model_64_steps.zip"):
        train(TINY_LOCAL, out, progress=False, resume=True)


# --- 3. every field type-checked -----------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("net_arch", "64"),
        ("net_arch", [1e9]),
        ("net_arch", [MAX_LAYER_WIDTH + 1]),
        ("net_arch", [64.0]),
        ("net_arch", [64.5]),
        ("net_arch", [True]),
        ("net_arch", [64] * (MAX_LAYERS + 1)),
        ("net_arch", []),
        ("net_arch", 64),
        ("gamma", "0.9"),
        ("gamma", True),
        ("gamma", float("nan")),
        ("learning_rate", "3e-4"),
        ("log_std_init", "x"),
        ("log_std_init", float("inf")),
        ("timesteps", "64"),
        ("timesteps", 64.0),
        ("n_envs", True),
        ("n_envs", MAX_N_ENVS + 1),
        ("seed", 1.0),
        ("eval_freq", None),
        ("save_freq", "0"),
        ("batch_size", 32.5),
        ("max_forward", "0.4"),
        ("previous_action", 1),
        ("scene", 3),
        ("scene", ["robolab"]),
        ("tracker", 3),
        ("tracker", ""),
        ("tracker", {"n_particles": 5}),
        ("tracker", {"type": "particle", "rng": object()}),
        ("vec_env", ["dummy"]),
        ("collector", 1),
        ("algo", ["ppo"]),
        ("places", "12"),
    ],
)
def test_every_train_config_field_is_type_checked(field, value):
    with pytest.raises(ValueError, match=field):
        replace(TrainConfig(), **{field: value})


def test_fields_are_stored_as_plain_json_values():
    config = TrainConfig(
        timesteps=np.int64(64), learning_rate=np.float32(0.5), net_arch=np.array([32, 16]),
        previous_action=np.bool_(True),
    )  # fmt: skip
    assert type(config.timesteps) is int and type(config.learning_rate) is float
    assert config.net_arch == (32, 16) and all(type(n) is int for n in config.net_arch)
    assert config.previous_action is True
    json.dumps(config.to_dict())


# --- 4. the tracker as {"type": name, **kwargs} --------------------------------------------


def test_a_tracker_dict_round_trips_and_stays_plain():
    given = {"type": "particle", "n_particles": 500}
    config = TrainConfig(tracker=given)
    given["n_particles"] = 1  # the config keeps its own copy
    assert config.tracker == {"type": "particle", "n_particles": 500}
    assert config.env_kwargs()["tracker"] == config.tracker
    config.env_kwargs()["tracker"]["n_particles"] = 2  # and hands out copies
    assert config.tracker["n_particles"] == 500
    saved = json.loads(json.dumps(config.to_dict()))
    assert TrainConfig.from_dict(saved) == config and hash(TrainConfig.from_dict(saved)) == hash(
        config
    )
    assert len({config, TrainConfig.from_dict(saved)}) == 1
    check_names(config)


def test_the_command_line_reads_a_json_tracker_for_train():
    spec = '{"type": "particle", "n_particles": 500}'
    args = build_parser().parse_args(["train", "--tracker", spec])
    assert args.tracker == {"type": "particle", "n_particles": 500}
    assert build_parser().parse_args(["train", "--tracker", "kalman"]).tracker == "kalman"
    check_names(TrainConfig(tracker=args.tracker))


@pytest.mark.slow
def test_a_run_trained_with_a_tracker_dict_reads_back(run):
    out, _ = run
    saved = read_train_config(out / "config.json")
    assert saved == TINY_LOCAL and saved.tracker == {"type": "grid"}


# --- 5. files choose no code ---------------------------------------------------------------


@pytest.fixture
def evil_module(tmp_path, monkeypatch):
    """An importable module that leaves a mark when it is imported."""
    marker = tmp_path / "imported"
    (tmp_path / "vc_gym_evil_tracker.py").write_text(
        f"open({str(marker)!r}, 'w').close()\ndef make():\n    raise SystemExit(0)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "vc_gym_evil_tracker:make", marker
    sys.modules.pop("vc_gym_evil_tracker", None)


@pytest.mark.parametrize("name", ["config.yml", "config.json"])
@pytest.mark.parametrize(
    "tracker", ["os:abort", "sys:exit", "this:x", "EVIL", {"type": "EVIL", "n": 1}, ["grid"]]
)
def test_a_files_tracker_must_be_a_registered_plugin(tmp_path, evil_module, name, tracker):
    path_spec, marker = evil_module
    tracker = path_spec if tracker == "EVIL" else tracker
    if isinstance(tracker, dict) and tracker["type"] == "EVIL":
        tracker = {**tracker, "type": path_spec}
    path = tmp_path / name
    data = {"tracker": tracker, "timesteps": 64}
    if name == "config.json":  # a run's own config.json
        data = {**TINY_LOCAL.to_dict(), "tracker": tracker}
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=rf"{name}: field 'tracker'"):
        read_train_config(path)
    assert not marker.exists() and "vc_gym_evil_tracker" not in sys.modules


def test_a_files_scene_must_be_a_registered_name(tmp_path):
    path = tmp_path / "t.yml"
    path.write_text('scene: "os:abort"\n')
    with pytest.raises(ValueError, match=r"t.yml: field 'scene'.*unknown scene"):
        read_train_config(path)
    with pytest.raises(ValueError, match=r"field 'scene'"):
        read_train_config(path, allow_imports=True)  # scenes are names only


def test_import_paths_from_files_only_when_allowed_and_from_the_keyboard(tmp_path, evil_module):
    path_spec, marker = evil_module
    path = tmp_path / "t.yml"
    path.write_text(f'tracker: "{path_spec}"\n')
    config = read_train_config(path, allow_imports=True)
    assert config.tracker == path_spec and not marker.exists()  # named, not imported yet
    # the command line's value replaces the file's and is not checked like it
    assert read_train_config(path, tracker="grid").tracker == "grid"
    plain = tmp_path / "plain.yml"
    plain.write_text("timesteps: 64\n")
    assert read_train_config(plain, tracker=path_spec).tracker == path_spec


def test_the_command_line_refuses_a_files_import_path_before_anything(
    tmp_path, evil_module, capsys
):
    path_spec, marker = evil_module
    cfg = tmp_path / "t.yml"
    cfg.write_text(f'tracker: "{path_spec}"\ntimesteps: 64\n')
    out = tmp_path / "out"
    assert main(["train", "--config", str(cfg), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "t.yml: field 'tracker'" in err and "--allow-imports" in err
    assert not marker.exists() and not out.exists()
    args = build_parser().parse_args(["train", "--allow-imports"])
    assert args.allow_imports is True
    assert build_parser().parse_args(["train"]).allow_imports is False


@pytest.mark.slow
def test_resume_reads_the_runs_config_through_the_same_checks(run, tmp_path, evil_module, capsys):
    path_spec, marker = evil_module
    out = _copy(run[0], tmp_path / "run")
    saved = json.loads((out / "config.json").read_text())
    saved["tracker"] = saved["env"]["tracker"] = path_spec
    (out / "config.json").write_text(json.dumps(saved))
    assert main(["train", "--resume", str(out)]) == 2
    assert "config.json: field 'tracker'" in capsys.readouterr().err
    assert not marker.exists()


@pytest.mark.slow
def test_a_large_or_malformed_training_log_is_refused_on_resume(run, tmp_path, monkeypatch):
    out = _copy(run[0], tmp_path / "run")
    log = out / "train_log.json"
    log.write_text(json.dumps({"per_episode": [{"timestep": "x"}]}))
    with pytest.raises(ValueError, match=r"train_log.json: per_episode\[0\]"):
        train(TINY_LOCAL, out, progress=False, resume=True)
    log.write_text(json.dumps({"per_episode": []}) + " " * 100)
    monkeypatch.setattr(run_folder, "MAX_TRAIN_LOG_BYTES", 50)
    with pytest.raises(ValueError, match=r"train_log.json.*larger than 50 bytes"):
        train(TINY_LOCAL, out, progress=False, resume=True)


# --- 7. an interrupted run stays resumable -------------------------------------------------


@pytest.mark.slow
def test_an_interrupted_run_keeps_whole_checkpoints_and_resumes(tmp_path, monkeypatch):
    from vc_gym.training.callbacks import AtomicCheckpoint

    save = AtomicCheckpoint._on_step

    def interrupted(self):
        go_on = save(self)
        if self.num_timesteps >= 64:
            raise KeyboardInterrupt  # Ctrl-C right after the checkpoint at 64
        return go_on

    monkeypatch.setattr(AtomicCheckpoint, "_on_step", interrupted)
    out = tmp_path / "run"
    config = replace(TINY_LOCAL, timesteps=96)
    with pytest.raises(KeyboardInterrupt):
        train(config, out, progress=False)
    monkeypatch.undo()
    assert not (out / "model.zip").exists() and _hidden_files(out) == []
    assert latest_checkpoint(out) == out / "checkpoints" / "model_64_steps.zip"
    # the episode log was saved with the checkpoint: the resume keeps those episodes
    before = json.loads((out / "train_log.json").read_text())["per_episode"]
    assert before and all(e["timestep"] <= 64 for e in before)
    s = train(config, out, progress=False, resume=True)
    assert s["resumed_from"] == str(out / "checkpoints" / "model_64_steps.zip")
    assert s["skipped_checkpoints"] == []
    after = json.loads((out / "train_log.json").read_text())["per_episode"]
    assert after[: len(before)] == before
