"""``"outdoor_field"``: a sports pitch outdoors, one of the paper's "other environments".

A grass pitch (mowing stripes, white lines, goals) with pitch-side advertising boards,
floodlight masts, a grandstand, trees and buildings 15-30 m away, inside a sky cylinder
with clouds and a far ridge of hills. Invisible fences keep the robot inside
``room_bounds``.
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.sim import textures as tx
from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.furniture import sun
from vc_gym.sim.scenes.parts import RGB, ball, box, cyl
from vc_gym.sim.scenes.registry import register_scene
from vc_gym.sim.scenes.scene import SceneLayout

__all__ = ["build_outdoor_field"]


@register_scene("outdoor_field", canonical_seed=5)
def build_outdoor_field(b: Builder) -> SceneLayout:
    """Build the outdoor_field scene (see the module docstring) with ``b``."""
    v, rng = b.choices, b.rng
    reach, field_b = (-7.0, 7.0, -5.0, 5.0), (-3.0, 3.0, -2.0, 2.0)
    radius, sky_h, ground = 34.0, 22.0, 35.0

    # grass: mowing stripes, white lines of a 44 x 28 m pitch
    g = v.color((70, 135, 55), dh=0.03, ds=0.15, dv=0.12)
    c = tx.Canvas(2 * ground, 2 * ground, 20.0, g)
    stripe = v.uniform(4.0, 3.0, 6.0)
    x = ground - 22.0
    k = 0
    while x < ground + 22.0:
        c.shade(x, x + stripe, ground - 14.0, ground + 14.0, 1.08 if k % 2 else 0.94)
        x, k = x + stripe, k + 1
    c.mottle(rng, 0.06, 3.0)
    white, lw = (235, 240, 235), 0.12
    px0, px1, py0, py1 = ground - 22.0, ground + 22.0, ground - 14.0, ground + 14.0
    c.outline(px0, px1, py0, py1, lw, white)
    c.rect(ground - lw / 2, ground + lw / 2, py0, py1, white)
    c.disc(ground, ground, 5.0 + lw / 2, white, inner=5.0 - lw / 2)
    for xl, sgn in ((px0, 1.0), (px1, -1.0)):
        xa, xb = sorted((xl, xl + sgn * 9.0))
        c.outline(xa, xb, ground - 10.0, ground + 10.0, lw, white)
        xa, xb = sorted((xl, xl + sgn * 3.0))
        c.outline(xa, xb, ground - 5.0, ground + 5.0, lw, white)
    floor_id = b.mesh(
        [((-ground, -ground, 0.0), (2 * ground, 0, 0), (0, 2 * ground, 0), (0, 0, 1, 1))],
        c.image(),
        collision=((0.0, 0.0, -0.25), (ground, ground, 0.25)),
        obstacle=False,
    )
    b.floor(floor_id)

    # the sky: a 24-sided cylinder with a lid, shaded as if it faced up (uniform light)
    band = tx.sky_band(rng)
    n = 24
    quads = []
    for i in range(n):
        a0, a1 = 2 * math.pi * i / n, 2 * math.pi * (i + 1) / n
        p0 = (radius * math.cos(a0), radius * math.sin(a0), 0.0)
        p1 = (radius * math.cos(a1), radius * math.sin(a1), 0.0)
        # seen from inside, left to right is clockwise: walk from a1 to a0
        du = (p0[0] - p1[0], p0[1] - p1[1], 0.0)
        quads.append((p1, du, (0.0, 0.0, sky_h), (1 - (i + 1) / n, 0.0, 1 - i / n, 1.0)))
    b.mesh(quads, band, normal=(0.0, 0.0, 1.0))
    zenith = band[0].astype(np.float32).mean(axis=0)
    lid = [((-ground, -ground, sky_h), (0, 2 * ground, 0), (2 * ground, 0, 0), (0, 0, 1, 1))]
    b.ceilings.append(b.mesh(lid, tx.sky_cap(rng, zenith), normal=(0.0, 0.0, 1.0)))

    # goals at the pitch ends: white frame, light grey net
    for sgn in (1.0, -1.0):
        xg = sgn * 22.0
        xb = xg + sgn * 1.5
        xa, xz = sorted((xg, xb))
        post, net = (248, 248, 248), (205, 208, 210)
        b.solid(
            [
                box(xg - 0.06, xg + 0.06, -2.56, -2.44, 0.0, 2.0, post),
                box(xg - 0.06, xg + 0.06, 2.44, 2.56, 0.0, 2.0, post),
                box(xg - 0.06, xg + 0.06, -2.56, 2.56, 1.9, 2.02, post),
                box(min(xb, xb - sgn * 0.03), max(xb, xb - sgn * 0.03), -2.5, 2.5, 0.0, 1.6, net),
                box(xa, xz, -2.53, -2.5, 0.0, 1.9, net),
                box(xa, xz, 2.5, 2.53, 0.0, 1.9, net),
            ]
        )
    # advertising boards round the pitch: one mesh with an atlas of boards
    boards: list[np.ndarray] = []
    quads = []
    bh = 0.9
    for y_side, sgn in ((16.0, -1.0), (-16.0, 1.0)):  # along the touchlines, facing in
        for x0 in np.arange(-20.0, 20.0, 4.0):
            x_a, x_b = (x0, x0 + 3.9) if sgn < 0 else (x0 + 3.9, x0)
            quads.append(((x_a, y_side, 0.0), (x_b - x_a, 0.0, 0.0), (0.0, 0.0, bh)))
    for x_side, sgn in ((25.0, -1.0), (-25.0, 1.0)):  # behind the goals
        for y0 in np.arange(-10.0, 10.0, 4.0):
            y_a, y_b = (y0, y0 + 3.9) if sgn > 0 else (y0 + 3.9, y0)
            quads.append(((x_side, y_a, 0.0), (0.0, y_b - y_a, 0.0), (0.0, 0.0, bh)))
    for _ in quads:
        boards.append(tx.ad_board(rng))
    atlas = np.vstack(boards)
    m = len(boards)
    b.mesh(
        [
            (o, du, dv, (0.0, 1 - (i + 1) / m, 1.0, 1 - i / m))
            for i, (o, du, dv) in enumerate(quads)
        ],
        atlas,
    )
    for o, du, _dv in quads:
        xs, ys = sorted((o[0], o[0] + du[0])), sorted((o[1], o[1] + du[1]))
        b.obstacles.append((xs[0] - 0.05, xs[1] + 0.05, ys[0] - 0.05, ys[1] + 0.05))

    # floodlight masts at the corners, a grandstand, buildings and trees
    mast = (150, 150, 155)
    parts = []
    for sx in (-24.0, 24.0):
        for sy in (-17.5, 17.5):
            parts.append(cyl(sx, sy, 0.0, 14.0, 0.18, mast))
            parts.append(box(sx - 1.0, sx + 1.0, sy - 0.2, sy + 0.2, 13.6, 14.8, (235, 235, 225)))
    b.solid(parts, collide=False)
    stand_side = v.choice(1.0, (1.0, -1.0))
    _grandstand(b, stand_side, v.color((30, 80, 170), dh=0.5, ds=0.2, dv=0.2))
    # buildings behind the goals and the far touchline (the diagonals hold the masts),
    # trees elsewhere
    sectors = [k for k in range(4) if k != (1 if stand_side > 0 else 3)]
    n_buildings = v.integers(3, 2, 3)
    chosen = [sectors[int(k)] for k in rng.permutation(len(sectors))[:n_buildings]]
    angles = []
    for k in chosen:
        a = math.radians(90.0 * k + float(rng.uniform(-15.0, 15.0)))
        angles.append(a)
        size = (float(rng.uniform(8.0, 14.0)), float(rng.uniform(5.0, 7.0)))
        _building(b, rng, 29.0 * math.cos(a), 29.0 * math.sin(a), *size, float(rng.uniform(5, 14)))
    trees = []
    n_trees = v.integers(18, 12, 24)
    for i in range(n_trees):
        a = 2 * math.pi * (i + rng.uniform(0.1, 0.9)) / n_trees
        r = float(rng.uniform(25.0, 31.0))
        x, y = r * math.cos(a), r * math.sin(a)
        near_building = any(abs(math.remainder(a - ab, 2 * math.pi)) < 0.3 for ab in angles)
        behind_stand = abs(y) > 17.0 and abs(x) < 14.0 and y * stand_side > 0
        if near_building or behind_stand:
            continue
        h = float(rng.uniform(4.0, 9.0))
        leaf = tx.hsv(rng.uniform(0.22, 0.36), rng.uniform(0.45, 0.8), rng.uniform(0.25, 0.5))
        trees.append(cyl(x, y, 0.0, h * 0.5, 0.25, (95, 70, 45)))
        if rng.uniform() < 0.6:
            trees.append(ball(x, y, h * 0.65, h * 0.3, leaf))
        else:
            trees.append(cyl(x, y, h * 0.35, h, h * 0.22, leaf))
    b.solid(trees, collide=False)

    # invisible fences round the area the robot may reach
    x0, x1, y0, y1 = reach
    t = 0.2
    b.fence(x1, x1 + t, y0 - t, y1 + t)
    b.fence(x0 - t, x0, y0 - t, y1 + t)
    b.fence(x0, x1, y1, y1 + t)
    b.fence(x0, x1, y0 - t, y0)
    return SceneLayout(reach, field_b, sun(b, (0.3, -0.4, 0.85)))


def _grandstand(b: Builder, side: float, seat: RGB) -> None:
    """A 24 m grandstand beyond the touchline ``y = 14 side``: four steps of seats, a
    back wall, a roof on three pillars."""
    grey, concrete = (120, 120, 125), (170, 170, 168)
    seat = np.asarray(seat, np.float32)

    def ys(d0: float, d1: float) -> tuple[float, float]:
        """The y range from ``d0`` to ``d1`` metres behind the stand's front at 19 m."""
        a, c = side * (19.0 + d0), side * (19.0 + d1)
        return min(a, c), max(a, c)

    parts = []
    for s in range(4):
        y0, y1 = ys(s, s + 1.0)
        parts.append(box(-12.0, 12.0, y0, y1, 0.0, 0.5 + s * 0.5, concrete))
        color = seat if s % 2 == 0 else seat * np.float32(0.8)
        parts.append(box(-12.0, 12.0, y0, y1, 0.5 + s * 0.5, 0.8 + s * 0.5, color))
    parts.append(box(-12.2, 12.2, *ys(4.0, 4.3), 0.0, 4.2, grey))
    roof = b.choices.color((180, 40, 40), dh=0.5)
    parts.append(box(-12.5, 12.5, *ys(-0.5, 4.3), 4.2, 4.5, roof))
    for xp in (-12.0, 0.0, 12.0):
        parts.append(box(xp - 0.1, xp + 0.1, *ys(-0.4, -0.2), 0.0, 4.2, grey))
    b.solid(parts)


def _building(
    b: Builder, rng: np.random.Generator, cx: float, cy: float, w: float, d: float, h: float
) -> None:
    """A block ``w`` wide facing the pitch centre, ``d`` deep, ``h`` high, with a
    facade texture on its walls and a flat roof."""
    if abs(cx) > abs(cy):  # east or west of the pitch: the wide side runs along y
        w, d = d, w
    x0, x1, y0, y1 = cx - w / 2, cx + w / 2, cy - d / 2, cy + d / 2
    img = tx.facade(rng, max(w, d), h)
    quads = [
        ((x0, y0, 0.0), (w, 0, 0), (0, 0, h), (0, 0, 1, 1)),  # south face
        ((x1, y0, 0.0), (0, d, 0), (0, 0, h), (0, 0, 1, 1)),  # east
        ((x1, y1, 0.0), (-w, 0, 0), (0, 0, h), (0, 0, 1, 1)),  # north
        ((x0, y1, 0.0), (0, -d, 0), (0, 0, h), (0, 0, 1, 1)),  # west
    ]
    b.mesh(quads, img)
    roof = tx.hsv(rng.uniform(0.0, 0.1), rng.uniform(0.2, 0.6), rng.uniform(0.3, 0.5))
    b.solid([box(x0 - 0.2, x1 + 0.2, y0 - 0.2, y1 + 0.2, h, h + 0.4, roof)], collide=False)
