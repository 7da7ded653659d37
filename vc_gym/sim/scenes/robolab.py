"""``"robolab"``: the UvA Robolab of the paper (section 5).

A 7 x 7 m room with a 6 x 4 m green carpet field (white outline, centre line, centre
circle, penalty boxes) and the two RoboCup goals behind its ends, tables with computers
and chairs along one side, windows with radiators, a bookshelf and robot crates on the
opposite side, a whiteboard, a cork board, a clock, a door and posters (real photos from
matplotlib's sample data, maps and procedural posters) on the walls, and a closed ceiling.
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
    shelf,
    sun,
    wall_colors,
    window,
    workstation,
)
from vc_gym.sim.scenes.parts import RGB, box
from vc_gym.sim.scenes.registry import register_scene
from vc_gym.sim.scenes.rooms import FLOOR_PPM, Room
from vc_gym.sim.scenes.scene import SceneLayout

__all__ = ["build_robolab"]


def _goal(b: Builder, x_mouth: float, sign: float, rgb: RGB) -> None:
    """A RoboCup 4-legged goal (0.8 m wide, 0.3 m high, 0.25 m deep) behind ``x_mouth``."""
    white = (245, 245, 245)
    xb = x_mouth + sign * 0.25
    xa, xz = min(x_mouth, xb), max(x_mouth, xb)
    hw, h, t = 0.4, 0.3, 0.03
    back = (xb - sign * t, xb)
    parts = [
        box(min(back), max(back), -hw, hw, 0.0, h, rgb),
        box(xa, xz, -hw - t, -hw, 0.0, h, rgb),
        box(xa, xz, hw, hw + t, 0.0, h, rgb),
        box(xa, xz, -hw - t, hw + t, h, h + 0.02, rgb),
        box(x_mouth - 0.02, x_mouth + 0.02, -hw - t, -hw, 0.0, h + 0.02, white),
        box(x_mouth - 0.02, x_mouth + 0.02, hw, hw + t, 0.0, h + 0.02, white),
        box(x_mouth - 0.02, x_mouth + 0.02, -hw - t, hw + t, h, h + 0.03, white),
    ]
    b.solid(parts)


@register_scene("robolab", canonical_seed=2006)
def build_robolab(b: Builder) -> SceneLayout:
    """Build the robolab scene (see the module docstring) with ``b``."""
    v, rng = b.choices, b.rng
    bounds, field_b, height = (-3.5, 3.5, -3.5, 3.5), (-3.0, 3.0, -2.0, 2.0), 2.8
    colors = wall_colors(b, (232, 228, 212))
    desk_side = v.choice("N", ("N", "S"))
    window_side = "S" if desk_side == "N" else "N"
    accent_side = v.choice("W", ("E", "W", "none"))
    if accent_side != "none":
        colors[accent_side] = v.color((120, 160, 200), dh=0.5, ds=0.2, dv=0.15)
    room = Room(b, bounds, height, colors)
    base_rgb = v.color((95, 95, 100), dh=0.5, ds=0.2, dv=0.2)
    for wall in room.walls.values():
        baseboard(wall, base_rgb)
        wall.canvas.mottle(rng, 0.02, 1.0)

    # tables with computers and chairs along one side (paper, section 5)
    u = v.uniform(0.2, 0.1, 0.5)
    for _ in range(v.integers(3, 2, 3)):
        width = v.uniform(1.6, 1.2, 1.8)
        if u + width > 6.8:
            break
        workstation(b, room, desk_side, u, width)
        u += width + v.uniform(0.25, 0.1, 0.6)
    if u + 1.0 < 6.9:
        door(b, room.walls[desk_side], max(u + 0.1, v.uniform(5.9, u + 0.1, 6.0)))
    else:
        door(b, room.walls["E"], v.uniform(5.6, 4.8, 5.9))

    # windows with radiators, a bookshelf and a cabinet with robot crates opposite
    win = room.walls[window_side]
    shelf(b, room, window_side, v.uniform(0.15, 0.1, 0.4), 0.9, frame=v.color((125, 90, 60)))
    n_win = v.integers(2, 1, 3)
    span0, span1 = 1.5, 5.6
    slot = (span1 - span0) / n_win
    for k in range(n_win):
        ww = v.uniform(1.5, 0.8, min(1.8, slot - 0.3))
        uc = span0 + (k + 0.5) * slot + v.uniform(0.0, -0.15, 0.15)
        window(b, win, uc - ww / 2, uc + ww / 2, 0.95, 2.3)
    cab = cabinet(b, room, window_side, 5.85, 1.0, 0.75, v.color((200, 200, 195)))
    crates = [(210, 40, 40), (40, 90, 200), (240, 200, 30)]
    for k in range(2):
        c = crates[int(rng.integers(3))] if v.randomize else crates[k]
        ua = 5.9 + k * 0.48
        cab.append(room.box(window_side, ua, ua + 0.44, 0.05, 0.4, 0.75, 1.02, c))
    b.solid(cab)

    # the field's goals, on the floor margin behind its ends (outside field_bounds)
    yellow, blue = (235, 200, 25), (60, 150, 225)
    if v.chance(False, 0.5):
        yellow, blue = blue, yellow
    _goal(b, 3.24, 1.0, yellow)
    _goal(b, -3.24, -1.0, blue)

    # boards, clock and posters
    west, east = room.walls["W"], room.walls["E"]
    wb_u = v.uniform(2.3, 0.6, 4.4)
    west.canvas.board(rng, wb_u, wb_u + 2.0, 0.9, 2.05, "white")
    west.take(wb_u, wb_u + 2.0, 0.85, 2.05)
    cb_u = v.uniform(0.5, 0.4, 5.3)
    if east.free(cb_u, cb_u + 1.2, 1.0, 1.9):
        east.canvas.board(rng, cb_u, cb_u + 1.2, 1.0, 1.9, "cork")
        east.take(cb_u, cb_u + 1.2, 1.0, 1.9)
    clock_wall = room.walls[v.choice("E", ("E", "W", window_side))]
    cu = v.uniform(3.5, 1.0, 6.0)
    if clock_wall.free(cu - 0.2, cu + 0.2, 2.05, 2.45, 0.05):
        clock_wall.canvas.clock(cu, 2.25, 0.19, (40, 40, 40))
        clock_wall.take(cu - 0.2, cu + 0.2, 2.05, 2.45)
    counts = {"E": v.integers(6, 4, 7), "W": v.integers(4, 3, 5), desk_side: v.integers(5, 4, 6)}
    counts[window_side] = v.integers(3, 2, 4)
    for side in "ENWS":
        hang_pictures(b, room.walls[side], counts[side], (0.5, 2.05))

    # floor: grey linoleum, the green carpet with coarse white lines
    fx0, fx1, fy0, fy1 = field_b
    floor = tx.Canvas(7.0, 7.0, FLOOR_PPM, v.color((165, 165, 160), dv=0.1))
    floor.mottle(rng, 0.04, 0.7)
    green = v.color((45, 120, 55), dh=0.03, ds=0.1, dv=0.1)
    sx, sy = fx0 - bounds[0], fy0 - bounds[2]  # field corner in canvas coordinates
    carpet = tx.Canvas(fx1 - fx0, fy1 - fy0, FLOOR_PPM, green)
    carpet.mottle(rng, 0.06, 0.5)
    floor.paste(sx, sx + 6.0, sy, sy + 4.0, carpet.image())
    white, lw, inset = (238, 238, 238), 0.05, 0.2
    ox0, ox1, oy0, oy1 = sx + inset, sx + 6.0 - inset, sy + inset, sy + 4.0 - inset
    floor.outline(ox0, ox1, oy0, oy1, lw, white)
    cx, cy = sx + 3.0, sy + 2.0
    floor.rect(cx - lw / 2, cx + lw / 2, oy0, oy1, white)
    floor.disc(cx, cy, 0.5 + lw / 2, white, inner=0.5 - lw / 2)
    floor.disc(cx, cy, 0.05, white)
    for x_line, sgn in ((ox0, 1.0), (ox1, -1.0)):  # penalty areas
        xa, xb = sorted((x_line, x_line + sgn * 0.65))
        floor.outline(xa, xb, cy - 0.65, cy + 0.65, lw, white)
    room.build(floor.image(), ceiling_texture(b, bounds))
    return SceneLayout(bounds, field_b, sun(b, (0.35, -0.45, 0.82)))
