"""A learning phase kept in a file: learned by the first env, loaded by the others."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import vc_gym  # noqa: F401
from vc_gym.envs.atlas_file import AtlasFile
from vc_gym.errors import MapFileError
from vc_gym.sim import HeadCameraSpec

FAST = {"learn_time_s": 0.2, "camera": HeadCameraSpec(52, 40, 56.9)}
STEPS = [np.array([0.6, 0.0, 0.3, 0.5, 0.0], np.float32)] * 5


def episode(env, seed):
    obs, info = env.reset(seed=seed)
    poses = [info["pose"]]
    images = [obs["image"]]
    for a in STEPS:
        obs, _, _, _, info = env.step(a)
        poses.append(info["pose"])
        images.append(obs["image"])
    return np.array(poses), np.array(images)


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """The file learned by one env (reset seed 5), and that env's first episode."""
    path = tmp_path_factory.mktemp("atlas") / "place.npz"
    env = gym.make("vc_gym/LearnThenHome-v0", atlas_file=path, learning_seed=0, **FAST)
    first = episode(env, seed=5)
    assert env.unwrapped.learner.learned and path.is_file()
    atlas = env.unwrapped.atlas
    env.close()
    return path, first, atlas


def test_the_first_env_learns_and_the_others_load(shared):
    path, _, learned = shared
    env = gym.make("vc_gym/LearnThenHome-v0", atlas_file=path, learning_seed=0, **FAST)
    env.reset(seed=11)  # another reset seed: the same place, loaded
    assert not env.unwrapped.learner.learned
    loaded = env.unwrapped.atlas
    assert loaded.names == learned.names
    np.testing.assert_array_equal(loaded.positions, learned.positions)
    for a, b in zip(loaded.compasses, learned.compasses, strict=True):
        np.testing.assert_array_equal(a._log_tables()[0], b._log_tables()[0])
    env.close()


def test_episodes_do_not_depend_on_who_learned_the_atlas(shared):
    path, (poses, images), _ = shared
    env = gym.make("vc_gym/LearnThenHome-v0", atlas_file=path, learning_seed=0, **FAST)
    poses2, images2 = episode(env, seed=5)
    env.close()
    np.testing.assert_array_equal(poses2, poses)
    np.testing.assert_array_equal(images2, images)


def test_a_missing_file_is_written_from_the_place_cache(shared, tmp_path):
    _, (poses, images), learned = shared  # its place went to the session's place cache too
    path = tmp_path / "copy.npz"
    env = gym.make("vc_gym/LearnThenHome-v0", atlas_file=path, learning_seed=0, **FAST)
    poses2, images2 = episode(env, seed=5)
    assert env.unwrapped.cached_learner.learned is False  # loaded from the cache
    assert env.unwrapped.learner.learned and path.is_file()  # and written to the file
    env.close()
    np.testing.assert_array_equal(poses2, poses)
    np.testing.assert_array_equal(images2, images)
    off = gym.make(
        "vc_gym/LearnThenHome-v0", atlas_file=tmp_path / "own.npz", learning_seed=0,
        place_cache=False, **FAST,
    )  # fmt: skip
    assert off.unwrapped.place_cache is None
    off.close()


@pytest.mark.parametrize(
    "change", [{"learn_time_s": 0.3}, {"learning_seed": 4}, {"scene": "office"}]
)
def test_a_file_learned_otherwise_is_refused(shared, change):
    path, _, _ = shared
    kwargs = {**FAST, "learning_seed": 0, **change}
    env = gym.make("vc_gym/LearnThenHome-v0", atlas_file=path, **kwargs)
    with pytest.raises(MapFileError, match="learned with"):
        env.reset(seed=0)
    env.close()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"atlas_file": "place.txt"}, "npz"),
        ({"atlas_file": "/no/such/folder/place.npz"}, "folder"),
        ({"atlas_file": "place.npz", "learning": "agent"}, "scripted"),
        ({"atlas_file": "place.npz", "randomize": True}, "randomised"),
        ({"learning_seed": -1}, "learning_seed"),
        ({"learning_seed": 1.5}, "learning_seed"),
    ],
)
def test_bad_atlas_file_arguments(tmp_path, monkeypatch, kwargs, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=message):
        gym.make("vc_gym/LearnThenHome-v0", **kwargs)


def test_a_learner_that_returns_the_wrong_type_writes_nothing(tmp_path):
    f = AtlasFile(tmp_path / "a.npz", lambda room, config: "not a result", {"x": 1})
    assert f(None, None) == "not a result"
    assert not (tmp_path / "a.npz").exists()
