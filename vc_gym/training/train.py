"""Training learned homing agents with stable-baselines3 (``vc-gym train``).

:func:`train` fits PPO (default) or SAC on ``vc_gym/Homing-v0`` (the task env seen
through the compass and a tracker, :mod:`vc_gym.envs.homing`) in parallel worker
processes (``SubprocVecEnv``) and writes ``model.zip``, ``config.json``,
``train_log.json`` and ``learning_curve.png``;
:class:`~vc_gym.agents.learned.LearnedHomingAgent` loads them. A run: its settings
(:mod:`.config`), the envs it trains on (:mod:`.environments`), its folder, checkpoints
and resume (:mod:`.run_folder`); before RL starts it measures its goal correction
(:mod:`.home_offset`) and clones the scripted expert (:mod:`.imitation`).

A run owns its folder: a new run refuses a folder that holds one
(:func:`~vc_gym.training.run_folder.check_new_run_dir`), and only ``resume`` continues
one. Checkpoints and every other file but SB3's monitor logs are written atomically, and
a resume skips a checkpoint that does not load, so an interrupted run can be resumed from
its last whole checkpoint.
"""

from __future__ import annotations

import os
import time
import warnings
from dataclasses import replace
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from vc_gym.deprecation import moved_names
from vc_gym.jobs.output import check_out_dir, new_figure, save_figure, write_json
from vc_gym.training import config as config_module
from vc_gym.training import run_folder, safe_load
from vc_gym.training.algorithms import algorithm_class
from vc_gym.training.config import HOME_OFFSET_SEED, MAX_PLACES, TrainConfig, check_names
from vc_gym.training.environments import (
    EnvFactory,
    learn_places,
    place_env,
    run_places,
    training_env,
)
from vc_gym.training.feature_expert import HomingFeatureExpert
from vc_gym.training.home_offset import centre_home_offset, measure_home_offset
from vc_gym.training.imitation import clone_behaviour, collect_demonstrations
from vc_gym.training.model_file import save_reproducible_model
from vc_gym.training.run_folder import (
    CHECKPOINT_PREFIX,
    RunStart,
    check_new_run_dir,
    resume_state,
    run_files,
)
from vc_gym.training.safe_load import load_sb3_model

__all__ = ["continue_run", "train"]

#: Names this module served that live elsewhere now, each with its module: read from
#: here they warn with a ``DeprecationWarning`` (for one release).
MOVED: dict[str, ModuleType] = {
    **{
        name: config_module
        for name in (
            "COLLECTORS",
            "CONFIG_SCHEMA",
            "DEFAULT_DEMO_EPISODES",
            "DEFAULT_HOME_OFFSET_EPISODES",
            "MAX_N_ENVS",
            "VEC_ENVS",
            "read_train_config",
        )
    },
    **{
        name: run_folder
        for name in ("MAX_TRAIN_LOG_BYTES", "RUN_FILES", "checkpoints", "latest_checkpoint")
    },
    **{name: safe_load for name in ("MAX_LAYERS", "MAX_LAYER_WIDTH")},
}


__getattr__ = moved_names(__name__, MOVED)


def _check_start(config: TrainConfig, tensorboard_log: str | os.PathLike | None) -> None:
    """What :func:`train` checks before it touches the run folder."""
    algorithm_class(config.algo)  # stable-baselines3 is installed
    check_names(config)  # before the run folder is made, not in the workers
    if tensorboard_log is not None:
        try:
            import tensorboard  # noqa: F401
        except ImportError:
            raise ValueError(
                "--tensorboard-log needs the tensorboard package: pip install tensorboard"
            ) from None


def train(
    config: TrainConfig,
    out_dir: str | os.PathLike,
    progress: bool = True,
    tensorboard_log: str | os.PathLike | None = None,
    resume: bool = False,
) -> dict[str, Any]:
    """Train a homing agent the way stable-baselines3 users expect.

    Writes to ``out_dir``: ``model.zip`` (the final policy), ``config.json``,
    ``train_log.json`` (every training episode), ``learning_curve.png``, ``atlas.npz``
    (the place, learned once; ``atlas-place<s>.npz`` per place with ``places``),
    ``monitor/<i>.monitor.csv`` (SB3's per-worker episode logs), with ``eval_freq``
    ``eval/evaluations.npz`` and ``best/best_model.zip`` (held-out kidnappings), with
    ``save_freq`` ``checkpoints/model_<N>_steps.zip``. Every file but the monitor logs
    (appended line by line) is written atomically, so an interrupted run (Ctrl-C) keeps
    whole checkpoints to resume from.

    Parameters
    ----------
    config : TrainConfig
        The run's settings (saved as ``config.json`` before training starts).
    out_dir : path-like
        The run folder. A new run refuses a folder that holds a run already
        (:func:`~vc_gym.training.run_folder.check_new_run_dir`), before anything is written.
    progress : bool
        Show progress.
    tensorboard_log : path-like, optional
        Also write TensorBoard logs there (needs the ``tensorboard`` package).
    resume : bool
        Continue the run in ``out_dir`` from its latest checkpoint up to
        ``config.timesteps`` decisions (its ``config.json`` must match ``config`` except
        for ``timesteps``). A checkpoint that does not load (a torn or foreign file) is
        skipped for the next older one; each skipped one is printed to stderr with the
        reason and listed in the result's ``skipped_checkpoints``.

    Returns
    -------
    dict
        Paths, duration, decisions per second while the policy trained, episodes seen,
        and the success rate and mean stop error of the last 50 training episodes.

    Raises
    ------
    ValueError
        A bad name, a folder that holds a run (without ``resume``), or a run that cannot
        be resumed (no ``config.json``, other settings, no checkpoint that loads).
    """
    out = Path(out_dir)
    _check_start(config, tensorboard_log)
    if resume:
        start = resume_state(out, config)
        if start.checkpoint is None:
            tried = "; ".join(f"{p.name}: {why}" for p, why in start.skipped)
            raise ValueError(
                f"{out}: no checkpoint to resume from (train with --save-freq N)"
                if not tried
                else f"{out}: no checkpoint loads ({tried})"
            )
    else:
        check_new_run_dir(out)
        start = RunStart(config)
    return _train(start, out, progress, tensorboard_log)


def continue_run(
    config: TrainConfig, out_dir: str | os.PathLike, progress: bool = False
) -> dict[str, Any]:
    """Train ``config`` in ``out_dir``, going on from what an earlier attempt of the same
    run left there (a sweep's job run again after an interruption or a failure).

    A folder without a run: a new run. A run of the same settings (its ``config.json``
    equals ``config``, a measured goal aside): resumed from its latest checkpoint that
    loads, or, without one, trained again from the start in the same folder (its atlases
    and measured goal are kept). Any other run there is refused.

    Raises
    ------
    ValueError
        Naming the folder: it holds another run (or files of one without its
        ``config.json``).
    """
    out = Path(out_dir)
    _check_start(config, None)
    if not run_files(out):
        return _train(RunStart(config), out, progress, None)
    if not (out / "config.json").is_file():
        raise ValueError(
            f"{out}: holds files of a training run ({', '.join(run_files(out))}) but no "
            "config.json: not a run of these settings; remove it or choose another --out"
        )
    return _train(resume_state(out, config), out, progress, None)


def _train(
    start: RunStart,
    out: Path,
    progress: bool,
    tensorboard_log: str | os.PathLike | None,
) -> dict[str, Any]:
    """The run itself (:func:`train`), once the folder is checked."""
    import torch
    from stable_baselines3.common.callbacks import CallbackList
    from stable_baselines3.common.logger import Logger
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from vc_gym.training.async_rollouts import AsyncRolloutPPO, AsyncSubprocVecEnv
    from vc_gym.training.callbacks import (
        AtomicCheckpoint,
        EpisodeLog,
        HeldOutEvaluation,
    )

    config, checkpoint, episodes = start.config, start.checkpoint, start.episodes
    resume = checkpoint is not None
    algo = algorithm_class(config.algo)
    warm_start: dict[str, Any] | None = None
    offset: dict[str, Any] | None = None
    out = check_out_dir(out)
    write_json(out / "config.json", config.to_dict())
    t0 = time.perf_counter()
    if progress:
        seeds = ", ".join(map(str, config.place_seeds))
        print(f"learning each place once ({config.scene}, learning seeds {seeds}) -> {out}")
    learn_places(config, out)
    if config.home_offset_m is None and config.home_offset_episodes:
        if progress:
            print(
                f"measuring the tracker's home: {config.home_offset_episodes} expert episodes "
                f"in each of {len(config.home_offset_seeds)} places"
            )
        config, offset = _measure_goal(config, out, progress)
    (out / "monitor").mkdir(exist_ok=True)
    factories = [
        EnvFactory(config, i, out, out / "monitor" / str(i), append=resume)
        for i in range(config.n_envs)
    ]
    algo_cls = AsyncRolloutPPO if config.collector == "async" else algo
    if config.vec_env == "subproc":
        # SB3's SubprocVecEnv whose workers can also run whole rollouts, and which closes
        # past a dead one (its error is then the one raised, not a BrokenPipeError)
        venv = AsyncSubprocVecEnv(factories, start_method="forkserver")
    else:
        venv = DummyVecEnv(factories)

    def write_log(eps: list[dict[str, Any]]) -> None:
        write_json(out / "train_log.json", {"running": True, "per_episode": eps})

    log = EpisodeLog(config.timesteps, episodes, write_log, f"train {config.algo}", progress)
    callbacks: list[Any] = [log]
    eval_env = None
    if config.eval_freq:
        # the training env (same places, same rules), kidnapped from held-out seeds
        eval_env = DummyVecEnv([lambda: Monitor(training_env(config, out))])
        callbacks.append(
            HeldOutEvaluation(
                eval_env,
                seed=config.eval_seed,
                at_start=bool(config.demo_episodes) and checkpoint is None,
                n_eval_episodes=config.eval_episodes,
                eval_freq=max(1, config.eval_freq // config.n_envs),
                best_model_save_path=str(out / "best"),
                log_path=str(out / "eval"),
                deterministic=True,
                verbose=0,
            )
        )
    if config.save_freq:
        callbacks.append(
            AtomicCheckpoint(
                max(1, config.save_freq // config.n_envs),
                out / "checkpoints",
                CHECKPOINT_PREFIX,
                # the log of the episodes so far with each checkpoint (after it: EpisodeLog
                # runs first), so that a run stopped here resumes with them
                on_save=lambda: write_log(episodes),
            )
        )
    # the policy is a small MLP: one torch thread is as fast, and a second one would
    # take a core from the env workers
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    tb = None if tensorboard_log is None else str(tensorboard_log)  # a str: plain JSON in the zip
    try:
        if checkpoint is not None:
            model = load_sb3_model(config.algo, checkpoint, env=venv, device="cpu", cls=algo_cls)
            if tb is not None:
                model.tensorboard_log = tb
        else:
            model = algo_cls("MlpPolicy", venv, tensorboard_log=tb, **_algo_kwargs(config))
            if config.demo_episodes:
                warm_start = _warm_start(model, venv, config, progress)
                write_json(out / "warm_start.json", warm_start)
        if tb is None:
            # without it SB3 makes an empty /tmp/SB3-<date> folder at every learn()
            model.set_logger(Logger(folder=None, output_formats=[]))
        with warnings.catch_warnings():
            # evaluation runs in this process (DummyVecEnv) on purpose
            warnings.filterwarnings("ignore", "Training and eval env are not of the same type")
            model.learn(
                total_timesteps=max(0, config.timesteps - model.num_timesteps),
                callback=CallbackList(callbacks),
                reset_num_timesteps=checkpoint is None,
                tb_log_name=config.algo,
            )
    finally:
        torch.set_num_threads(threads)
        venv.close()
        if eval_env is not None:
            eval_env.close()
    model_path = out / "model.zip"
    save_reproducible_model(model, model_path)  # the same run gives the same bytes
    recent = episodes[-50:]
    rate, task_rate = log.decisions_per_s, log.task_steps_per_s
    summary = {
        "model": str(model_path),
        "config": config.to_dict(),
        "duration_s": round(time.perf_counter() - t0, 1),
        # agent decisions per second while the policy trained (no learning phase, no
        # worker start-up): what `vc-gym bench train` compares with the env's own speed
        "decisions_per_s": None if rate is None else round(rate, 2),
        "task_steps_per_s": None if task_rate is None else round(task_rate, 2),
        "episodes": len(episodes),
        "resumed_from": None if checkpoint is None else str(checkpoint),
        "skipped_checkpoints": [{"checkpoint": str(p), "error": why} for p, why in start.skipped],
        "warm_start": warm_start,
        "home_offset": offset,
        "best_model": str(out / "best" / "best_model.zip")
        if (out / "best" / "best_model.zip").is_file()
        else None,
        "recent_success_rate": float(np.mean([e["success"] for e in recent])) if recent else None,
        "recent_mean_stop_error_m": float(np.nanmean([e["stop_error_m"] for e in recent]))
        if recent
        else None,
    }
    write_json(out / "train_log.json", {**summary, "per_episode": episodes})
    if episodes:
        _plot_curve(out / "learning_curve.png", episodes, config)
    return summary


def _measure_goal(
    config: TrainConfig, out: Path, progress: bool
) -> tuple[TrainConfig, dict[str, Any]]:
    """Measure the run's goal correction (:mod:`.home_offset`) and keep it in the run
    folder (``home_offset.json``, ``config.json``); the config to train with."""
    files = {s: f for s, f in run_places(config, out)}
    envs = []  # each place going to its atlas' home; the extra ones learned here
    try:
        for s in config.home_offset_seeds:
            envs.append(place_env(config, s, files.get(s, out / f"home-offset-place{s}.npz")))
        seed = HOME_OFFSET_SEED + MAX_PLACES * config.seed
        measured = measure_home_offset(envs, config.home_offset_episodes, seed, progress=progress)
        if config.home_offset_centre:
            measured = centre_home_offset(
                envs, measured, config.home_offset_episodes, seed, progress=progress
            )
    finally:
        for env in envs:
            env.close()
    config = replace(config, home_offset_m=measured.offset_m)
    write_json(out / "home_offset.json", measured.to_dict())
    write_json(out / "config.json", config.to_dict())
    return config, measured.to_dict()


def _warm_start(model: Any, venv: Any, config: TrainConfig, progress: bool) -> dict[str, Any]:
    """Clone the scripted expert into ``model``'s policy (see :mod:`.imitation`)."""
    expert = HomingFeatureExpert(
        config.max_forward,
        config.max_turn_deg_s,
        previous_action=config.previous_action,
        max_speed_m_s=config.expert_speed_m_s,
    )
    demos = collect_demonstrations(venv, expert, config.demo_episodes, config.gamma, progress)
    fit = clone_behaviour(model.policy, demos, seed=config.seed)
    errors = [e["stop_error_m"] for e in demos.episodes]
    return {
        "demo_episodes": len(demos.episodes),
        "demo_decisions": len(demos.actions),
        "demo_success_rate": demos.success_rate,
        "demo_mean_stop_error_m": float(np.nanmean(errors)),
        **fit,
    }


def _algo_kwargs(config: TrainConfig) -> dict[str, Any]:
    kwargs: dict[str, Any] = {
        "learning_rate": config.learning_rate,
        "gamma": config.gamma,
        "batch_size": config.batch_size,
        "policy_kwargs": {"net_arch": list(config.net_arch), "log_std_init": config.log_std_init},
        "seed": config.seed,
        "verbose": 0,
        "device": "cpu",
    }
    if config.algo == "ppo":
        kwargs["n_steps"] = config.n_steps
    return kwargs



def _plot_curve(path: Path, episodes: list[dict[str, Any]], config: TrainConfig) -> None:
    t = np.array([e["timestep"] for e in episodes])
    ret = np.array([e["return"] for e in episodes])
    succ = np.array([e["success"] for e in episodes], float)
    err = np.array([e["stop_error_m"] for e in episodes])
    k = max(1, min(50, len(episodes) // 5))
    kernel = np.ones(k) / k

    def smooth(v):
        return np.convolve(v, kernel, mode="valid") if len(v) >= k else v

    ts = t[k - 1 :] if len(t) >= k else t
    fig = new_figure(figsize=(12, 3.5), layout="constrained")
    axes = fig.subplots(1, 3)
    axes[0].plot(t, ret, ".", ms=2, color="0.7")
    axes[0].plot(ts, smooth(ret), color="tab:blue")
    axes[0].set_ylabel("episode return")
    axes[1].plot(ts, smooth(succ), color="tab:green")
    axes[1].set_ylabel(f"success rate (≤ {config.success_radius_m} m, mean of {k})")
    axes[1].set_ylim(0, 1)
    axes[2].plot(t, err * 100, ".", ms=2, color="0.7")
    axes[2].plot(ts, smooth(np.nan_to_num(err, nan=np.nanmax(err))) * 100, color="tab:red")
    axes[2].set_ylabel("stop distance from home (cm)")
    for ax in axes:
        ax.set_xlabel("agent decisions")
    fig.suptitle(f"{config.algo.upper()} on vc_gym/LearnThenHome-v0 ({config.scene})")
    save_figure(fig, path, dpi=100)
