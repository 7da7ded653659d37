"""``"plain_house"``: a living room as plain as a real house: plain walls, muted furniture.

The built-in rooms flatter an appearance-based compass: posters and colourful furniture
everywhere. Real furnished houses are mostly plain, and this scene is one: a 5.5 x 4.5 m
room with a 2.5 m ceiling, walls of one off-white paint (a little lighter or darker per
wall, as the light falls, and only a very faint mottle), a white skirting board, a white
ceiling and a light wooden floor. Real-size furniture in muted colours stands along the
walls: a 2 m grey sofa with a floor lamp, a white wardrobe, a wooden dining table pushed
against a wall with a chair at each end, a low white shelf with a few muted books and
boxes. Two bright windows (white frames, a pale sky outside), one white door and two
small muted pictures; no posters. The robot's field (3.0 x 2.4 m, as in ``home``) is
free of furniture.
"""

from __future__ import annotations

import numpy as np

from vc_gym.sim import textures as tx
from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.furniture import (
    baseboard,
    bright_window,
    ceiling_texture,
    dining_table,
    door,
    floor_lamp,
    shelf,
    sofa,
    sun,
    wardrobe,
)
from vc_gym.sim.scenes.registry import register_scene
from vc_gym.sim.scenes.rooms import FLOOR_PPM, Room, Wall
from vc_gym.sim.scenes.scene import SceneLayout

__all__ = ["build_plain_house"]

#: The wall that the ``u = 0`` end of each wall meets (see :meth:`Room.origin`).
_START = {"E": "N", "N": "W", "W": "S", "S": "E"}
#: Muted colours of the books and boxes on the low shelf.
_SHELF_PALETTE = (
    (200, 192, 178),
    (150, 148, 142),
    (120, 128, 138),
    (228, 226, 220),
    (170, 150, 125),
)


def _bright_sky(rng: np.random.Generator, height: int = 96, width: int = 128) -> np.ndarray:
    """A window's view of a bright, hazy sky: pale blue at the top to almost white."""
    t = np.linspace(0.0, 1.0, height, dtype=np.float32)[:, None, None]  # 0 top, 1 bottom
    hue = rng.uniform(0.55, 0.6)
    img = tx.hsv(hue, rng.uniform(0.12, 0.22), 0.93) * (1 - t) + tx.hsv(hue, 0.04, 0.99) * t
    cloud = np.clip(tx.smooth_noise(rng, height, width, 3) - 0.4, 0.0, 1.0)[..., None]
    img = img * (1 - 0.6 * cloud) + 250.0 * 0.6 * cloud
    return np.clip(np.broadcast_to(img, (height, width, 3)), 0, 255).astype(np.uint8)


def _small_print(b: Builder, wall: Wall, uc: float, z0: float, w: float, h: float) -> None:
    """A small framed print in muted colours (a landscape, faded) centred at ``uc``."""
    rng = b.rng
    img = tx.procedural_poster(rng, (72, int(72 * w / h)), "landscape").astype(np.float32)
    grey = img.mean(axis=2, keepdims=True)
    img = 0.35 * img + 0.45 * grey + 0.2 * 235.0  # faded, washed towards the wall
    frame = b.choices.choice((60, 58, 55), ((60, 58, 55), (235, 233, 228), (185, 160, 125)))
    u0 = uc - w / 2
    wall.canvas.framed(u0, u0 + w, z0, z0 + h, img.astype(np.uint8), frame, 0.03)
    wall.take(u0, u0 + w, z0, z0 + h)


@register_scene("plain_house", canonical_seed=2011)
def build_plain_house(b: Builder) -> SceneLayout:
    """Build the plain_house scene (see the module docstring) with ``b``."""
    v, rng = b.choices, b.rng
    bounds, field_b, height = (-2.75, 2.75, -2.25, 2.25), (-1.5, 1.5, -1.2, 1.2), 2.5
    light = sun(b, (0.45, -0.3, 0.85))
    paint = v.color((240, 237, 228), dh=0.04, ds=0.05, dv=0.04)  # one off-white paint
    shades = {"E": 1.0, "N": 0.975, "W": 0.955, "S": 0.99}  # a little light or shadow
    colors = {s: paint * np.float32(v.uniform(f, 0.94, 1.0)) for s, f in shades.items()}
    room = Room(b, bounds, height, colors)
    skirting = v.color((246, 245, 241), ds=0.02, dv=0.03)
    for wall in room.walls.values():
        baseboard(wall, skirting, 0.09)
        wall.canvas.mottle(rng, 0.006, 1.2)
    # the end walls (4.5 m): the sofa on one, wardrobe and door on the other; the long
    # walls (5.5 m): a window and a low shelf on one, the table and a window on the other.
    # Each piece is placed by its distance from a corner, so that mirrored (randomised)
    # layouts keep the pieces apart: the table in the corner of its wall with the
    # wardrobe's, the wardrobe at the window wall's end, the shelf at the sofa's end.
    sofa_side = v.choice("W", ("W", "E"))
    ward_side = "E" if sofa_side == "W" else "W"
    window_side = v.choice("N", ("N", "S"))
    table_side = "S" if window_side == "N" else "N"

    def along(side: str, corner: str, off: float, width: float) -> float:
        """``u0`` of a piece ``width`` long on wall ``side``, ``off`` from wall ``corner``."""
        return off if _START[side] == corner else room.walls[side].length - off - width

    # a grey sofa with beige pillows, a floor lamp at its end near the table's wall and a
    # small print above it
    sofa_w = v.uniform(2.0, 1.8, 2.2)
    su = along(sofa_side, table_side, v.uniform(1.25, 0.75, 4.05 - sofa_w), sofa_w)
    lamp_u = su - 0.32 if _START[sofa_side] == table_side else su + sofa_w + 0.32
    sofa_rgb = v.color((150, 150, 147), dh=0.1, ds=0.06, dv=0.15)
    sofa(b, room, sofa_side, su, sofa_w, sofa_rgb, pillows=v.color((208, 200, 186), ds=0.05))
    floor_lamp(b, room, sofa_side, lamp_u, 0.3)
    _small_print(b, room.walls[sofa_side], su + sofa_w / 2, 1.3, 0.55, 0.42)

    # a white wardrobe and a white door on the opposite wall
    wu = along(ward_side, window_side, v.uniform(0.3, 0.2, 0.6), 1.2)
    wardrobe(b, room, ward_side, wu, 1.2, 2.1, 0.6, v.color((232, 230, 224), ds=0.05, dv=0.06))
    du = along(ward_side, window_side, v.uniform(2.5, 2.2, 2.9), 0.85)
    door(b, room.walls[ward_side], du, 0.85, leaf=(240, 239, 234))

    # a window with a radiator and a low shelf on one long wall
    ww = v.uniform(1.5, 1.2, 1.8)
    wu0 = along(window_side, sofa_side, v.uniform(2.9, 2.75, 3.6) - ww / 2, ww)
    sky = _bright_sky(rng)
    bright_window(b, room, window_side, wu0, wu0 + ww, 0.85, 2.2, light, view=sky)
    shelf_rgb = v.choice((238, 236, 230), ((238, 236, 230), (196, 166, 126)))
    shu = along(window_side, sofa_side, v.uniform(0.35, 0.25, 0.6), 1.1)
    shelf(b, room, window_side, shu, 1.1, 0.8, 0.35, shelf_rgb, palette=_SHELF_PALETTE)

    # a wooden table with two chairs, a second window and a small print on the other
    wood = v.color((196, 164, 122), dh=0.02, ds=0.1, dv=0.12)
    tu = along(table_side, ward_side, v.uniform(0.8, 0.6, 1.2), 1.2)
    dining_table(b, room, table_side, tu, 1.2, 0.8, wood)
    _small_print(b, room.walls[table_side], tu + 0.6, 1.25, 0.4, 0.5)
    if v.chance(True, 0.7):
        u0 = along(table_side, ward_side, v.uniform(3.75, 3.35, 4.6) - 0.55, 1.1)
        bright_window(b, room, table_side, u0, u0 + 1.1, 0.9, 2.2, light, radiator=False, view=sky)

    # floor: light oak boards of hardly different shades (or, randomised, grey vinyl)
    if v.chance(True, 0.7):
        floor = tx.Canvas(5.5, 4.5, FLOOR_PPM, v.color((202, 176, 140), dh=0.02, ds=0.1, dv=0.1))
        bw = 0.16
        for i in range(int(4.5 / bw) + 1):
            x = float(-rng.uniform(0.0, 1.5))
            while x < 5.5:
                ln = float(rng.uniform(0.9, 1.9))
                floor.shade(
                    x, x + ln - 0.005, i * bw, (i + 1) * bw - 0.005, rng.uniform(0.95, 1.05)
                )
                x += ln
    else:
        floor = tx.Canvas(5.5, 4.5, FLOOR_PPM, v.color((172, 172, 168), ds=0.05, dv=0.12))
    floor.mottle(rng, 0.02, 0.6)
    room.build(floor.image(), ceiling_texture(b, bounds, panels=False))
    return SceneLayout(bounds, field_b, light)
