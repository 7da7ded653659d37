"""``"office"``: an office, one of the paper's "other environments" (section 5).

A 6 x 5 m room with desks with monitors, tall shelves with binders, a whiteboard,
windows with blinds, filing cabinets, a printer and plants; blue-grey carpet tiles and a
ceiling with light panels.
"""

from __future__ import annotations

from vc_gym.sim import textures as tx
from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.furniture import (
    baseboard,
    cabinet,
    ceiling_texture,
    door,
    hang_pictures,
    plant,
    shelf,
    sun,
    wall_colors,
    window,
    workstation,
)
from vc_gym.sim.scenes.registry import register_scene
from vc_gym.sim.scenes.rooms import FLOOR_PPM, Room
from vc_gym.sim.scenes.scene import SceneLayout

__all__ = ["build_office"]


@register_scene("office", canonical_seed=16)
def build_office(b: Builder) -> SceneLayout:
    """Build the office scene (see the module docstring) with ``b``."""
    v, rng = b.choices, b.rng
    bounds, field_b, height = (-3.0, 3.0, -2.5, 2.5), (-2.0, 2.0, -1.0, 1.0), 2.7
    colors = wall_colors(b, (240, 240, 236))
    accent = v.choice("W", ("E", "N", "W", "S"))
    colors[accent] = v.color((70, 140, 150), dh=0.5, ds=0.25, dv=0.2)
    room = Room(b, bounds, height, colors)
    for wall in room.walls.values():
        baseboard(wall, (70, 72, 78), 0.1)
        wall.canvas.mottle(rng, 0.015, 1.0)
    desk_side = v.choice("N", ("N", "S"))
    window_side = "S" if desk_side == "N" else "N"

    # desks with monitors along one long wall
    u = v.uniform(0.3, 0.15, 0.8)
    for _ in range(v.integers(3, 2, 3)):
        width = v.uniform(1.6, 1.3, 1.8)
        if u + width > 5.85:
            break
        workstation(b, room, desk_side, u, width)
        u += width + v.uniform(0.3, 0.15, 0.5)

    # tall shelves with binders on the east wall (or west)
    shelf_side = v.choice("E", ("E", "W"))
    board_side = "W" if shelf_side == "E" else "E"
    u = v.uniform(0.4, 0.2, 1.2)
    frame = v.color((150, 155, 160), dh=0.5, ds=0.2, dv=0.2)
    for _ in range(v.integers(3, 2, 4)):
        if u + 0.9 > 4.8:
            break
        shelf(b, room, shelf_side, u, 0.9, 1.95, 0.4, frame, binders=True)
        u += 0.92
    # windows with blinds, filing cabinets and a plant
    win = room.walls[window_side]
    blinds = v.color((215, 215, 210), dh=0.5, ds=0.3, dv=0.1)
    for uc in (1.6, 4.4) if not v.randomize else sorted(rng.uniform(1.2, 4.8, 2)):
        if win.free(uc - 0.75, uc + 0.75, 0.8, 2.3, 0.05):
            window(b, win, uc - 0.75, uc + 0.75, 0.8, 2.3, blinds=blinds)
    cab_rgb = v.color((120, 125, 135), dh=0.5, ds=0.3, dv=0.2)
    cu = v.uniform(0.15, 0.1, 0.4)
    parts = cabinet(b, room, window_side, cu, 0.5, 1.05, cab_rgb)
    parts += cabinet(b, room, window_side, cu + 0.52, 0.5, 1.05, cab_rgb)
    b.solid(parts)
    printer = [room.box(window_side, 5.2, 5.8, 0.0, 0.5, 0.0, 0.75, (225, 225, 220))]
    printer.append(room.box(window_side, 5.25, 5.75, 0.05, 0.45, 0.75, 0.95, (90, 90, 95)))
    printer.append(room.box(window_side, 5.3, 5.7, 0.5, 0.53, 0.5, 0.6, (60, 60, 65)))
    b.solid(printer)
    room.walls[window_side].take(5.2, 5.8, 0.0, 1.0)
    plant(b, room, shelf_side, v.uniform(4.6, 4.5, 4.7), 0.3)

    # whiteboard, door and posters
    board = room.walls[board_side]
    wu = v.uniform(1.0, 0.5, 2.4)
    board.canvas.board(rng, wu, wu + 2.2, 0.85, 2.05, "white")
    board.take(wu, wu + 2.2, 0.8, 2.05)
    door(b, board, v.uniform(3.8, 3.6, 3.9))
    clock_wall = room.walls[v.choice(desk_side, ("E", "N", "W", "S"))]
    cu = v.uniform(2.9, 0.6, 5.0)
    if clock_wall.free(cu - 0.18, cu + 0.18, 2.1, 2.5, 0.05):
        clock_wall.canvas.clock(cu, 2.3, 0.17, (200, 40, 40))
        clock_wall.take(cu - 0.18, cu + 0.18, 2.1, 2.5)
    for side in "ENWS":
        hang_pictures(b, room.walls[side], v.integers(4, 3, 5), (0.6, 2.1))

    # floor: blue-grey carpet tiles; ceiling with light panels
    floor = tx.Canvas(6.0, 5.0, FLOOR_PPM, v.color((95, 105, 125), dh=0.5, ds=0.2, dv=0.15))
    for i in range(12):
        for j in range(10):
            floor.shade(i * 0.5, i * 0.5 + 0.5, j * 0.5, j * 0.5 + 0.5, rng.uniform(0.93, 1.07))
    floor.mottle(rng, 0.03, 0.4)
    room.build(floor.image(), ceiling_texture(b, bounds))
    return SceneLayout(bounds, field_b, sun(b, (-0.3, -0.5, 0.8)))
