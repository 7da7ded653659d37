"""The place cache: a learned place is learned once, by the first env, and loaded by every
later one with the same episodes."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import vc_gym
from vc_gym.compass import CompassConfig
from vc_gym.envs.learning import LearningConfig, LearningResult
from vc_gym.envs.place_cache import (
    CachedLearner,
    PlaceCache,
    default_cache_dir,
    place_key_value,
)
from vc_gym.errors import MapFileError
from vc_gym.sim.head_camera import HeadCameraSpec

SMALL = HeadCameraSpec(52, 40, 56.9)
FAST = {"learn_time_s": 0.2, "max_homing_s": 2.0, "camera": SMALL}
STEPS = [np.array([0.6, 0.0, 0.3, 0.5, 0.0], np.float32)] * 6


def episode(env, seed):
    """Observations, rewards and poses of one episode with fixed actions."""
    obs, info = env.reset(seed=seed)
    frames, rewards, poses = [obs["image"]], [], [info["pose"]]
    for a in STEPS:
        obs, r, _, _, info = env.step(a)
        frames.append(obs["image"])
        rewards.append(r)
        poses.append(info["pose"])
    return np.array(frames), np.array(rewards), np.array(poses)


def test_tests_never_touch_the_users_cache(place_cache_dir):
    assert default_cache_dir() == place_cache_dir
    assert Path.home() not in place_cache_dir.parents


def test_the_default_folder(monkeypatch, tmp_path):
    monkeypatch.setenv("VC_GYM_CACHE", str(tmp_path / "mine"))
    assert default_cache_dir() == tmp_path / "mine"
    monkeypatch.delenv("VC_GYM_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_cache_dir() == tmp_path / "xdg" / "vc_gym" / "places"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "vc_gym" / "places"


def test_keys_name_everything_that_shapes_the_place(tmp_path):
    cache = PlaceCache(tmp_path)
    base = {
        "scene": "robolab",
        "learning": LearningConfig(learn_time_s=0.2),
        "learning_seed": 3,
        "room": {"camera": SMALL},
    }
    path = cache.path_for(base)
    assert path == PlaceCache(tmp_path).path_for(dict(reversed(base.items())))
    assert path.parent == tmp_path and path.suffix == ".npz" and len(path.stem) == 32
    changes = [
        {"scene": "office"},
        {"learning": LearningConfig(learn_time_s=0.3)},
        {"learning": LearningConfig(learn_time_s=0.2, compass=CompassConfig(n_colors=3))},
        {"learning_seed": 4},
        {"room": {"camera": HeadCameraSpec(52, 40, 60.0)}},
    ]
    others = {cache.path_for({**base, **c}) for c in changes}
    assert path not in others and len(others) == len(changes)
    key = cache.full_key(base)
    assert key["vc_gym"] == vc_gym.__version__
    assert {"place_cache_schema", "atlas_schema_version"} <= set(key)


def test_key_values_are_plain_data():
    assert place_key_value((1, 0.5, np.float32(0.25), None, "x", True)) == [
        1,
        "0.5",
        "0.25",
        None,
        "x",
        True,
    ]
    assert place_key_value(-0.0) != place_key_value(0.0)
    with pytest.raises(TypeError, match="cannot key"):
        place_key_value(object())
    with pytest.raises(TypeError, match="cannot key"):
        place_key_value({"learner": lambda room, config: None})


def test_bad_cache_arguments(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="is a file"):
        PlaceCache(tmp_path / "file")
    with pytest.raises(ValueError, match="must be a path"):
        PlaceCache(3)
    with pytest.raises(ValueError, match="place_cache"):
        gym.make("vc_gym/LearnThenHome-v0", place_cache=3, **FAST)


@pytest.fixture(scope="module")
def learned(tmp_path_factory):
    """One env learns the place into a fresh cache; its episode and files."""
    folder = tmp_path_factory.mktemp("places")
    work = tmp_path_factory.mktemp("work")
    here = os.getcwd()
    os.chdir(work)
    try:
        env = gym.make("vc_gym/LearnThenHome-v0", place_cache=folder, **FAST)
        first = episode(env, seed=5)
        learned_it = env.unwrapped.cached_learner.learned
        atlas = env.unwrapped.atlas
        env.close()
    finally:
        os.chdir(here)
    return folder, work, first, learned_it, atlas


def test_the_first_env_learns_and_writes_the_place_into_the_cache(learned):
    folder, work, _, learned_it, _ = learned
    assert learned_it
    (place,) = PlaceCache(folder).places()
    assert place.with_name(place.name + ".lock").is_file()  # beside the map
    assert list(work.iterdir()) == []  # nothing in the working folder


def test_a_cached_place_gives_the_same_episodes_as_a_learned_one(learned):
    folder, _, (frames, rewards, poses), _, atlas = learned
    cached = gym.make("vc_gym/LearnThenHome-v0", place_cache=folder, **FAST)
    frames2, rewards2, poses2 = episode(cached, seed=5)
    assert cached.unwrapped.cached_learner.learned is False
    loaded = cached.unwrapped.atlas
    for a, b in zip(loaded.compasses, atlas.compasses, strict=True):
        np.testing.assert_array_equal(a._log_tables()[0], b._log_tables()[0])
    cached.close()
    np.testing.assert_array_equal(frames2, frames)
    np.testing.assert_array_equal(rewards2, rewards)
    np.testing.assert_array_equal(poses2, poses)
    # and the same as without a cache, where the place is learned in the env
    plain = gym.make("vc_gym/LearnThenHome-v0", place_cache=False, **FAST)
    frames3, rewards3, poses3 = episode(plain, seed=5)
    assert plain.unwrapped.place_cache is None and plain.unwrapped.cached_learner is None
    plain.close()
    np.testing.assert_array_equal(frames3, frames)
    np.testing.assert_array_equal(rewards3, rewards)
    np.testing.assert_array_equal(poses3, poses)


def test_homing_shares_the_place_of_the_task(learned):
    folder = learned[0]
    env = gym.make("vc_gym/Homing-v0", place_cache=folder, **FAST)
    env.reset(seed=5)  # the same learning settings and seed: loaded
    assert env.unwrapped.cached_learner.learned is False
    env.close()
    assert len(PlaceCache(folder).places()) == 1


def test_a_vector_env_learns_a_shared_place_once(tmp_path):
    vec = gym.make_vec(
        "vc_gym/Homing-v0",
        num_envs=2,
        vectorization_mode="sync",
        place_cache=tmp_path,
        learning_seed=0,
        **FAST,
    )
    vec.reset(seed=[1, 2])
    sources = [e.unwrapped.cached_learner.learned for e in vec.envs]
    vec.close()
    assert sorted(sources) == [False, True]
    assert len(PlaceCache(tmp_path).places()) == 1


def test_an_unknown_learning_seed_is_not_cached(tmp_path):
    env = gym.make("vc_gym/LearnThenHome-v0", place_cache=tmp_path, **FAST)
    env.reset()  # seeded from the OS: no later env would ask for this place
    assert env.unwrapped.cached_learner is None
    env.close()
    assert PlaceCache(tmp_path).places() == []


def test_a_cold_cache_shows_progress_on_stderr(tmp_path, capfd):
    env = gym.make("vc_gym/LearnThenHome-v0", place_cache=tmp_path, **FAST)
    env.reset(seed=0)
    assert "learn 4 spots" in capfd.readouterr().err
    env.close()
    env = gym.make("vc_gym/LearnThenHome-v0", place_cache=tmp_path, **FAST)
    env.reset(seed=0)
    assert "learn 4 spots" not in capfd.readouterr().err
    env.close()


# ---------------------------------------------------------------- the cache on its own
class _Room:
    """What a learner and the cache need of the room: its generator."""

    def __init__(self, seed: int = 0):
        self.np_random = np.random.default_rng(seed)


def _counting_learner(atlas, calls: list):
    def learner(room, config):
        calls.append(1)
        room.np_random.integers(10, size=7)  # learning moves the generator on
        return LearningResult(atlas, {n: (1.0, 2.0) for n in atlas.names}, [(0.0, 0.0, 1.0)])

    return learner


def test_envs_that_need_a_place_at_once_learn_it_once(tmp_path, room_atlas):
    calls: list = []
    cache = PlaceCache(tmp_path)

    def learn(results: list, room: _Room) -> None:
        r = cache.learner(_counting_learner(room_atlas, calls), {"k": 1}, progress=False)
        results.append((r(room, LearningConfig()), r.learned))

    results: list = []
    rooms = [_Room(), _Room()]
    threads = [threading.Thread(target=learn, args=(results, room)) for room in rooms]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert len(calls) == 1 and sorted(learned for _, learned in results) == [False, True]
    # the room that loaded the place continues with the generator the learning left
    assert rooms[0].np_random.integers(2**31) == rooms[1].np_random.integers(2**31)
    loaded = next(r for r, learned in results if not learned)
    assert loaded.spots == {n: (1.0, 2.0) for n in room_atlas.names}
    assert loaded.true_path == [(0.0, 0.0, 1.0)]


@pytest.mark.parametrize("damage", ["garbage", "empty", "other place"])
def test_a_damaged_cache_file_is_reported_and_learned_again(tmp_path, room_atlas, damage):
    calls: list = []
    cache = PlaceCache(tmp_path)
    first = cache.learner(_counting_learner(room_atlas, calls), {"k": 1}, progress=False)
    first(_Room(), LearningConfig())
    if damage == "garbage":
        first.path.write_bytes(b"PK\x03\x04 not a zip")
    elif damage == "empty":
        first.path.write_bytes(b"")
    else:  # a valid file of another key under this key's name
        other = cache.learner(_counting_learner(room_atlas, calls), {"k": 2}, progress=False)
        other(_Room(), LearningConfig())
        other.path.replace(first.path)
    again = cache.learner(_counting_learner(room_atlas, calls), {"k": 1}, progress=False)
    with pytest.warns(RuntimeWarning, match="cannot be used"):
        again(_Room(), LearningConfig())
    assert again.learned
    again = cache.learner(_counting_learner(room_atlas, calls), {"k": 1}, progress=False)
    again(_Room(), LearningConfig())
    assert not again.learned  # the new file is sound


def test_a_saved_generator_state_of_another_kind_is_refused(tmp_path, room_atlas):
    from vc_gym.envs import place_cache

    calls: list = []
    learner = CachedLearner(PlaceCache(tmp_path), _counting_learner(room_atlas, calls), {"k": 1})
    learner.progress = False
    learner(_Room(), LearningConfig())
    room = _Room()
    good = room.np_random.bit_generator.state
    for bad in (
        None,
        {**good, "bit_generator": "MT19937"},
        {**good, "state": {"state": -1, "inc": 1}},
        {**good, "state": {"state": 2**200, "inc": 1}},
        {**good, "has_uint32": True},
    ):
        with pytest.raises(MapFileError, match="room_generator"):
            place_cache._restore_generator(room, bad, learner.path)
    assert room.np_random.bit_generator.state == good


def test_clear_deletes_the_cached_places_only(tmp_path, room_atlas):
    calls: list = []
    cache = PlaceCache(tmp_path)
    for k in (1, 2):
        cache.learner(_counting_learner(room_atlas, calls), {"k": k}, progress=False)(
            _Room(), LearningConfig()
        )
    (tmp_path / "notes.txt").write_text("keep me")
    assert len(cache.places()) == 2
    assert cache.clear() == 2
    assert cache.places() == [] and sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    assert PlaceCache(tmp_path / "missing").clear() == 0
