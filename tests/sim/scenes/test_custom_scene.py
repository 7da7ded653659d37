"""A user's own scene, defined here (not in the package): built, rendered, used by the envs."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.sim import textures
from vc_gym.sim.head_camera import HeadCameraSpec, render_camera
from vc_gym.sim.scenes import (
    Builder,
    Room,
    SceneLayout,
    build_scene,
    register_scene,
    scene_names,
    unregister_scene,
)
from vc_gym.sim.scenes.furniture import ceiling_texture, sun

#: Name the test scene is registered under.
BOX_ROOM = "test_box_room"
#: Wall paint: east (seen looking along +x) red, north green, west blue, south yellow.
WALL_RGB = {"E": (210, 30, 30), "N": (30, 170, 50), "W": (30, 60, 210), "S": (230, 210, 30)}
#: Which wall the camera at the field centre sees, by heading.
FACING = {0.0: "E", 90.0: "N", 180.0: "W", 270.0: "S"}
BOUNDS = (-2.5, 2.5, -2.0, 2.0)
FIELD = (-1.5, 1.5, -1.2, 1.2)


def box_room(b: Builder) -> SceneLayout:
    """A 5 x 4 m room with four plainly coloured walls and a poster on the north wall.

    Large enough for LearnThenHome's learning spots 1 m around home (the origin).
    """
    room = Room(b, BOUNDS, 2.4, {s: b.choices.color(rgb, dh=0.02) for s, rgb in WALL_RGB.items()})
    poster = textures.procedural_poster(b.rng, (96, 64), "blocks")
    north = room.walls["N"]  # u from the west end (x = -2.5) eastwards
    north.canvas.framed(3.7, 4.3, 0.5, 1.4, poster, (25, 25, 25), 0.04)
    north.take(3.7, 4.3, 0.5, 1.4)
    floor = textures.Canvas(5.0, 4.0, 40.0, (110, 105, 100))
    floor.mottle(b.rng, 0.05, 0.5)
    room.build(floor.image(), ceiling_texture(b, BOUNDS, panels=False))
    return SceneLayout(BOUNDS, FIELD, sun(b, (0.3, -0.4, 0.85)))


@pytest.fixture
def box_room_name():
    """:func:`box_room` registered for one test only."""
    assert BOX_ROOM not in scene_names()
    register_scene(BOX_ROOM, canonical_seed=11)(box_room)
    try:
        yield BOX_ROOM
    finally:
        unregister_scene(BOX_ROOM)


def wall_seen(image: np.ndarray) -> str:
    """The wall whose paint is closest in chromaticity to the image's upper middle."""
    h, w = image.shape[:2]
    mean = image[h // 8 : h // 2, w // 4 : 3 * w // 4].reshape(-1, 3).mean(axis=0)
    chroma = mean / max(float(mean.sum()), 1.0)

    def distance(side: str) -> float:
        paint = np.asarray(WALL_RGB[side], np.float64)
        return float(np.abs(chroma - paint / paint.sum()).sum())

    return min(WALL_RGB, key=distance)


def test_custom_scene_builds_and_shows_its_walls(bc, box_room_name):
    scene = build_scene(bc, box_room_name)
    assert scene.name == box_room_name
    assert scene.room_bounds == BOUNDS and scene.field_bounds == FIELD
    assert len(scene.obstacles) == 4  # the walls
    assert len(scene.body_ids) == 6 and len(scene.ceiling_ids) == 1
    assert math.isclose(math.hypot(*scene.light_direction), 1.0)
    spec = HeadCameraSpec()  # the Aibo's 208 x 160
    for yaw, side in FACING.items():
        img = render_camera(
            bc, spec, (0.0, 0.0, 0.3), yaw, 0.0, light_direction=scene.light_direction
        )
        assert img.shape == (160, 208, 3)
        assert not np.any(img.min(axis=2) == 255), "the room is closed"
        assert wall_seen(img) == side, (yaw, img[:80].reshape(-1, 3).mean(axis=0))
    # canonical: the same for any rng; randomised: seeded
    bc.resetSimulation()
    again = build_scene(bc, box_room_name, np.random.default_rng(99))
    img_a = render_camera(
        bc, spec, (0.0, 0.0, 0.3), 90.0, 0.0, light_direction=again.light_direction
    )
    bc.resetSimulation()
    build_scene(bc, box_room_name)
    img_b = render_camera(
        bc, spec, (0.0, 0.0, 0.3), 90.0, 0.0, light_direction=again.light_direction
    )
    np.testing.assert_array_equal(img_a, img_b)
    bc.resetSimulation()
    rand = build_scene(bc, box_room_name, np.random.default_rng(1), randomize=True)
    assert rand.light_direction != scene.light_direction


def test_custom_scene_in_aibo_room_env(box_room_name):
    env = gym.make("vc_gym/AiboRoom-v0", scene=box_room_name)
    try:
        obs, info = env.reset(seed=0, options={"pose": (0.0, 0.0, 180.0)})
        assert info["scene"] == box_room_name
        assert env.unwrapped.scene.room_bounds == BOUNDS
        assert wall_seen(obs["image"]) == "W"
        rng = np.random.default_rng(0)
        for _ in range(5):
            action = rng.uniform(-0.5, 0.5, 5).astype(np.float32)
            obs, reward, terminated, truncated, info = env.step(action)
            assert obs["image"].shape == (160, 208, 3) and not terminated
        x0, x1, y0, y1 = BOUNDS
        x, y, _ = info["pose"]
        assert x0 < x < x1 and y0 < y < y1
        # a fresh reset draws a start pose on the custom scene's field
        _, info = env.reset(seed=3)
        fx0, fx1, fy0, fy1 = FIELD
        assert fx0 <= info["pose"][0] <= fx1 and fy0 <= info["pose"][1] <= fy1
    finally:
        env.close()


def test_custom_scene_passes_the_env_checker(box_room_name):
    env = gym.make(
        "vc_gym/AiboRoom-v0",
        scene=box_room_name,
        camera=HeadCameraSpec(52, 40, 56.9),
    )
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    env.close()
    # SB3 prefers channel-first images; Gymnasium's convention (and ours) is HxWxC
    unexpected = [
        str(w.message)
        for w in record
        if "channel" not in str(w.message) and "pkg_resources" not in str(w.message)
    ]
    assert not unexpected, unexpected


def test_unregistered_scene_is_refused_by_the_env():
    with pytest.raises(ValueError, match="unknown scene 'test_box_room'.*robolab"):
        gym.make("vc_gym/AiboRoom-v0", scene=BOX_ROOM)


def test_custom_scene_in_learn_then_home(box_room_name):
    env = gym.make(
        "vc_gym/LearnThenHome-v0",
        scene=box_room_name,
        learn_time_s=0.2,
        max_homing_s=2.0,
        camera=HeadCameraSpec(52, 40, 56.9),  # small frames keep the learning phase quick
    )
    try:
        obs, info = env.reset(seed=0)
        assert info["scene"] == box_room_name
        zero = np.zeros(env.action_space.shape, env.action_space.dtype)
        for _ in range(200):  # 2 s of homing at 0.1 s a step ends it long before
            obs, reward, terminated, truncated, info = env.step(zero)
            if terminated or truncated:
                break
        assert terminated or truncated
        assert "stop_error_m" in info
    finally:
        env.close()


def test_cli_renders_a_registered_scene(box_room_name, tmp_path, capsys):
    from vc_gym.cli import main

    assert main(["render", "--scene", box_room_name, "--out", str(tmp_path)]) == 0
    for kind in ("top", "strip"):
        png = (tmp_path / f"{box_room_name}_{kind}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert box_room_name in capsys.readouterr().out


@pytest.mark.parametrize("command", ["render", "train"])
def test_cli_refuses_an_unknown_scene_before_any_work(command, tmp_path, capsys, monkeypatch):
    from vc_gym import cli

    def no_work(args):  # pragma: no cover - must not run
        raise AssertionError("the command ran")

    monkeypatch.setattr(getattr(cli, command), "run", no_work)
    with pytest.raises(SystemExit) as e:
        cli.main([command, "--scene", BOX_ROOM, "--out", str(tmp_path)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"invalid choice: '{BOX_ROOM}'" in err
    assert "'robolab', 'office', 'home', 'outdoor_field', 'plain_house'" in err
    assert list(tmp_path.iterdir()) == []
