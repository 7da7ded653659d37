"""The plain_house scene: a real-size room, a free field, plain walls and bright windows."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.scenes import SCENES, build_scene, scene_names

MARGIN = 0.2  # least distance of furniture from the field (the scenes' rule)
H = 160


def _solid_boxes(bc, scene):
    """``(body, aabb)`` of every body with a collision shape, except the floor."""
    for body in scene.body_ids[1:]:
        if bc.getCollisionShapeData(body, -1):
            yield body, bc.getAABB(body)


def _gap(lo, hi, field) -> float:
    """Floor-plane distance between a body's AABB and the field rectangle."""
    fx0, fx1, fy0, fy1 = field
    dx = max(lo[0] - fx1, fx0 - hi[0], 0.0)
    dy = max(lo[1] - fy1, fy0 - hi[1], 0.0)
    return float(np.hypot(dx, dy))


def _view(bc, scene, eye, yaw_deg: float, w: int = 104, h: int = 80) -> np.ndarray:
    """A level pinhole view (45° vertical field of view) from ``eye`` at ``yaw_deg``."""
    a = math.radians(yaw_deg)
    target = (eye[0] + math.cos(a), eye[1] + math.sin(a), eye[2])
    view = bc.computeViewMatrix(eye, target, (0.0, 0.0, 1.0))
    proj = bc.computeProjectionMatrixFOV(45.0, w / h, 0.02, 50.0)
    rgba = bc.getCameraImage(
        w, h, view, proj, renderer=bc.ER_TINY_RENDERER, lightDirection=list(scene.light_direction)
    )[2]
    return np.asarray(rgba, np.uint8).reshape(h, w, 4)[:, :, :3]


def _turn(scene: str, pose=(0.0, 0.0)) -> list[np.ndarray]:
    """The head camera's frames every 45° at ``pose`` in the canonical ``scene``."""
    env = AiboRoomEnv(scene=scene)
    try:
        frames = []
        for yaw in range(0, 360, 45):
            obs, _ = env.reset(seed=0, options={"pose": (*pose, float(yaw))})
            frames.append(obs["image"].copy())
        return frames
    finally:
        env.close()


def _plainness(frames: list[np.ndarray]) -> tuple[float, float]:
    """Share of low-gradient pixels and of edge pixels above the horizon, over frames."""
    low, edges = [], []
    for img in frames:
        grey = cv2.cvtColor(img, cv2.COLOR_RGB2GRAY).astype(np.float32)
        gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3) / 8.0
        gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3) / 8.0
        low.append(float((np.hypot(gx, gy)[: H // 2] < 2.0).mean()))
        edges.append(float((cv2.Canny(img, 50, 150)[: H // 2] > 0).mean()))
    return float(np.mean(low)), float(np.mean(edges))


def test_is_a_registered_builtin_scene():
    assert "plain_house" in SCENES
    assert "plain_house" in scene_names()


def test_builds_a_real_size_room_with_a_field_like_home(bc):
    scene = build_scene(bc, "plain_house")
    x0, x1, y0, y1 = scene.room_bounds
    assert (x1 - x0, y1 - y0) == pytest.approx((5.5, 4.5))
    fx0, fx1, fy0, fy1 = scene.field_bounds
    assert (fx1 - fx0, fy1 - fy0) == pytest.approx((3.0, 2.4))
    assert fx0 < 0.0 < fx1 and fy0 < 0.0 < fy1  # home and the learning spots on it
    walls = [aabb for _, aabb in _solid_boxes(bc, scene) if aabb[1][2] - aabb[0][2] >= 2.4]
    heights = {round(hi[2], 3) for _, hi in walls}
    assert heights == {2.5}  # a 2.5 m ceiling
    # real-size furniture: a ~2 m sofa, a wardrobe ~2 m tall, a table at ~0.75 m
    sizes = [
        (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
        for _, (lo, hi) in _solid_boxes(bc, scene)
        if hi[2] - lo[2] < 2.4
    ]
    assert any(max(w, d) >= 1.8 and 0.8 <= h <= 1.0 for w, d, h in sizes)  # sofa
    assert any(1.9 <= h <= 2.2 and max(w, d) >= 1.0 for w, d, h in sizes)  # wardrobe
    assert any(0.7 <= h <= 0.8 and max(w, d) >= 1.0 for w, d, h in sizes)  # table


@pytest.mark.parametrize("seed", [None, *range(12)])
def test_nothing_solid_stands_in_or_near_the_field(bc, seed):
    rng = np.random.default_rng(seed)
    scene = build_scene(bc, "plain_house", rng, randomize=seed is not None)
    boxes = list(_solid_boxes(bc, scene))
    assert len(boxes) >= 9  # 4 walls and the furniture
    for body, (lo, hi) in boxes:
        assert _gap(lo, hi, scene.field_bounds) >= MARGIN, (seed, body, lo, hi)
    # and the pieces of furniture (randomised: mirrored, moved) stand apart
    x0, x1, y0, y1 = np.add(scene.room_bounds, (-1e-3, 1e-3, -1e-3, 1e-3))  # vertex nudges
    pieces = [
        (lo, hi)
        for _, (lo, hi) in boxes
        if x0 <= lo[0] and hi[0] <= x1 and y0 <= lo[1] and hi[1] <= y1
    ]
    assert len(pieces) == len(boxes) - 4  # all but the walls
    for i, (la, ha) in enumerate(pieces):
        for lb, hb in pieces[i + 1 :]:
            overlap = min(ha[0], hb[0]) - max(la[0], lb[0]), min(ha[1], hb[1]) - max(la[1], lb[1])
            assert min(overlap) <= 0.0, (seed, la, ha, lb, hb)
    # rays straight down over the field and across it at the robot's height hit nothing
    fx0, fx1, fy0, fy1 = scene.field_bounds
    xs, ys = np.meshgrid(np.arange(fx0, fx1 + 1e-9, 0.05), np.arange(fy0, fy1 + 1e-9, 0.05))
    starts = [(x, y, 2.45) for x, y in zip(xs.ravel(), ys.ravel(), strict=True)]
    ends = [(x, y, 0.005) for x, y, _ in starts]
    for z in (0.05, 0.2, 0.35):
        for y in np.arange(fy0, fy1 + 1e-9, 0.1):
            starts.append((fx0 - MARGIN, y, z))
            ends.append((fx1 + MARGIN, y, z))
        for x in np.arange(fx0, fx1 + 1e-9, 0.1):
            starts.append((x, fy0 - MARGIN, z))
            ends.append((x, fy1 + MARGIN, z))
    hits = []
    for k in range(0, len(starts), 1000):  # rayTestBatch takes at most ~16k rays
        hits += bc.rayTestBatch(starts[k : k + 1000], ends[k : k + 1000])
    assert all(h[0] == -1 for h in hits), [h for h in hits if h[0] != -1][:3]


def test_round_poses_render_without_holes(bc):
    # eyes at round positions and headings once made the tiny renderer drop triangles
    scene = build_scene(bc, "plain_house")
    for eye in ((0.0, 0.0, 0.3), (1.0, 1.0, 0.3), (-1.5, -1.2, 0.25)):
        for yaw in (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0):
            img = _view(bc, scene, eye, yaw)
            assert not np.any(img.min(axis=2) == 255), (eye, yaw)
            assert np.mean(img.max(axis=2) == 0) < 0.01, (eye, yaw)


def test_is_plainer_than_home_from_the_same_poses():
    plain, home = _turn("plain_house"), _turn("home")
    low_p, edges_p = _plainness(plain)
    low_h, edges_h = _plainness(home)
    # measured: 0.90 vs 0.84 low-gradient pixels, 3.3 % vs 5.8 % edge pixels
    assert low_p > low_h + 0.03, (low_p, low_h)
    assert edges_p < 0.75 * edges_h, (edges_p, edges_h)
    # and what is seen above the horizon is mostly a light, nearly colourless paint
    upper = np.concatenate([f[: H // 2].reshape(-1, 3) for f in plain]).astype(np.float32)
    sat = (upper.max(axis=1) - upper.min(axis=1)) / np.maximum(upper.max(axis=1), 1.0)
    assert np.median(sat) < 0.1
    assert np.median(upper.mean(axis=1)) > 140.0


def test_has_bright_windows():
    frames = _turn("plain_house")
    bright = [(f[: H // 2].min(axis=2) >= 215).mean() for f in frames]
    # the window on the north wall fills part of the view at 90°; a second one is in
    # the south-west; the walls themselves never get this bright
    assert bright[2] > 0.05, bright
    assert sum(b > 0.01 for b in bright) >= 2, bright
    walls = np.median(np.concatenate([f[: H // 2].reshape(-1, 3) for f in frames]), axis=0)
    assert walls.max() < 200, walls
