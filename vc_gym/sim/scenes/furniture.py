"""Furniture and wall decorations for rooms made with :class:`~vc_gym.sim.scenes.rooms.Room`.

Wall decorations (:func:`hang_pictures`, :func:`door`, :func:`window`, :func:`baseboard`)
are painted on a :class:`~vc_gym.sim.scenes.rooms.Wall`'s canvas and take their area
(:func:`bright_window` adds glass panes of their own to a painted window); furniture
(:func:`workstation`, :func:`chair`, :func:`shelf`, :func:`cabinet`, :func:`plant`,
:func:`sofa`, :func:`floor_lamp`, :func:`wardrobe`, :func:`dining_table`,
:func:`dining_chair`) is built from parts placed along a wall:
``side`` is the wall (``"E"``, ``"N"``, ``"W"``, ``"S"``), ``u`` the position along it
seen from inside (left to right) and ``d`` the distance out of it, in metres. Colours
are RGB 0..255; every random draw comes from the builder's generator (``b.rng``) or its
layout choices (``b.choices``).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence

import numpy as np

from vc_gym.deprecation import moved_names
from vc_gym.sim import textures as tx
from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.parts import RGB, Part
from vc_gym.sim.scenes.rooms import Room, Wall

__all__ = [
    "baseboard",
    "bright_window",
    "cabinet",
    "ceiling_texture",
    "chair",
    "dining_chair",
    "dining_table",
    "door",
    "floor_lamp",
    "hang_pictures",
    "plant",
    "shelf",
    "sofa",
    "sun",
    "wall_colors",
    "wardrobe",
    "window",
    "workstation",
]


# ---------------------------------------------------------------- painted decorations


def _frame_color(rng: np.random.Generator) -> tuple[np.ndarray, float]:
    kind = rng.uniform()
    if kind < 0.3:
        return np.array([25, 25, 25], np.float32), 0.035
    if kind < 0.5:
        return tx.hsv(rng.uniform(0.06, 0.1), rng.uniform(0.4, 0.7), rng.uniform(0.3, 0.6)), 0.05
    if kind < 0.7:
        return np.array([235, 235, 232], np.float32), 0.04
    if kind < 0.85:
        return np.array([175, 178, 182], np.float32), 0.025
    return tx.random_color(rng), 0.04


def hang_pictures(
    b: Builder,
    wall: Wall,
    n: int,
    z_range: tuple[float, float] = (0.5, 2.0),
    width: tuple[float, float] = (0.6, 1.5),
    paintings: bool = False,
) -> int:
    """Hang up to ``n`` framed pictures on free parts of ``wall``.

    Posters are real photos, maps or procedural posters
    (:func:`vc_gym.sim.textures.poster_image`); ``paintings`` draws landscapes and
    abstract paintings only. Each picture is placed where :meth:`Wall.free` allows and the
    area is then taken.

    Parameters
    ----------
    b : Builder
        The scene's builder (its ``rng`` draws the pictures and places them).
    wall : Wall
        The wall to paint them on.
    n : int
        How many to try.
    z_range : tuple of float
        Lowest bottom and highest top of a picture (m).
    width : tuple of float
        Range of picture widths (m).
    paintings : bool
        Paintings instead of posters.

    Returns
    -------
    int
        How many were hung.
    """
    rng = b.rng
    hung = 0
    for _ in range(n):
        if paintings:
            style = str(rng.choice(["landscape", "landscape", "blocks", "discs", "bands"]))
            aspect = float(rng.choice([0.75, 1.0, 1.33, 1.5]))
            h_px = 120
            img = tx.procedural_poster(rng, (h_px, int(h_px * aspect)), style)
        else:
            img = tx.poster_image(rng, float(rng.uniform(0.65, 1.5)))
        aspect = img.shape[1] / img.shape[0]
        frame_rgb, frame_m = _frame_color(rng)
        for attempt in range(40):
            # shrink the picture a little after each failed attempt to fill small gaps
            w = float(rng.uniform(*width)) * (1.0 - attempt / 60.0)
            h = w / aspect
            if h > 1.3:
                h, w = 1.3, 1.3 * aspect
            lo, hi = z_range
            if h > hi - lo or w < 0.3 or w > wall.length - 0.5:
                continue
            u0 = float(rng.uniform(0.25, wall.length - 0.25 - w))
            # low on the wall rather than high: the robot's eye is 0.3 m above the floor
            z0 = lo + float(rng.uniform() ** 2) * (hi - h - lo)
            if wall.free(u0, u0 + w, z0, z0 + h):
                wall.canvas.framed(u0, u0 + w, z0, z0 + h, img, frame_rgb, frame_m)
                wall.take(u0, u0 + w, z0, z0 + h)
                hung += 1
                break
    return hung


def door(b: Builder, wall: Wall, u0: float, width: float = 0.9, leaf: RGB | None = None) -> None:
    """Paint a 2.05 m high door with its casing on ``wall`` from ``u0`` and take the area.

    Parameters
    ----------
    b : Builder
        The scene's builder (colours from ``b.choices``).
    wall : Wall
        The wall.
    u0 : float
        Left edge of the door along the wall (m).
    width : float
        Width of the door (m).
    leaf : sequence of float, optional
        Canonical colour of the door leaf, varied only a little when randomising
        (default: a wooden door of any colour when randomising).
    """
    v = b.choices
    if leaf is None:
        leaf = v.color((150, 105, 65), dh=0.5, ds=0.4, dv=0.3)
    else:
        leaf = v.color(leaf, dh=0.05, ds=0.05, dv=0.08)
    casing = v.color((238, 236, 230), dh=0.1, ds=0.05, dv=0.08)
    wall.canvas.door(u0, u0 + width, 2.05, leaf, casing)
    wall.take(u0 - 0.1, u0 + width + 0.1, 0.0, 2.15)


def window(
    b: Builder,
    wall: Wall,
    u0: float,
    u1: float,
    z0: float,
    z1: float,
    *,
    radiator: bool = True,
    blinds: RGB | None = None,
    curtains: RGB | None = None,
    view: np.ndarray | None = None,
) -> None:
    """Paint a window with a view outside on ``wall`` and take the area.

    Parameters
    ----------
    b : Builder
        The scene's builder (its ``rng`` paints the view).
    wall : Wall
        The wall.
    u0, u1, z0, z1 : float
        The window's extent along the wall and its sill and top heights (m).
    radiator : bool
        Paint a radiator below it.
    blinds : sequence of float, optional
        Colour of half-closed blinds.
    curtains : sequence of float, optional
        Colour of curtains beside it.
    view : numpy.ndarray, optional
        ``(H, W, 3)`` ``uint8`` RGB picture of what the glass shows (default: a view of
        sky, trees and lawn painted from ``b.rng``).
    """
    c = wall.canvas
    if curtains is not None:
        c.curtains(u0, u1, z0 - 0.3, min(z1 + 0.2, wall.height - 0.05), curtains, 0.35)
    if view is None:
        view = tx.outdoor_view(b.rng)
    c.window(u0, u1, z0, z1, view, mullions=1 if u1 - u0 > 1.0 else 0)
    if blinds is not None:
        c.blinds(u0 + 0.06, u1 - 0.06, z0 + 0.06, z1 - 0.06, blinds)
    if radiator:
        c.radiator(u0 + 0.1, u1 - 0.1, 0.15, min(0.65, z0 - 0.15))
    pad = 0.45 if curtains is not None else 0.1
    wall.take(u0 - pad, u1 + pad, 0.0 if radiator else z0 - 0.1, z1 + 0.1)


def bright_window(
    b: Builder,
    room: Room,
    side: str,
    u0: float,
    u1: float,
    z0: float,
    z1: float,
    light: Sequence[float],
    *,
    radiator: bool = True,
    view: np.ndarray | None = None,
) -> None:
    """A :func:`window` whose glass is as bright as daylight through a real window.

    A painted window is shaded like the wall it is on (a wall facing away from the light
    shows its view at ~60 % brightness); here the panes are quads of their own, 2 mm in
    front of the wall, shaded as if they faced ``light``, so they show ``view`` at full
    brightness from every side. The frame, sill and radiator are painted as by
    :func:`window`.

    Parameters
    ----------
    b : Builder
        The scene's builder (its ``rng`` paints the default view).
    room : Room
        The room.
    side : str
        The wall.
    u0, u1, z0, z1 : float
        The window's extent along the wall and its sill and top heights (m).
    light : sequence of float
        The scene's light direction (towards the light).
    radiator : bool
        Paint a radiator below it.
    view : numpy.ndarray, optional
        What the glass shows (default: :func:`vc_gym.sim.textures.outdoor_view`).
    """
    if view is None:
        view = tx.outdoor_view(b.rng)
    window(b, room.walls[side], u0, u1, z0, z1, radiator=radiator, view=view)
    # the panes between the bars Canvas.window paints: a 6 cm frame, a 6 cm mullion in
    # the middle of windows wider than 1 m and a 6 cm transom at 62 % of the height
    f, bar = 0.06, 0.03
    ga, gb, gc, gd = u0 + f, u1 - f, z0 + f, z1 - f
    cols = [ga, gb] if u1 - u0 <= 1.0 else [ga, (u0 + u1) / 2 - bar, (u0 + u1) / 2 + bar, gb]
    zt = z0 + 0.62 * (z1 - z0)
    quads = []
    for a, c in zip(cols[::2], cols[1::2], strict=True):
        for lo, hi in ((gc, zt - bar), (zt + bar, gd)):
            origin, du, dv, _ = room.quad(side, a, c, lo, hi, 0.002)
            uv = (
                (a - ga) / (gb - ga),
                (lo - gc) / (gd - gc),
                (c - ga) / (gb - ga),
                (hi - gc) / (gd - gc),
            )
            quads.append((origin, du, dv, uv))
    b.mesh(quads, view, normal=light)


def baseboard(wall: Wall, rgb: RGB, height: float = 0.08) -> None:
    """Paint a skirting board of colour ``rgb``, ``height`` metres high, along ``wall``."""
    wall.canvas.rect(0.0, wall.length, 0.0, height, rgb)


def ceiling_texture(b: Builder, bounds, panels: bool = True) -> np.ndarray:
    """The texture of a ceiling over ``bounds`` for :meth:`Room.build`.

    Parameters
    ----------
    b : Builder
        The scene's builder (the colour comes from ``b.choices``).
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the room.
    panels : bool
        Paint office light panels.

    Returns
    -------
    numpy.ndarray
        ``(H, W, 3)`` ``uint8`` texture (u along y, v along x).
    """
    x0, x1, y0, y1 = bounds
    # the ceiling's texture u runs along y, v along x (see Room.build)
    c = tx.Canvas(y1 - y0, x1 - x0, 32.0, b.choices.color((240, 240, 236), dv=0.05))
    if panels:
        for u in np.arange(0.9, y1 - y0 - 0.9, 1.8):
            for v in np.arange(0.9, x1 - x0 - 1.2, 2.4):
                c.rect(u, u + 0.6, v, v + 1.2, (252, 252, 255))
                c.outline(u, u + 0.6, v, v + 1.2, 0.04, (200, 200, 200))
    return c.image()


# -------------------------------------------------------------------------- furniture


def workstation(b: Builder, room: Room, side: str, u0: float, width: float = 1.6) -> None:
    """A table against ``side`` with one or two monitors, keyboard, PC box and chair.

    Everything stays within 1.2 m of the wall (the chair is half under the table).

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall the table stands against.
    u0 : float
        The table's left end along the wall (m).
    width : float
        The table's length (m); below 1.4 m it holds one monitor in the canonical scene.
    """
    v, rng = b.choices, b.rng
    depth, top = 0.75, 0.74
    wood = v.color((200, 170, 125), dh=0.05, ds=0.2, dv=0.2)
    leg = v.color((90, 90, 95), dv=0.2)
    parts = [room.box(side, u0, u0 + width, 0.0, depth, top - 0.04, top, wood)]
    for uu in (u0 + 0.03, u0 + width - 0.08):
        for dd in (0.04, depth - 0.09):
            parts.append(room.box(side, uu, uu + 0.05, dd, dd + 0.05, 0.0, top - 0.04, leg))
    n_mon = v.integers(1 if width < 1.4 else 2, 1, 2)
    centres = [u0 + width / 2] if n_mon == 1 else [u0 + width * 0.3, u0 + width * 0.7]
    bezel = (25, 25, 28) if rng.uniform() < 0.8 else (200, 200, 195)
    for uc in centres:
        mw = float(rng.uniform(0.45, 0.6))
        z0, z1 = top + 0.14, top + 0.14 + mw * 0.62
        parts.append(room.box(side, uc - 0.12, uc + 0.12, 0.1, 0.3, top, top + 0.02, bezel))
        parts.append(room.box(side, uc - 0.03, uc + 0.03, 0.12, 0.16, top, z0 + 0.05, bezel))
        parts.append(room.box(side, uc - mw / 2, uc + mw / 2, 0.16, 0.2, z0, z1, bezel))
        screen = room.quad(
            side, uc - mw / 2 + 0.025, uc + mw / 2 - 0.025, z0 + 0.03, z1 - 0.025, 0.202
        )
        b.mesh([screen], tx.desktop_screen(rng))
    kb = (40, 40, 45) if rng.uniform() < 0.6 else (215, 212, 200)
    kc = u0 + width / 2 + float(rng.uniform(-0.2, 0.2))
    parts.append(room.box(side, kc - 0.22, kc + 0.22, 0.42, 0.58, top, top + 0.025, kb))
    pc = (35, 35, 40) if rng.uniform() < 0.5 else (205, 200, 185)
    pu = u0 + width - 0.32 if rng.uniform() < 0.5 else u0 + 0.12
    parts.append(room.box(side, pu, pu + 0.2, 0.1, 0.55, 0.0, 0.45, pc))
    parts.append(room.box(side, pu + 0.03, pu + 0.17, 0.55, 0.56, 0.3, 0.42, (90, 90, 90)))
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, top + 0.7)
    chair(b, room, side, u0 + width / 2 + float(rng.uniform(-0.3, 0.3)), depth - 0.07)


def chair(b: Builder, room: Room, side: str, uc: float, d0: float) -> None:
    """An office chair from ``d0`` to ``d0 + 0.52`` off wall ``side``, its back to the room.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it faces.
    uc : float
        Its centre along the wall (m).
    d0 : float
        Distance of its front from the wall (m).
    """
    v = b.choices
    seat = v.color((45, 70, 150), dh=0.5, ds=0.3, dv=0.3)
    dark = (35, 35, 38)
    dc = d0 + 0.25
    parts = [
        room.box(side, uc - 0.27, uc + 0.27, dc - 0.27, dc + 0.27, 0.02, 0.08, dark),
        room.cyl(side, uc, dc, 0.08, 0.42, 0.03, dark),
        room.box(side, uc - 0.23, uc + 0.23, dc - 0.22, dc + 0.22, 0.42, 0.5, seat),
        room.box(side, uc - 0.03, uc + 0.03, dc + 0.2, dc + 0.24, 0.42, 0.6, dark),
        room.box(side, uc - 0.22, uc + 0.22, dc + 0.2, dc + 0.27, 0.58, 0.95, seat),
    ]
    b.solid(parts)


def shelf(
    b: Builder,
    room: Room,
    side: str,
    u0: float,
    width: float,
    height: float = 1.85,
    depth: float = 0.35,
    frame: RGB = (120, 85, 55),
    binders: bool = False,
    palette: Sequence[RGB] | None = None,
) -> None:
    """A bookshelf with coarse blocks of coloured books or binders on its shelves.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands against.
    u0 : float
        Its left end along the wall (m).
    width, height, depth : float
        Its size (m).
    frame : sequence of float
        Colour of the frame.
    binders : bool
        Taller, deeper blocks like office binders.
    palette : sequence of RGB, optional
        Colours of the books (each block one of them, a little lighter or darker);
        default: any colour.
    """
    rng = b.rng
    frame = np.asarray(frame, np.float32)
    inner = frame * np.float32(0.55)
    t = 0.03
    parts = [
        room.box(side, u0, u0 + t, 0.0, depth, 0.0, height, frame),
        room.box(side, u0 + width - t, u0 + width, 0.0, depth, 0.0, height, frame),
        room.box(side, u0, u0 + width, 0.0, depth, height - t, height, frame),
        room.box(side, u0, u0 + width, 0.0, depth, 0.0, 0.08, frame),
        room.box(side, u0 + t, u0 + width - t, 0.0, 0.02, 0.08, height - t, inner),
    ]
    n = max(3, int(round((height - 0.1) / 0.38)))
    edges = np.linspace(0.08, height - t, n + 1)
    for k, (z0, z1) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        if k > 0:
            parts.append(room.box(side, u0 + t, u0 + width - t, 0.0, depth, z0, z0 + 0.025, frame))
        u = u0 + t + 0.02
        while u < u0 + width - t - 0.15:
            bw = float(min(rng.uniform(0.12, 0.4), u0 + width - t - 0.02 - u))
            if rng.uniform() < 0.8:
                zt = z0 + 0.025 + (z1 - z0 - 0.04) * rng.uniform(0.65 if binders else 0.55, 0.95)
                if palette is None:
                    c = tx.random_color(rng, s=(0.4, 1.0), v=(0.35, 0.95))
                else:
                    c = np.asarray(palette[int(rng.integers(len(palette)))], np.float32)
                    c = c * np.float32(rng.uniform(0.9, 1.08))
                dd = depth - 0.03 if binders else depth - 0.06
                parts.append(room.box(side, u, u + bw, 0.03, dd, z0 + 0.025, zt, c))
            u += bw + 0.01
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, height)


def cabinet(
    b: Builder, room: Room, side: str, u0: float, width: float, height: float, rgb: RGB
) -> list[Part]:
    """A low cabinet or chest of drawers, 0.45 m deep, against wall ``side``.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands against.
    u0 : float
        Its left end along the wall (m).
    width, height : float
        Its size (m).
    rgb : sequence of float
        Its colour.

    Returns
    -------
    list of Part
        Its parts, not yet built: add things standing on it, then ``b.solid(parts)``.
    """
    body = np.asarray(rgb, np.float32)
    depth = 0.45
    parts = [room.box(side, u0, u0 + width, 0.0, depth, 0.05, height, body)]
    parts.append(
        room.box(side, u0 + 0.03, u0 + width - 0.03, 0.0, depth - 0.03, 0.0, 0.05, body * 0.4)
    )
    n = 3 if height > 0.6 else 2
    for k in range(n):
        z0 = 0.08 + k * (height - 0.1) / n
        z1 = z0 + (height - 0.1) / n - 0.03
        parts.append(
            room.box(side, u0 + 0.03, u0 + width - 0.03, depth, depth + 0.015, z0, z1, body * 0.9)
        )
        uc = u0 + width / 2
        parts.append(
            room.box(
                side,
                uc - 0.1,
                uc + 0.1,
                depth + 0.015,
                depth + 0.03,
                z1 - 0.07,
                z1 - 0.04,
                (60, 60, 60),
            )
        )
    room.walls[side].take(u0, u0 + width, 0.0, height)
    return parts


def plant(b: Builder, room: Room, side: str, u: float, d: float, big: bool = True) -> None:
    """A potted plant (a pot and two or three leafy balls) ``d`` metres off wall ``side``.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands at.
    u, d : float
        Position along and out of the wall (m).
    big : bool
        Big (about 1.2 m) or small.
    """
    rng = b.rng
    pot = tx.hsv(rng.uniform(0.02, 0.08), rng.uniform(0.5, 0.8), rng.uniform(0.45, 0.75))
    h = 0.35 if big else 0.2
    parts = [room.cyl(side, u, d, 0.0, h, 0.17 if big else 0.12, pot)]
    for k in range(3 if big else 2):
        r = float(rng.uniform(0.18, 0.28) if big else rng.uniform(0.12, 0.18))
        z = h + r + k * r * 1.1
        du, dd = rng.uniform(-0.1, 0.1, 2)
        leaf = tx.hsv(rng.uniform(0.25, 0.38), rng.uniform(0.5, 0.8), rng.uniform(0.3, 0.55))
        parts.append(room.ball(side, u + du, d + dd, z, r, leaf))
    b.solid(parts)


def sofa(
    b: Builder,
    room: Room,
    side: str,
    u0: float,
    width: float,
    rgb: RGB,
    pillows: RGB | None = None,
) -> None:
    """A sofa with cushions and pillows, ``width`` long, 0.9 m deep, against wall ``side``.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands against.
    u0 : float
        Its left end along the wall (m).
    width : float
        Its length (m).
    rgb : sequence of float
        Upholstery colour.
    pillows : sequence of float, optional
        Colour of both pillows (default: two random bright colours).
    """
    rng = b.rng
    c = np.asarray(rgb, np.float32)
    depth = 0.9
    parts = [
        room.box(side, u0, u0 + width, 0.05, depth, 0.08, 0.42, c * 0.9),
        room.box(side, u0, u0 + width, 0.05, 0.3, 0.42, 0.88, c),
        room.box(side, u0, u0 + 0.2, 0.05, depth, 0.42, 0.64, c * 0.85),
        room.box(side, u0 + width - 0.2, u0 + width, 0.05, depth, 0.42, 0.64, c * 0.85),
    ]
    n = 3 if width > 1.7 else 2
    cw = (width - 0.4) / n
    for k in range(n):
        ua = u0 + 0.2 + k * cw
        parts.append(
            room.box(side, ua + 0.01, ua + cw - 0.01, 0.3, depth - 0.02, 0.42, 0.53, c * 1.05)
        )
    for ua in (u0 + 0.25, u0 + width - 0.65):
        if pillows is None:
            pillow = tx.random_color(rng, s=(0.5, 1.0), v=(0.6, 1.0))
        else:
            pillow = pillows
        parts.append(room.box(side, ua, ua + 0.4, 0.3, 0.45, 0.53, 0.88, pillow))
    for ua in (u0 + 0.03, u0 + width - 0.08):
        parts.append(room.box(side, ua, ua + 0.05, 0.1, 0.15, 0.0, 0.08, (50, 35, 25)))
        parts.append(
            room.box(side, ua, ua + 0.05, depth - 0.1, depth - 0.05, 0.0, 0.08, (50, 35, 25))
        )
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, 0.95)


def wardrobe(
    b: Builder,
    room: Room,
    side: str,
    u0: float,
    width: float = 1.2,
    height: float = 2.1,
    depth: float = 0.6,
    rgb: RGB = (232, 230, 224),
) -> None:
    """A plain wardrobe with two (or three, from 1.3 m wide) doors against wall ``side``.

    The doors stand a little proud of the carcass with a dark gap between them and a
    slim vertical handle each; the plinth is recessed and darker.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands against.
    u0 : float
        Its left end along the wall (m).
    width, height, depth : float
        Its size (m); the doors add 2 cm to the depth.
    rgb : sequence of float
        Its colour.
    """
    body = np.asarray(rgb, np.float32)
    n = 2 if width < 1.3 else 3
    dw = width / n
    handle = (150, 150, 152)
    parts = [
        room.box(side, u0, u0 + width, 0.0, depth, 0.07, height, body),
        room.box(side, u0 + 0.03, u0 + width - 0.03, 0.0, depth - 0.03, 0.0, 0.07, body * 0.5),
    ]
    front, top = depth + 0.02, height - 0.02
    for k in range(n):
        a = u0 + k * dw
        parts.append(
            room.box(side, a + 0.007, a + dw - 0.007, depth, front, 0.08, top, body * 0.97)
        )
        if k > 0:  # the dark gap between two doors
            parts.append(
                room.box(side, a - 0.01, a + 0.01, depth, front - 0.008, 0.08, top, body * 0.45)
            )
        hu = a + dw - 0.07 if k % 2 == 0 else a + 0.05
        parts.append(room.box(side, hu, hu + 0.02, front, front + 0.025, 0.85, 1.25, handle))
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, height)


def dining_chair(
    b: Builder, room: Room, side: str, u0: float, d0: float, facing: int, rgb: RGB
) -> None:
    """A plain wooden chair, 0.42 m square, its seat ``u0..u0 + 0.42`` along wall ``side``.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands along.
    u0, d0 : float
        The seat's corner nearest the wall's left end and the wall (m).
    facing : int
        ``+1``: it faces along the wall to the right (its back at ``u0``), ``-1``: to
        the left (its back at ``u0 + 0.42``).
    rgb : sequence of float
        Its colour.
    """
    c = np.asarray(rgb, np.float32)
    s, t = 0.42, 0.035
    ub = u0 if facing > 0 else u0 + s - t  # the back's side
    uf = u0 + s - t if facing > 0 else u0  # the front's side
    parts = [room.box(side, u0, u0 + s, d0, d0 + s, 0.42, 0.46, c)]
    for dd in (d0, d0 + s - t):
        parts.append(room.box(side, uf, uf + t, dd, dd + t, 0.0, 0.42, c * 0.85))
        parts.append(room.box(side, ub, ub + t, dd, dd + t, 0.0, 0.9, c * 0.85))
    parts.append(room.box(side, ub, ub + t, d0, d0 + s, 0.68, 0.88, c))
    b.solid(parts)


def dining_table(
    b: Builder,
    room: Room,
    side: str,
    u0: float,
    width: float = 1.2,
    depth: float = 0.8,
    wood: RGB = (196, 164, 122),
    chairs: RGB | None = None,
) -> None:
    """A table pushed against wall ``side`` with a chair at each end (along the wall).

    The table stands from ``u0`` to ``u0 + width``, the chairs 5 cm beyond its ends, so
    the whole set spans ``u0 - 0.47 .. u0 + width + 0.47`` and stays within ``depth``
    of the wall.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    room : Room
        The room.
    side : str
        The wall it stands against.
    u0 : float
        The table's left end along the wall (m).
    width, depth : float
        The table's size (m).
    wood : sequence of float
        Colour of the table.
    chairs : sequence of float, optional
        Colour of the chairs (default: the table's).
    """
    w = np.asarray(wood, np.float32)
    top, leg = 0.75, 0.06
    parts = [room.box(side, u0, u0 + width, 0.0, depth, top - 0.035, top, w)]
    for uu in (u0 + 0.04, u0 + width - 0.04 - leg):
        for dd in (0.04, depth - 0.04 - leg):
            parts.append(room.box(side, uu, uu + leg, dd, dd + leg, 0.0, top - 0.035, w * 0.9))
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, top)
    chair_rgb = w if chairs is None else chairs
    dc = depth / 2 - 0.21
    dining_chair(b, room, side, u0 - 0.47, dc, 1, chair_rgb)
    dining_chair(b, room, side, u0 + width + 0.05, dc, -1, chair_rgb)


def floor_lamp(b: Builder, room: Room, side: str, u: float, d: float) -> None:
    """A 1.6 m floor lamp ``d`` metres off wall ``side`` at ``u`` along it."""
    rng = b.rng
    shade = tx.hsv(rng.uniform(0.08, 0.14), rng.uniform(0.1, 0.4), 0.95)
    metal = (60, 55, 50)
    b.solid(
        [
            room.cyl(side, u, d, 0.0, 0.04, 0.16, metal),
            room.cyl(side, u, d, 0.04, 1.4, 0.02, metal),
            room.cyl(side, u, d, 1.3, 1.62, 0.22, shade),
        ]
    )


def sun(b: Builder, canonical: tuple[float, float, float]) -> tuple[float, float, float]:
    """The light direction: ``canonical`` or, when randomising, a random sun.

    A random sun has any azimuth and an elevation of 35-75°.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    canonical : tuple of float
        Direction towards the light in the canonical scene (need not be unit length).

    Returns
    -------
    tuple of float
        Unit vector towards the light.
    """
    if b.choices.randomize:
        az = b.rng.uniform(0.0, 2.0 * math.pi)
        el = b.rng.uniform(math.radians(35.0), math.radians(75.0))
        vec = (math.cos(az) * math.cos(el), math.sin(az) * math.cos(el), math.sin(el))
    else:
        vec = canonical
    n = math.sqrt(sum(c * c for c in vec))
    return (vec[0] / n, vec[1] / n, vec[2] / n)


def wall_colors(b: Builder, canonical: RGB) -> dict[str, np.ndarray]:
    """The same paint on all walls (canonical) or a random light paint (randomised).

    Parameters
    ----------
    b : Builder
        The scene's builder.
    canonical : sequence of float
        Paint of the canonical scene.

    Returns
    -------
    dict of str to numpy.ndarray
        Paint per side (``"E"``, ``"N"``, ``"W"``, ``"S"``) for :class:`Room`; replace an
        entry to paint one wall differently.
    """
    v = b.choices
    if v.randomize:
        if b.rng.uniform() < 0.6:
            base = tx.hsv(b.rng.uniform(), b.rng.uniform(0.02, 0.2), b.rng.uniform(0.82, 0.95))
        else:
            base = tx.hsv(b.rng.uniform(), b.rng.uniform(0.15, 0.45), b.rng.uniform(0.6, 0.9))
    else:
        base = np.asarray(canonical, np.float32)
    return {s: base for s in "ENWS"}


# deprecated: wall_colours, the British spelling of wall_colors, served for one release
__getattr__ = moved_names(__name__, {"wall_colours": (sys.modules[__name__], "wall_colors")})
