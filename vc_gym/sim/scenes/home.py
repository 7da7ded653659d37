"""``"home"``: a living room in warm colours, one of the paper's "other environments".

A 5.5 x 4.8 m room: wooden floor with a rug, sofa, armchair, bookshelf, TV on a cabinet,
floor lamp, curtains, paintings.
"""

from __future__ import annotations

from vc_gym.sim import textures as tx
from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.furniture import (
    baseboard,
    cabinet,
    ceiling_texture,
    door,
    floor_lamp,
    hang_pictures,
    plant,
    shelf,
    sofa,
    sun,
    wall_colors,
    window,
)
from vc_gym.sim.scenes.registry import register_scene
from vc_gym.sim.scenes.rooms import FLOOR_PPM, Room
from vc_gym.sim.scenes.scene import SceneLayout

__all__ = ["build_home"]


@register_scene("home", canonical_seed=2007)
def build_home(b: Builder) -> SceneLayout:
    """Build the home scene (see the module docstring) with ``b``."""
    v, rng = b.choices, b.rng
    bounds, field_b, height = (-2.75, 2.75, -2.4, 2.4), (-1.5, 1.5, -1.2, 1.2), 2.6
    colors = wall_colors(b, (236, 218, 186))
    if v.randomize and rng.uniform() < 0.5:  # warm paints in randomised homes
        colors = {
            s: tx.hsv(rng.uniform(0.0, 0.15), rng.uniform(0.15, 0.45), rng.uniform(0.7, 0.92))
            for s in "ENWS"
        }
    accent = v.choice("N", ("E", "N", "W", "S"))
    colors[accent] = v.color((185, 105, 75), dh=0.06, ds=0.15, dv=0.15)
    room = Room(b, bounds, height, colors)
    for wall in room.walls.values():
        baseboard(wall, (245, 242, 235), 0.1)
        wall.canvas.mottle(rng, 0.02, 1.0)
    sofa_side = v.choice("N", ("N", "S"))
    tv_side = "S" if sofa_side == "N" else "N"

    # sofa with paintings above it, lamp and side table
    sofa_w = v.uniform(2.2, 1.8, 2.4)
    su = v.uniform(1.6, 1.2, 2.9)
    sofa(b, room, sofa_side, su, sofa_w, v.color((170, 60, 45), dh=0.5, ds=0.3, dv=0.2))
    floor_lamp(b, room, sofa_side, su - 0.35, 0.35)
    st = su + sofa_w + 0.1
    if st + 0.5 < 5.3:
        wood = v.color((120, 80, 50), dv=0.15)
        b.solid(
            [
                room.box(sofa_side, st, st + 0.5, 0.05, 0.55, 0.52, 0.56, wood),
                room.box(sofa_side, st + 0.05, st + 0.45, 0.1, 0.5, 0.0, 0.52, wood * 0.8),
                room.cyl(sofa_side, st + 0.25, 0.3, 0.56, 0.8, 0.07, tx.random_color(rng)),
            ]
        )
        room.walls[sofa_side].take(st, st + 0.5, 0.0, 0.85)
    hang_pictures(b, room.walls[sofa_side], v.integers(3, 2, 4), (1.0, 2.2), (0.6, 1.3), True)

    # TV on a low cabinet, plant, window with curtains
    tu = v.uniform(1.95, 1.2, 2.5)
    tv_parts = cabinet(b, room, tv_side, tu, 1.6, 0.5, v.color((80, 55, 40), dv=0.2))
    tc = tu + 0.8
    tv_parts.append(room.box(tv_side, tc - 0.15, tc + 0.15, 0.1, 0.3, 0.5, 0.53, (20, 20, 22)))
    tv_parts.append(room.box(tv_side, tc - 0.04, tc + 0.04, 0.14, 0.18, 0.53, 0.65, (20, 20, 22)))
    tv_parts.append(room.box(tv_side, tc - 0.62, tc + 0.62, 0.14, 0.2, 0.62, 1.33, (20, 20, 22)))
    b.solid(tv_parts)
    show = tx.procedural_poster(rng, (90, 160), str(rng.choice(["landscape", "chart", "text"])))
    b.mesh([room.quad(tv_side, tc - 0.58, tc + 0.58, 0.66, 1.29, 0.202)], show)
    room.walls[tv_side].take(tu, tu + 1.6, 0.0, 1.4)
    plant(b, room, tv_side, v.uniform(0.45, 0.35, 0.8), 0.35)
    curtain = v.color((150, 40, 50), dh=0.5, ds=0.2, dv=0.2)
    win_u = v.uniform(4.3, 4.0, 4.5) if tu + 1.6 < 3.9 else 0.9
    window(b, room.walls[tv_side], win_u - 0.2, win_u + 0.65, 1.0, 2.15, curtains=curtain)

    # bookshelf and armchair on one end wall, window, sideboard and clock on the other
    shelf_side = v.choice("E", ("E", "W"))
    other = "W" if shelf_side == "E" else "E"
    shelf(b, room, shelf_side, v.uniform(2.6, 2.4, 3.3), 1.2, 1.95, 0.35, v.color((110, 75, 45)))
    arm = v.color((70, 110, 90), dh=0.5, ds=0.2, dv=0.2)
    au = v.uniform(0.7, 0.3, 1.0)
    parts = [
        room.box(shelf_side, au, au + 0.85, 0.1, 0.9, 0.1, 0.42, arm),
        room.box(shelf_side, au, au + 0.85, 0.1, 0.3, 0.42, 0.9, arm),
        room.box(shelf_side, au, au + 0.15, 0.1, 0.9, 0.42, 0.62, arm * 0.85),
        room.box(shelf_side, au + 0.7, au + 0.85, 0.1, 0.9, 0.42, 0.62, arm * 0.85),
        room.box(shelf_side, au + 0.15, au + 0.7, 0.3, 0.88, 0.42, 0.5, arm * 1.1),
    ]
    b.solid(parts)
    room.walls[shelf_side].take(au, au + 0.85, 0.0, 0.95)
    door(b, room.walls[shelf_side], v.uniform(3.95, 3.9, 3.95), 0.85)
    o = room.walls[other]
    window(b, o, 1.5, 3.3, 0.95, 2.1, radiator=False, curtains=curtain)
    sb = cabinet(b, room, other, 0.25, 1.0, 0.85, v.color((95, 60, 40), dv=0.15))
    sb.append(room.cyl(other, 0.55, 0.22, 0.85, 1.15, 0.08, tx.random_color(rng)))
    b.solid(sb)
    o.canvas.clock(4.1, 1.95, 0.18, (90, 60, 35))
    o.take(3.9, 4.3, 1.75, 2.15)
    plant(b, room, other, 4.3, 0.3)
    for side in "ENWS":
        if side != sofa_side:
            hang_pictures(b, room.walls[side], v.integers(3, 2, 4), (0.7, 2.2), (0.5, 1.2), True)

    # floor: wooden boards with a big patterned rug under the free area
    wood = v.color((160, 110, 70), dh=0.03, ds=0.15, dv=0.15)
    floor = tx.Canvas(5.5, 4.8, FLOOR_PPM, wood)
    bw = 0.18
    for i in range(int(4.8 / bw) + 1):
        x = float(-rng.uniform(0.0, 1.5))
        while x < 5.5:
            ln = float(rng.uniform(0.8, 1.8))
            floor.shade(x, x + ln - 0.01, i * bw, (i + 1) * bw - 0.01, rng.uniform(0.88, 1.1))
            x += ln
    floor.mottle(rng, 0.03, 0.5)
    rug = v.color((150, 40, 40), dh=0.5, ds=0.2, dv=0.2)
    border = v.color((230, 200, 120), dh=0.5, ds=0.2, dv=0.1)
    rx0, rx1, ry0, ry1 = 1.15, 4.35, 1.3, 3.5
    floor.rect(rx0, rx1, ry0, ry1, border)
    floor.rect(rx0 + 0.15, rx1 - 0.15, ry0 + 0.15, ry1 - 0.15, rug)
    floor.disc((rx0 + rx1) / 2, (ry0 + ry1) / 2, 0.6, border)
    floor.disc((rx0 + rx1) / 2, (ry0 + ry1) / 2, 0.4, rug * 0.6)
    room.build(floor.image(), ceiling_texture(b, bounds, panels=False))
    return SceneLayout(bounds, field_b, sun(b, (0.5, 0.35, 0.8)))
