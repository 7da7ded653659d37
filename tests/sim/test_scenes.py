"""The simulated scenes build, look like closed, varied rooms, and are seeded."""

from __future__ import annotations

import math
import os

import gymnasium as gym
import numpy as np
import pybullet
import pytest
from pybullet_utils import bullet_client

from vc_gym.sim.scenes import SCENES, Scene, build_scene, scene_names

W, H, HFOV = 208, 160, 56.9
FOV_V = math.degrees(2.0 * math.atan(math.tan(math.radians(HFOV / 2.0)) * H / W))
ROBOT_RADIUS = 0.25
#: Scenes plain by design (as real houses are): some directions show only a painted wall.
PLAIN_SCENES = frozenset({"plain_house"})


def head_view(bc, scene: Scene, yaw_deg: float, eye=None, size=(W, H)) -> np.ndarray:
    """What a camera 0.3 m above the field centre sees at ``yaw_deg`` (pitch 0)."""
    if eye is None:
        fx0, fx1, fy0, fy1 = scene.field_bounds
        eye = ((fx0 + fx1) / 2.0, (fy0 + fy1) / 2.0, 0.3)
    a = math.radians(yaw_deg)
    target = (eye[0] + math.cos(a), eye[1] + math.sin(a), eye[2])
    view = bc.computeViewMatrix(eye, target, (0.0, 0.0, 1.0))
    w, h = size
    proj = bc.computeProjectionMatrixFOV(FOV_V, w / h, 0.02, 50.0)
    rgba = bc.getCameraImage(
        w,
        h,
        view,
        proj,
        renderer=bc.ER_TINY_RENDERER,
        shadow=0,
        lightDirection=list(scene.light_direction),
    )[2]
    return np.asarray(rgba, np.uint8).reshape(h, w, 4)[:, :, :3].copy()


def gap(box, field) -> float:
    """Distance between two axis-aligned rectangles (0 if they overlap)."""
    dx = max(box[0] - field[1], field[0] - box[1], 0.0)
    dy = max(box[2] - field[3], field[2] - box[3], 0.0)
    return math.hypot(dx, dy)


@pytest.mark.parametrize("name", scene_names())
def test_scene_builds_closed_and_varied(bc, name):
    scene = build_scene(bc, name)
    assert scene.name == name
    x0, x1, y0, y1 = scene.room_bounds
    fx0, fx1, fy0, fy1 = scene.field_bounds
    assert x0 < fx0 < fx1 < x1 and y0 < fy0 < fy1 < y1
    # the field is free: a robot placed anywhere on it touches no obstacle
    assert scene.obstacles
    assert min(gap(o, scene.field_bounds) for o in scene.obstacles) >= ROBOT_RADIUS - 0.06
    assert len(scene.body_ids) == len(set(scene.body_ids)) > 5
    assert bc.getNumBodies() == len(scene.body_ids)
    for body in scene.body_ids:
        assert bc.getVisualShapeData(body), f"body {body} has no visual shape"
    assert bc.getDynamicsInfo(scene.body_ids[0], -1)[1] == pytest.approx(1.0)  # floor
    assert set(scene.ceiling_ids) <= set(scene.body_ids)
    assert math.isclose(math.hypot(*scene.light_direction), 1.0, rel_tol=1e-9)
    assert scene.light_direction[2] > 0
    assert scene.background_rgb is None

    views = [head_view(bc, scene, yaw) for yaw in range(0, 360, 45)]
    for img in views:
        assert img.shape == (H, W, 3) and img.dtype == np.uint8
        # closed scene: every ray hits something (the renderer clears to pure white)
        assert not np.any(img.min(axis=2) == 255)
    spread = [img[: H // 2].std() for img in views]
    if name in PLAIN_SCENES:
        # plain by design: a direction may show little but a painted wall and a white
        # door, yet something is drawn there, and most directions show more
        assert min(spread) > 4.0, "nothing drawn above the horizon"
        assert sum(s > 15.0 for s in spread) >= 6, spread
    else:
        assert min(spread) > 15.0, "nothing to see above the horizon"
    # different content in different directions, above the horizon
    uppers = [v[: H // 2].astype(np.float64) for v in views]
    for i in range(len(uppers)):
        j = (i + 2) % len(uppers)
        assert np.abs(uppers[i] - uppers[j]).mean() > 10.0


@pytest.mark.parametrize("name", scene_names())
def test_randomised_scenes_are_seeded_and_canonical_ignores_rng(name):
    def render(seed, randomize):
        client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
        try:
            scene = build_scene(client, name, np.random.default_rng(seed), randomize=randomize)
            views = [head_view(client, scene, yaw, size=(104, 80)) for yaw in (30.0, 210.0)]
            return scene, views
        finally:
            client.disconnect()

    (sa, a), (sb, b), (sc, c) = render(1, True), render(1, True), render(2, True)
    assert sc != sa
    assert sa == sb
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    assert any(not np.array_equal(x, z) for x, z in zip(a, c, strict=True))
    (s1, canon1), (s2, canon2) = render(1, False), render(2, False)
    assert s1 == s2
    for x, y in zip(canon1, canon2, strict=True):
        np.testing.assert_array_equal(x, y)
    assert any(not np.array_equal(x, z) for x, z in zip(a, canon1, strict=True))


def test_randomised_layouts_keep_the_field_free(bc):
    for name in scene_names():
        for seed in range(4):
            bc.resetSimulation()
            scene = build_scene(bc, name, np.random.default_rng(seed), randomize=True)
            x0, x1, y0, y1 = scene.room_bounds
            fx0, fx1, fy0, fy1 = scene.field_bounds
            assert x0 < fx0 < fx1 < x1 and y0 < fy0 < fy1 < y1
            closest = min(gap(o, scene.field_bounds) for o in scene.obstacles)
            assert closest >= ROBOT_RADIUS - 0.06, (name, seed, closest)
            assert scene.light_direction[2] > 0


def test_round_poses_render_without_holes(bc):
    # eyes exactly at round positions and headings (45° steps) once made the tiny
    # renderer drop big floor triangles whose corners lay in the eye's plane
    for name in ("robolab", "outdoor_field"):
        bc.resetSimulation()
        scene = build_scene(bc, name)
        for eye in ((0.0, 0.0, 0.3), (1.0, 1.0, 0.3), (-1.0, 1.0, 0.25)):
            for yaw in (45.0, 135.0, 225.0, 315.0):
                img = head_view(bc, scene, yaw, eye=eye, size=(104, 80))
                assert not np.any(img.min(axis=2) == 255), (name, eye, yaw)
                assert np.mean(img.max(axis=2) == 0) < 0.01, (name, eye, yaw)


def test_rebuild_after_reset_simulation(bc, private_tmp):
    first = None
    for _ in range(3):
        bc.resetSimulation()
        scene = build_scene(bc, "robolab")
        img = head_view(bc, scene, 0.0)
        if first is None:
            first = img
        np.testing.assert_array_equal(img, first)
    assert bc.getNumBodies() == len(scene.body_ids)
    # texture files and their folder are removed as soon as PyBullet has read them
    assert os.listdir(private_tmp) == []


def test_builtin_scenes_are_registered_first_in_order():
    assert SCENES == ("robolab", "office", "home", "outdoor_field", "plain_house")
    assert scene_names()[: len(SCENES)] == SCENES


def test_bad_arguments(bc):
    with pytest.raises(ValueError, match="robolab, office, home, outdoor_field, plain_house"):
        build_scene(bc, "moon")
    with pytest.raises(ValueError, match="register_scene"):
        build_scene(bc, "moon")
    with pytest.raises(ValueError, match="robolab"):
        build_scene(bc, None)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="Generator"):
        build_scene(bc, "robolab", rng=42, randomize=True)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="Generator"):
        build_scene(bc, "robolab", rng=np.random.RandomState(0))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="rng"):
        build_scene(bc, "office", randomize=True)
    with pytest.raises(ValueError, match="bool"):
        build_scene(bc, "office", np.random.default_rng(0), randomize="yes")  # type: ignore[arg-type]
    assert bc.getNumBodies() == 0


def test_making_and_closing_envs_keeps_no_python_memory():
    # pybullet keeps every list given as a mesh's vertices, uvs, normals or indices:
    # unless they are freed, each make/reset/close cycle leaves ~20 KB of them behind
    import gc
    import tracemalloc

    def cycle(seed):
        env = gym.make("vc_gym/AiboRoom-v0")
        env.reset(seed=seed)
        env.step(env.action_space.sample())
        env.close()

    for k in range(3):
        cycle(k)
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.take_snapshot()
    for k in range(10):
        cycle(k)
    gc.collect()
    grown = sum(s.size_diff for s in tracemalloc.take_snapshot().compare_to(before, "filename"))
    tracemalloc.stop()
    assert grown / 10 < 2048, f"{grown / 10:.0f} bytes of Python objects kept per cycle"
