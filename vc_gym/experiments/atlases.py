"""Learned atlases, saved once per (scene, seed, learning config) and shared by every job.

The learning phase is the expensive part of the task (~40 s for four spots). An
experiment names the atlases it needs as *atlas specs* (plain dicts: scene, seed,
learner, learning time, compass config, room options); :func:`ensure_atlases` learns each
missing one as a job of the run (``DIR/atlases/<key>.npz``) or copies it from a folder
of saved ones (``--atlas DIR``), and the jobs that use an atlas load it from its file
with :class:`SavedAtlas` as the task's learner. A job thus depends on its own seed and
the saved atlas only.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym

from vc_gym.compass import CompassAtlas, CompassConfig
from vc_gym.envs.atlas_file import SavedAtlas
from vc_gym.envs.learning import GridLearning, LearningConfig, SpotLearning
from vc_gym.errors import MapFileError
from vc_gym.jobs.job import Job
from vc_gym.jobs.run import ExperimentRun
from vc_gym.persistence import write_atomic

__all__ = ["SavedAtlas", "atlas_key", "atlas_spec", "ensure_atlases", "learn_atlas_job"]

LEARNERS = ("scripted", "spot", "grid")


#: The learning options of ``vc_gym/LearnThenHome-v0`` an atlas spec may set.
LEARNING_OPTIONS = ("normalise_at", "around_m", "landmarks")


def atlas_spec(
    scene: str = "robolab",
    seed: int = 0,
    learner: str = "scripted",
    learn_time_s: float = 5.0,
    compass: Mapping[str, Any] | None = None,
    spot: Sequence[float] | None = None,
    room: Mapping[str, Any] | None = None,
    learning: Mapping[str, Any] | None = None,
    spots: Sequence[Sequence[float]] | None = None,
    around_m: float = 0.0,
    keep_around: bool = False,
) -> dict[str, Any]:
    """What identifies a learned atlas (a JSON dict; see :func:`learn_atlas_job`).

    Parameters
    ----------
    scene : str
        Registered scene name.
    seed : int
        Seed of the learning phase (``LearnThenHome-v0.reset(seed=...)``).
    learner : str
        ``"scripted"``: the paper's four spots around home (5.2); ``"spot"``: one spot
        learned in a full turn at ``spot`` (5.1); ``"grid"``: that at every one of
        ``spots`` (:class:`~vc_gym.envs.learning.GridLearning`).
    learn_time_s : float
        Learning time per direction (paper: 5 s).
    compass : mapping, optional
        :class:`~vc_gym.compass.CompassConfig` fields that differ from the paper's.
    spot : (x, y), optional
        The spot of the ``"spot"`` learner.
    room : mapping, optional
        Extra ``vc_gym/AiboRoom-v0`` options while learning (e.g. ``illumination``).
    learning : mapping, optional
        Learning options of ``vc_gym/LearnThenHome-v0`` that differ from the paper's
        (:data:`LEARNING_OPTIONS`, e.g. ``{"normalise_at": "start"}``).
    spots : sequence of (x, y), optional
        The spots of the ``"grid"`` learner, the first one home.
    around_m : float
        The ``"grid"`` learner's extra turns around each spot (``GridLearning``'s
        ``around_m``; 0: none).
    keep_around : bool
        Keep those turns as atlas entries of their own (``GridLearning``'s
        ``keep_around``).
    """
    if learner not in LEARNERS:
        raise ValueError(f"learner must be one of {LEARNERS}, got {learner!r}")
    if (learner == "spot") != (spot is not None):
        raise ValueError("spot is needed by, and only by, the 'spot' learner")
    if (learner == "grid") != (spots is not None):
        raise ValueError("spots are needed by, and only by, the 'grid' learner")
    if (around_m or keep_around) and learner != "grid":
        raise ValueError("around_m and keep_around belong to the 'grid' learner")
    if spots is not None:
        grid = GridLearning(spots, around_m, keep_around=keep_around)
        spots, around_m = [[float(x), float(y)] for x, y in grid.spots], grid.around_m
    config = CompassConfig(**dict(compass or {}))  # validates the fields
    learning = dict(learning or {})
    unknown = set(learning) - set(LEARNING_OPTIONS)
    if unknown:
        raise ValueError(
            f"unknown learning options {sorted(unknown)}; known: {list(LEARNING_OPTIONS)}"
        )
    LearningConfig(learn_time_s=learn_time_s, compass=config, **learning)
    spec = {
        "scene": str(scene),
        "seed": int(seed),
        "learner": learner,
        "learn_time_s": float(learn_time_s),
        "compass": config.to_dict(),
        "room": dict(room or {}),
    }
    if spot is not None:
        spec["spot"] = [float(v) for v in spot]
    if spots is not None:
        spec["spots"] = spots
    if around_m:  # only when set, so that it changes no other grid spec's atlas key
        spec["around_m"] = float(around_m)
    if keep_around:  # likewise
        spec["keep_around"] = True
    if learning:  # only when set, so that it changes no paper spec's atlas key
        spec["learning"] = learning
    json.dumps(spec, allow_nan=False)  # JSON values only
    return spec


def atlas_key(spec: Mapping[str, Any]) -> str:
    """File-name key of an atlas spec: readable prefix + hash of the whole spec."""
    digest = hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:10]
    return f"{spec['scene']}-{spec['learner']}-seed{spec['seed']}-{digest}"


def _learner(spec: Mapping[str, Any]):
    if spec["learner"] == "spot":
        return SpotLearning(tuple(spec["spot"]))
    if spec["learner"] == "grid":
        return GridLearning(
            [tuple(p) for p in spec["spots"]],
            spec.get("around_m", 0.0),
            keep_around=bool(spec.get("keep_around", False)),
        )
    return None  # the task's default: the paper's scripted learning


def learn_atlas_job(spec: dict[str, Any], path: str) -> dict[str, Any]:
    """Job: run the learning phase of ``spec`` and save its atlas to ``path``.

    Returns the learning's figures (also kept in the atlas file's metadata).
    """
    env = gym.make(
        "vc_gym/LearnThenHome-v0",
        scene=spec["scene"],
        learn_time_s=spec["learn_time_s"],
        compass=CompassConfig(**spec["compass"]),
        **({"learner": _learner(spec)} if spec["learner"] != "scripted" else {}),
        **spec.get("learning", {}),
        **spec["room"],
    )
    try:
        env.reset(seed=spec["seed"])
        result = env.unwrapped.learning_result
    finally:
        env.close()
    figures = {
        "spots": {n: [round(v, 6) for v in p] for n, p in result.spots.items()},
        "odometry_turn_scale": float(result.odometry_turn_scale),
    }
    result.atlas.save(path, metadata={"spec": spec, **figures})
    return figures


def ensure_atlases(
    run: ExperimentRun,
    specs: Sequence[Mapping[str, Any]],
    source: str | os.PathLike | None = None,
) -> dict[str, str]:
    """Make sure every atlas in ``specs`` is saved in ``run.out / "atlases"``.

    An atlas already there (a resumed run) or in ``source`` (``--atlas DIR``: copied
    after checking it loads and was learned from the same spec) is reused; the others
    are learned as jobs of the run's ``learn`` stage.

    Returns
    -------
    dict
        ``{atlas_key: absolute path of the .npz}`` for every spec.
    """
    folder = run.out / "atlases"
    folder.mkdir(parents=True, exist_ok=True)
    paths: dict[str, str] = {}
    jobs = []
    for spec in specs:
        key = atlas_key(spec)
        if key in paths:
            continue
        path = (folder / f"{key}.npz").resolve()
        paths[key] = str(path)
        if path.is_file() and _matches(path, spec):
            continue
        if source is not None:
            src = Path(source) / f"{key}.npz"
            if src.is_file() and _matches(src, spec):
                write_atomic(path, lambda tmp, src=src: shutil.copyfile(src, tmp))
                continue
        run.job_file("learn", key).unlink(missing_ok=True)  # its atlas is gone: learn again
        kwargs = {"spec": dict(spec), "path": str(path)}
        jobs.append(Job(key, f"{__name__}:learn_atlas_job", kwargs))
    if jobs:
        run.run("learn", jobs)
        missing = [j.key for j in jobs if not Path(j.kwargs["path"]).is_file()]
        if missing:
            raise RuntimeError(
                f"learning failed for {missing}; see {folder.parent / 'jobs' / 'learn'} "
                "for the errors (rerun the same command to retry)"
            )
    return paths


def _matches(path: Path, spec: Mapping[str, Any]) -> bool:
    try:
        _, meta = CompassAtlas.load_with_metadata(path)
    except MapFileError:
        return False
    return meta.get("spec") == json.loads(json.dumps(spec))
