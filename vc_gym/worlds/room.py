"""A seeded rectangular room and a tiny 2.5-D ray caster that renders it from any position.

:mod:`vc_gym.worlds.panorama` renders views of a panorama, i.e. of a scene at infinity
seen from one fixed viewpoint: it can test the compass for rotation only. This module
renders a room with textured walls from any ``(x, y)`` position inside it, so nearby
walls look bigger than far ones and features shift against each other as the camera
moves (parallax): the compass can be tested for *translation*.

:func:`make_room` paints a procedural "robot lab" (posters, doors, windows, a
whiteboard, desks with computers and cabinets along one wall) from a numpy random
generator; :func:`render_room_view` ray-casts the view a
:class:`~vc_gym.compass.camera.Camera` sees from a given position. The walls are flat
(2.5-D): furniture is painted on them, there are no occluders inside the room.

Conventions
-----------
World ``x`` points forward/east, ``y`` left/north, ``z`` up, in metres; the room is the
box ``[-width/2, width/2] x [-depth/2, depth/2] x [0, wall_height]``. Yaw is in degrees,
counter-clockwise from ``+x`` (the convention of :mod:`vc_gym.angles`).

The wall texture is the four walls unrolled counter-clockwise (seen from above) into
one image. Its columns follow the arc length ``s`` along the perimeter, starting at the
corner ``(+W/2, -D/2)`` (``W = width_m``, ``D = depth_m``):

============  ======================  ===========================================
wall          ``s`` range             point on the wall
============  ======================  ===========================================
``x = +W/2``  ``[0, D]``              ``y = -D/2 + s``
``y = +D/2``  ``[D, D + W]``          ``x = +W/2 - (s - D)``
``x = -W/2``  ``[D + W, 2D + W]``     ``y = +D/2 - (s - D - W)``
``y = -D/2``  ``[2D + W, 2D + 2W]``   ``x = -W/2 + (s - 2D - W)``
============  ======================  ===========================================

Texture column ``c`` (pixel centre ``c + 0.5``) is at ``s = (c + 0.5) P / Wt`` with
``P = 2 (W + D)`` the perimeter and ``Wt`` the texture width; row ``r`` is at height
``z = wall_height - (r + 0.5) wall_height / Ht`` (row 0 at the top). Seen from inside
the room ``s`` increases to the *left*, so the texture image appears mirrored left to
right in the views (like a panorama unrolled the other way round).

A camera pixel ``(u, v)`` of a ``w x h`` view has the camera-frame ray
``x = (u - cx) / f`` (right), ``y_up = (cy - v) / f`` (up), forward ``1``, with
``f = (w / 2) / tan(hfov / 2)`` and ``(cx, cy)`` the principal point. Pitched up by
``θ``: ``forward = cos θ - sin θ y_up``, ``up = sin θ + cos θ y_up``, ``left = -x``;
the horizontal part ``(forward, left)`` is rotated by the yaw into the world. These are
the rays of :func:`vc_gym.worlds.rays.ray_grid`, shared with the panorama renderer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.exposure import gain_table
from vc_gym.images import check_image
from vc_gym.validation import finite_float, int_at_least, positive_float
from vc_gym.worlds.paint import hsv, random_color, value_noise
from vc_gym.worlds.rays import REMAP_MAX_SIDE, ray_grid

__all__ = ["Room", "make_room", "render_room_view"]

#: Side of the square carpet tiles of the floor pattern (metres).
FLOOR_TILE_M = 0.5


def _rgb(name: str, value: object) -> tuple[int, int, int]:
    """Validate an RGB triple of integers in 0..255."""
    try:
        items = tuple(value)  # type: ignore[arg-type]
    except TypeError:
        raise ValueError(f"{name} must be an (r, g, b) tuple, got {value!r}") from None
    if len(items) != 3:
        raise ValueError(f"{name} must be an (r, g, b) tuple, got {value!r}")
    out = []
    for c in items:
        if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or not 0 <= c <= 255:
            raise ValueError(f"{name} must hold three integers in 0..255, got {value!r}")
        out.append(int(c))
    return out[0], out[1], out[2]


# ------------------------------------------------------------------------------ Room


@dataclass(frozen=True, eq=False)
class Room:
    """A rectangular room with textured walls, a floor and a ceiling (or open sky).

    Parameters
    ----------
    width_m : float
        Extent along ``x``; the room spans ``[-width_m/2, width_m/2]``.
    depth_m : float
        Extent along ``y``; the room spans ``[-depth_m/2, depth_m/2]``.
    wall_height_m : float
        Height of the walls (and of the ceiling).
    wall_texture : numpy.ndarray
        ``(Ht, Wt, 3)`` ``uint8`` RGB: the four walls unrolled counter-clockwise from
        the corner ``(+width/2, -depth/2)``, columns along the perimeter arc length,
        rows from the top (``z = wall_height``) to the bottom (``z = 0``); see the
        module conventions. Any size works (the scale is ``Wt`` over the perimeter
        horizontally and ``Ht / wall_height`` vertically), but ``Wt`` must be below
        32767 (a ``cv2.remap`` limit). Not copied: do not modify it while in use.
    floor_rgb : tuple of int
        Floor (carpet) colour.
    ceiling_rgb : tuple of int or None
        Ceiling colour; ``None`` means an open top (rays above the walls see the sky).
    sky_rgb : tuple of int
        Colour seen above the walls when ``ceiling_rgb`` is ``None``.

    Raises
    ------
    ValueError
        On a non-positive or non-finite size, a bad texture or a bad colour.

    Notes
    -----
    Equality and hashing are by identity (the texture is a numpy array).
    """

    width_m: float
    depth_m: float
    wall_height_m: float
    wall_texture: np.ndarray
    floor_rgb: tuple[int, int, int]
    ceiling_rgb: tuple[int, int, int] | None
    sky_rgb: tuple[int, int, int] = (150, 190, 230)

    def __post_init__(self) -> None:
        object.__setattr__(self, "width_m", positive_float("width_m", self.width_m))
        object.__setattr__(self, "depth_m", positive_float("depth_m", self.depth_m))
        object.__setattr__(
            self, "wall_height_m", positive_float("wall_height_m", self.wall_height_m)
        )
        check_image(self.wall_texture, "wall_texture")
        if self.wall_texture.shape[1] > REMAP_MAX_SIDE:
            raise ValueError(
                f"wall_texture is {self.wall_texture.shape[1]} pixels wide; it must be "
                f"at most {REMAP_MAX_SIDE} (a cv2.remap limit)"
            )
        object.__setattr__(self, "floor_rgb", _rgb("floor_rgb", self.floor_rgb))
        if self.ceiling_rgb is not None:
            object.__setattr__(self, "ceiling_rgb", _rgb("ceiling_rgb", self.ceiling_rgb))
        object.__setattr__(self, "sky_rgb", _rgb("sky_rgb", self.sky_rgb))

    @property
    def perimeter_m(self) -> float:
        """Length of the perimeter, ``2 (width + depth)``: the texture's horizontal span."""
        return 2.0 * (self.width_m + self.depth_m)

    def wall_point(self, s: float) -> tuple[float, float]:
        """World ``(x, y)`` of the point at arc length ``s`` (wrapped) along the walls."""
        w, d = self.width_m, self.depth_m
        s = float(np.mod(finite_float("s", s), self.perimeter_m))
        if s <= d:
            return w / 2.0, -d / 2.0 + s
        if s <= d + w:
            return w / 2.0 - (s - d), d / 2.0
        if s <= 2.0 * d + w:
            return -w / 2.0, d / 2.0 - (s - d - w)
        return -w / 2.0 + (s - 2.0 * d - w), -d / 2.0


# ------------------------------------------------------------------------- make_room


class _Texture:
    """Float RGB wall texture painted in metres: arc length ``s`` and height ``z``."""

    def __init__(self, perimeter: float, height: float, px_per_m: int) -> None:
        self.width = max(2, int(round(perimeter * px_per_m)))
        self.height = max(2, int(round(height * px_per_m)))
        self.sx = self.width / perimeter
        self.sz = self.height / height
        self.wall_height = height
        self.img = np.zeros((self.height, self.width, 3), dtype=np.float32)
        self._s = (np.arange(self.width) + 0.5) / self.sx  # increasing
        self._neg_z = (np.arange(self.height) + 0.5) / self.sz - height  # -z, increasing

    def region(self, s0: float, s1: float, z0: float, z1: float) -> tuple[slice, slice]:
        """Rows and columns whose pixel centres lie in ``[s0, s1) x [z0, z1)``."""
        c0, c1 = np.searchsorted(self._s, [s0, s1], side="left")
        r0, r1 = np.searchsorted(self._neg_z, [-z1, -z0], side="right")
        return slice(int(r0), int(r1)), slice(int(c0), int(c1))

    def rect(self, s0: float, s1: float, z0: float, z1: float, color: np.ndarray) -> None:
        self.img[self.region(s0, s1, z0, z1)] = color

    def scale(self, s0: float, s1: float, z0: float, z1: float, factor: float) -> None:
        self.img[self.region(s0, s1, z0, z1)] *= np.float32(factor)

    def disc(self, sc: float, zc: float, radius: float, color: np.ndarray) -> None:
        rows, cols = self.region(sc - radius, sc + radius, zc - radius, zc + radius)
        s = self._s[cols][None, :]
        z = -self._neg_z[rows][:, None]
        block = self.img[rows, cols]
        block[(s - sc) ** 2 + (z - zc) ** 2 <= radius * radius] = color
        self.img[rows, cols] = block


class _Layout:
    """Free intervals along each wall, per layer ("low": floor-standing, "high": hung)."""

    def __init__(self, rng: np.random.Generator, lengths: list[float]) -> None:
        self.rng = rng
        self.lengths = lengths
        self.used: dict[str, list[list[tuple[float, float]]]] = {
            "low": [[] for _ in lengths],
            "high": [[] for _ in lengths],
        }

    def place(
        self, walls: list[int], width: float, layers: tuple[str, ...], margin: float = 0.15
    ) -> tuple[int, float, float] | None:
        """A random free interval ``(wall, a, b)`` of ``width`` metres, or ``None``."""
        for _ in range(30):
            wall = int(walls[int(self.rng.integers(len(walls)))])
            room = self.lengths[wall] - 2.0 * margin - width
            if room < 0.0:
                continue
            a = margin + float(self.rng.uniform(0.0, room))
            b = a + width
            gap = 0.12
            if all(
                b + gap <= ua or a >= ub + gap
                for layer in layers
                for ua, ub in self.used[layer][wall]
            ):
                for layer in layers:
                    self.used[layer][wall].append((a, b))
                return wall, a, b
        return None


def _vivid(rng: np.random.Generator) -> np.ndarray:
    """A saturated poster colour."""
    return random_color(rng, s=(0.45, 0.95), v=(0.45, 0.95))


def _furniture_color(rng: np.random.Generator) -> np.ndarray:
    """Grey, beige, wood or (sometimes) a colourful lacquer."""
    kind = rng.uniform()
    if kind < 0.35:  # grey / white laminate
        return hsv(rng.uniform(), rng.uniform(0.0, 0.08), rng.uniform(0.45, 0.9))
    if kind < 0.7:  # wood
        return hsv(rng.uniform(0.05, 0.11), rng.uniform(0.35, 0.65), rng.uniform(0.4, 0.8))
    return hsv(rng.uniform(), rng.uniform(0.35, 0.8), rng.uniform(0.35, 0.8))


def _paint_door(rng: np.random.Generator, tex: _Texture, s0: float, s1: float) -> None:
    top = min(rng.uniform(2.0, 2.12), tex.wall_height - 0.1)
    casing = hsv(rng.uniform(), rng.uniform(0.0, 0.12), rng.uniform(0.75, 0.95))
    if rng.uniform() < 0.6:
        leaf = hsv(rng.uniform(0.05, 0.11), rng.uniform(0.4, 0.75), rng.uniform(0.35, 0.7))
    else:
        leaf = _vivid(rng) * np.float32(0.8)
    trim = 0.07
    tex.rect(s0, s1, 0.0, top + trim, casing)
    tex.rect(s0 + trim, s1 - trim, 0.0, top, leaf)


def _paint_window(rng: np.random.Generator, tex: _Texture, s0: float, s1: float) -> None:
    z0 = rng.uniform(0.95, 1.2)
    z1 = min(rng.uniform(2.0, 2.3), tex.wall_height - 0.12)
    frame = hsv(rng.uniform(), rng.uniform(0.0, 0.1), rng.uniform(0.82, 0.97))
    trim = 0.07
    tex.rect(s0, s1, z0, z1, frame)
    tex.rect(s0 - 0.05, s1 + 0.05, z0 - 0.06, z0, frame * np.float32(0.85))  # sill
    rows, cols = tex.region(s0 + trim, s1 - trim, z0 + trim, z1 - trim)
    if rows.stop > rows.start and cols.stop > cols.start:
        hue = rng.uniform(0.53, 0.62)
        lower = hsv(hue, rng.uniform(0.05, 0.25), rng.uniform(0.78, 0.92))
        upper = hsv(hue, rng.uniform(0.25, 0.5), rng.uniform(0.85, 1.0))
        t = np.linspace(1.0, 0.0, rows.stop - rows.start, dtype=np.float32)[:, None, None]
        tex.img[rows, cols] = lower * (1.0 - t) + upper * t
    if z1 - z0 > 0.9 and rng.uniform() < 0.5:  # a transom bar
        zt = z1 - rng.uniform(0.3, 0.4)
        tex.rect(s0, s1, zt - 0.035, zt + 0.035, frame)


def _paint_whiteboard(rng: np.random.Generator, tex: _Texture, s0: float, s1: float) -> None:
    z0 = rng.uniform(0.85, 1.0)
    z1 = min(z0 + rng.uniform(1.0, 1.2), tex.wall_height - 0.1)
    frame = hsv(0.6, 0.03, rng.uniform(0.55, 0.7))
    tex.rect(s0, s1, z0, z1, frame)
    tex.rect(s0 + 0.04, s1 - 0.04, z0 + 0.04, z1 - 0.04, hsv(0.6, 0.02, 0.97))
    tex.rect(s0 + 0.1, s1 - 0.1, z0 - 0.05, z0, frame * np.float32(0.8))  # marker tray
    # a few sheets of paper / big scribbles pinned to it
    for _ in range(int(rng.integers(0, 4))):
        w, h = rng.uniform(0.3, 0.45), rng.uniform(0.3, 0.45)
        if s1 - s0 - 0.2 < w or z1 - z0 - 0.2 < h:
            continue
        a = rng.uniform(s0 + 0.1, s1 - 0.1 - w)
        b = rng.uniform(z0 + 0.1, z1 - 0.1 - h)
        tex.rect(a, a + w, b, b + h, hsv(rng.uniform(), rng.uniform(0.15, 0.6), 0.9))


def _paint_poster(
    rng: np.random.Generator, tex: _Texture, s0: float, s1: float, z_min: float
) -> None:
    width = s1 - s0
    z0 = z_min + rng.uniform(0.0, 0.35)
    z1 = min(z0 + width * rng.uniform(0.8, 1.4), tex.wall_height - 0.12)
    z1 = max(z1, min(z0 + 0.4, tex.wall_height - 0.05))
    outer = _vivid(rng)
    tex.rect(s0, s1, z0, z1, outer)
    inset = min(rng.uniform(0.04, 0.1), 0.2 * width, 0.2 * (z1 - z0))
    a0, a1, b0, b1 = s0 + inset, s1 - inset, z0 + inset, z1 - inset
    inner = _vivid(rng)
    tex.rect(a0, a1, b0, b1, inner)
    style = rng.uniform()
    if style < 0.3:  # two-tone "landscape"
        split = b0 + rng.uniform(0.3, 0.6) * (b1 - b0)
        tex.rect(a0, a1, b0, split, _vivid(rng))
    elif style < 0.55:  # vertical halves
        split = a0 + rng.uniform(0.35, 0.65) * (a1 - a0)
        tex.rect(a0, split, b0, b1, _vivid(rng))
    elif style < 0.8:  # a big disc ("logo")
        r = 0.35 * min(a1 - a0, b1 - b0)
        tex.disc(0.5 * (a0 + a1), 0.5 * (b0 + b1), r, _vivid(rng))
    else:  # a title band at the top
        tex.rect(a0, a1, b1 - rng.uniform(0.12, 0.2), b1, _vivid(rng))


def _paint_cabinet(
    rng: np.random.Generator, tex: _Texture, s0: float, s1: float, max_top: float
) -> None:
    top = min(rng.uniform(0.7, max_top), tex.wall_height - 0.15)
    body = _furniture_color(rng)
    tex.rect(s0, s1, 0.0, top, body)
    # drawers or doors: alternating shades in coarse horizontal bands
    n = max(1, int(round(top / rng.uniform(0.35, 0.6))))
    edges = np.linspace(0.08, top - 0.04, n + 1)
    for i, (lo, hi) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        tex.rect(
            s0 + 0.03, s1 - 0.03, lo + 0.015, hi - 0.015, body * np.float32(0.9 + 0.12 * (i % 2))
        )
    tex.rect(s0, s1, 0.0, 0.08, body * np.float32(0.45))  # plinth
    if top < 1.3 and max_top > 1.0 and rng.uniform() < 0.6:  # a box or a robot on top
        w = min(rng.uniform(0.3, 0.55), s1 - s0 - 0.1)
        a = rng.uniform(s0 + 0.05, s1 - 0.05 - w)
        tex.rect(a, a + w, top, top + rng.uniform(0.25, 0.4), _vivid(rng) * np.float32(0.85))


def _paint_desk(
    rng: np.random.Generator, tex: _Texture, s0: float, s1: float, wall_rgb: np.ndarray
) -> None:
    top = rng.uniform(0.72, 0.78)
    slab = rng.uniform(0.05, 0.07)
    wood = _furniture_color(rng)
    tex.rect(s0, s1, 0.0, top - slab, wall_rgb * np.float32(rng.uniform(0.4, 0.55)))  # shadow
    tex.rect(s0, s1, top - slab, top, wood)
    panel = 0.1
    tex.rect(s0, s0 + panel, 0.0, top, wood * np.float32(0.75))  # side panels
    tex.rect(s1 - panel, s1, 0.0, top, wood * np.float32(0.75))
    # a PC tower under the desk
    if rng.uniform() < 0.7 and s1 - s0 > 0.9:
        a = rng.uniform(s0 + panel + 0.05, s1 - panel - 0.35)
        case = hsv(rng.uniform(), rng.uniform(0.0, 0.1), rng.uniform(0.1, 0.8))
        tex.rect(a, a + 0.3, 0.02, min(0.5, top - slab - 0.05), case)
    # one or two monitors on the desk
    n_mon = 1 if s1 - s0 < 1.4 else int(rng.integers(1, 3))
    slots = np.linspace(s0, s1, n_mon + 2)[1:-1]
    for centre in slots:
        w = rng.uniform(0.5, 0.65)
        h = rng.uniform(0.32, 0.42)
        lift = rng.uniform(0.1, 0.16)
        bezel = hsv(rng.uniform(), rng.uniform(0.0, 0.08), rng.uniform(0.08, 0.3))
        tex.rect(centre - 0.06, centre + 0.06, top, top + lift + 0.02, bezel)  # stand
        tex.rect(centre - w / 2, centre + w / 2, top + lift, top + lift + h, bezel)
        screen = hsv(rng.uniform(), rng.uniform(0.2, 0.7), rng.uniform(0.35, 0.85))
        tex.rect(centre - w / 2 + 0.03, centre + w / 2 - 0.03, top + lift + 0.03,
                 top + lift + h - 0.03, screen)  # fmt: skip
        if rng.uniform() < 0.5:  # a window on the screen
            tex.rect(centre - w / 4, centre + w / 4, top + lift + h / 2, top + lift + h - 0.06,
                     hsv(rng.uniform(), rng.uniform(0.0, 0.3), 0.92))  # fmt: skip


def make_room(
    rng: np.random.Generator,
    width_m: float = 7.0,
    depth_m: float = 7.0,
    wall_height_m: float = 2.5,
    *,
    texture_px_per_m: int = 100,
    open_top: bool = False,
) -> Room:
    """Paint a procedural robot lab: pale walls with posters, doors, windows, desks.

    One random wall holds the "lab bench": desks with computer monitors (and PC towers
    underneath) and cabinets rising from the floor. The other walls get one or two
    doors, up to two windows, maybe a whiteboard, a few large colourful posters and
    maybe a low cabinet. Each wall is lit a little differently (so the corners show as
    vertical edges) and the whole texture gets mild, coarse brightness noise plus
    faint per-pixel noise. Everything is coarse: items are at least about 0.3 m wide,
    only frames, trims and desk slabs are thinner (4-10 cm), there are no stripes.

    The room depends only on ``rng``; the global ``numpy.random`` state is neither used
    nor changed.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of all randomness (``np.random.default_rng(seed)``).
    width_m, depth_m : float
        Room extent along ``x`` and ``y`` in metres, ``>= 2``.
    wall_height_m : float
        Wall height in metres, ``>= 2``.
    texture_px_per_m : int
        Texture resolution, ``>= 10`` pixels per metre, in both directions. The
        texture is ``round(perimeter * px_per_m)`` pixels wide, which must stay below
        32767.
    open_top : bool
        If true the room has no ceiling (``ceiling_rgb=None``): the sky shows above
        the walls.

    Returns
    -------
    Room
        The room, with a ``uint8`` RGB wall texture.

    Raises
    ------
    ValueError
        On a bad size or resolution.
    TypeError
        If ``rng`` is not a ``numpy.random.Generator``.
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"rng must be a numpy.random.Generator (np.random.default_rng(seed)), got "
            f"{type(rng).__name__}"
        )
    w = positive_float("width_m", width_m)
    d = positive_float("depth_m", depth_m)
    h = positive_float("wall_height_m", wall_height_m)
    for name, v in (("width_m", w), ("depth_m", d), ("wall_height_m", h)):
        if v < 2.0:
            raise ValueError(f"{name} must be >= 2 metres, got {v}")
    ppm = int_at_least("texture_px_per_m", texture_px_per_m, 10)
    perimeter = 2.0 * (w + d)
    if round(perimeter * ppm) > REMAP_MAX_SIDE or round(h * ppm) > REMAP_MAX_SIDE:
        raise ValueError(
            f"the wall texture would be {round(perimeter * ppm)} x {round(h * ppm)} pixels; "
            f"sides must be at most {REMAP_MAX_SIDE}: lower texture_px_per_m or the room size"
        )

    tex = _Texture(perimeter, h, ppm)
    lengths = [d, w, d, w]
    starts = [0.0, d, d + w, 2.0 * d + w]

    # --- plain walls with a baseboard
    wall_rgb = hsv(rng.uniform(), rng.uniform(0.03, 0.25), rng.uniform(0.78, 0.93))
    tex.img[:] = wall_rgb
    base_h = rng.uniform(0.07, 0.12)
    base_rgb = hsv(rng.uniform(), rng.uniform(0.0, 0.3), rng.uniform(0.2, 0.7))
    tex.rect(0.0, perimeter, 0.0, base_h, base_rgb)

    # --- furniture and things on the walls, biggest first
    layout = _Layout(rng, lengths)
    lab = int(rng.integers(4))
    others = [i for i in range(4) if i != lab]
    items: list[tuple[str, int, float, float]] = []

    def add(kind: str, walls: list[int], width: float, layers: tuple[str, ...]) -> None:
        spot = layout.place(walls, width, layers)
        if spot is not None:
            wall, a, b = spot
            items.append((kind, wall, a, b))

    # the lab bench: desks and (tall) cabinets packed along one wall, posters may hang
    # above the desks
    pos, end = 0.15 + rng.uniform(0.0, 0.5), lengths[lab] - 0.15
    while True:
        cabinet = rng.uniform() < 0.3
        size = rng.uniform(0.6, 1.2) if cabinet else rng.uniform(1.2, 1.8)
        if pos + size > end:
            break
        layers = ("low", "high") if cabinet else ("low",)
        for layer in layers:
            layout.used[layer][lab].append((pos, pos + size))
        items.append(("cabinet" if cabinet else "desk", lab, pos, pos + size))
        pos += size + rng.uniform(0.05, 0.6)
    for _ in range(int(rng.integers(1, 3))):
        add("door", others, rng.uniform(0.85, 1.0), ("low", "high"))
    if rng.uniform() < 0.6:
        add("whiteboard", others, rng.uniform(1.4, 2.4), ("high",))
    for _ in range(int(rng.integers(0, 3))):
        add("window", others, rng.uniform(1.0, 1.8), ("high",))
    for _ in range(int(rng.integers(0, 3))):
        add("cabinet", others, rng.uniform(0.6, 1.0), ("low",))
    for _ in range(int(rng.integers(8, 15))):
        add("poster", others + [lab], rng.uniform(0.5, 1.4), ("high",))

    for kind, wall, a, b in items:
        s0, s1 = starts[wall] + a, starts[wall] + b
        if kind == "desk":
            _paint_desk(rng, tex, s0, s1, wall_rgb)
        elif kind == "cabinet":
            # floor-standing cabinets on the other walls stay low (below the "high" layer)
            _paint_cabinet(rng, tex, s0, s1, max_top=2.0 if wall == lab else 0.95)
        elif kind == "door":
            _paint_door(rng, tex, s0, s1)
        elif kind == "whiteboard":
            _paint_whiteboard(rng, tex, s0, s1)
        elif kind == "window":
            _paint_window(rng, tex, s0, s1)
        else:  # above the monitors on the lab wall
            _paint_poster(rng, tex, s0, s1, z_min=1.45 if wall == lab else 0.95)

    # --- lighting: each wall a little different, coarse blotches, faint pixel noise
    light = rng.uniform(0.8, 1.05, 4).astype(np.float32)
    for i in range(4):
        tex.scale(starts[i], starts[i] + lengths[i], 0.0, h + 1.0, float(light[i]))
    cells_x = max(4, int(round(perimeter / 0.5)))
    cells_y = max(2, int(round(h / 0.5)))
    tex.img *= (1.0 + 0.03 * value_noise(rng, tex.height, tex.width, cells_x, cells_y))[:, :, None]
    tex.img += rng.standard_normal(tex.img.shape, dtype=np.float32) * np.float32(1.5)
    np.clip(tex.img, 0.0, 255.0, out=tex.img)
    texture = np.rint(tex.img).astype(np.uint8)

    if rng.uniform() < 0.55:  # green robot-soccer carpet
        floor = hsv(rng.uniform(0.24, 0.4), rng.uniform(0.3, 0.6), rng.uniform(0.35, 0.6))
    else:  # grey / blue-grey carpet
        floor = hsv(rng.uniform(0.5, 0.7), rng.uniform(0.0, 0.2), rng.uniform(0.3, 0.6))
    ceiling = hsv(rng.uniform(), rng.uniform(0.0, 0.06), rng.uniform(0.85, 0.96))

    def as_rgb(c: np.ndarray) -> tuple[int, int, int]:
        r, g, b = (int(v) for v in np.clip(np.rint(c), 0, 255))
        return r, g, b

    return Room(
        width_m=w,
        depth_m=d,
        wall_height_m=h,
        wall_texture=texture,
        floor_rgb=as_rgb(floor),
        ceiling_rgb=None if open_top else as_rgb(ceiling),
    )


# ------------------------------------------------------------------ render_room_view


def _tile_hash(ix: np.ndarray, iy: np.ndarray) -> np.ndarray:
    """Pseudo-random value in [-1, 1] per integer tile index pair (deterministic)."""
    h = ix.astype(np.int64).astype(np.uint64) * np.uint64(0x9E3779B1)
    h ^= iy.astype(np.int64).astype(np.uint64) * np.uint64(0x85EBCA77)
    h ^= h >> np.uint64(15)
    h *= np.uint64(0xC2B2AE3D)
    h ^= h >> np.uint64(13)
    return (h & np.uint64(0xFFFF)).astype(np.float32) * np.float32(2.0 / 65535.0) - np.float32(1.0)


def render_room_view(
    room: Room,
    x: float,
    y: float,
    camera: Camera,
    width: int = 208,
    height: int = 160,
    *,
    eye_height_m: float = 0.3,
    illumination: float = 1.0,
) -> np.ndarray:
    """Ray-cast the view ``camera`` sees from ``(x, y)`` inside ``room``.

    Each pixel's ray (module conventions) is cut with the four wall planes along its
    horizontal direction; the nearest hit gives the horizontal distance ``d`` and the
    perimeter coordinate ``s``, and the ray's elevation the hit height
    ``z = eye_height + d tan(elevation)``. If ``0 <= z <= wall_height`` the wall
    texture is sampled bilinearly at ``(s, z)`` (wrapping around the perimeter); below
    the wall the ray hits the floor (its colour with faint, square carpet tiles of
    :data:`FLOOR_TILE_M` whose contrast fades out where they would be smaller than a
    few pixels), above it the ceiling (or the sky, for an open room). The projection
    is exact, so nearby walls subtend larger angles than far ones (parallax).

    Parameters
    ----------
    room : Room
        The scene.
    x, y : float
        Camera position in metres; must be strictly inside the room.
    camera : Camera
        Horizontal field of view, yaw (optical axis direction, degrees CCW from
        ``+x``), pitch (positive up) and optional principal point.
    width, height : int
        Size of the rendered image, ``>= 2``. The Aibo camera is 208 x 160.
    eye_height_m : float
        Height of the camera above the floor, ``0 < eye_height_m < wall_height``.
    illumination : float
        Scale of the linear-light intensity, ``> 0``, applied after rendering exactly
        as in :func:`vc_gym.worlds.panorama.render_view` (sRGB to linear, scale,
        back to sRGB, clip).

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` ``uint8`` RGB image.

    Raises
    ------
    ValueError
        If the position is not strictly inside the room, the eye height is not
        strictly between floor and ceiling, a size is below 2, or the illumination is
        not finite and positive.
    TypeError
        If ``room`` is not a :class:`Room` or ``camera`` not a ``Camera``.
    """
    if not isinstance(room, Room):
        raise TypeError(f"room must be a Room, got {type(room).__name__}")
    if not isinstance(camera, Camera):
        raise TypeError(f"camera must be a Camera, got {type(camera).__name__}")
    width = int_at_least("width", width, 2)
    height = int_at_least("height", height, 2)
    px, py = finite_float("x", x), finite_float("y", y)
    hw, hd, wall_h = room.width_m / 2.0, room.depth_m / 2.0, room.wall_height_m
    if not (-hw < px < hw and -hd < py < hd):
        raise ValueError(
            f"camera position ({px}, {py}) must be strictly inside the room "
            f"(-{hw}, {hw}) x (-{hd}, {hd})"
        )
    eye = positive_float("eye_height_m", eye_height_m)
    if not eye < wall_h:
        raise ValueError(f"eye_height_m must be in (0, {wall_h}), got {eye_height_m!r}")
    illum = positive_float("illumination", illumination)

    focal = float(camera.focal_px(width))
    rays = ray_grid(camera, width, height)
    fw, lw, up = rays.forward, rays.left, rays.up
    yaw = math.radians(float(camera.yaw_deg))
    c, s = math.cos(yaw), math.sin(yaw)
    dx = c * fw - s * lw
    dy = s * fw + c * lw

    # ray parameter t (per unit of the un-normalised ray) to the x = ±W/2 and y = ±D/2
    # walls ahead; the camera is strictly inside, so both are positive (or +inf)
    tx = np.full(dx.shape, np.inf)
    ty = np.full(dx.shape, np.inf)
    np.divide(np.where(dx > 0, hw, -hw) - px, dx, out=tx, where=dx != 0)
    np.divide(np.where(dy > 0, hd, -hd) - py, dy, out=ty, where=dy != 0)
    x_wall = tx <= ty
    t = np.minimum(tx, ty)
    with np.errstate(invalid="ignore"):  # vertical rays: t = inf, dx = dy = 0
        z = eye + t * up
        hit_x = px + t * dx
        hit_y = py + t * dy
    perimeter_s = np.where(
        x_wall,
        np.where(dx > 0, hd + hit_y, 2.0 * hd + 2.0 * hw + (hd - hit_y)),
        np.where(dy > 0, 2.0 * hd + (hw - hit_x), 4.0 * hd + 2.0 * hw + (hit_x + hw)),
    )
    wall = (z >= 0.0) & (z <= wall_h)
    floor = z < 0.0
    above = ~(wall | floor)

    tex = room.wall_texture
    th, tw = tex.shape[:2]
    scale_s = tw / room.perimeter_m
    scale_z = th / wall_h
    map_x = np.where(wall, perimeter_s * scale_s - 0.5, 0.0)
    map_x = np.mod(map_x, tw).astype(np.float32)
    map_y = np.where(wall, (wall_h - z) * scale_z - 0.5, 0.0)
    np.clip(map_y, 0.0, th - 1.0, out=map_y)
    out = cv2.remap(
        np.ascontiguousarray(tex),
        map_x,
        map_y.astype(np.float32),
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_WRAP,
    )

    if floor.any():
        with np.errstate(divide="ignore", invalid="ignore"):
            t_floor = -eye / up[floor]
        fx = px + t_floor * dx[floor]
        fy = py + t_floor * dy[floor]
        dist = t_floor * np.hypot(fw[floor], lw[floor])
        # contrast fades where a tile would span fewer than ~3 pixels vertically
        tile_px = focal * eye * FLOOR_TILE_M / np.maximum(dist, 1e-9) ** 2
        fade = np.clip((tile_px - 2.0) / 6.0, 0.0, 1.0)
        idx = np.floor(fx / FLOOR_TILE_M), np.floor(fy / FLOOR_TILE_M)
        shade = 1.0 + 0.06 * _tile_hash(*idx) * fade
        floor_rgb = np.asarray(room.floor_rgb, dtype=float)
        out[floor] = np.clip(np.rint(floor_rgb[None, :] * shade[:, None]), 0, 255).astype(np.uint8)
    if above.any():
        out[above] = room.ceiling_rgb if room.ceiling_rgb is not None else room.sky_rgb

    if illum != 1.0:
        out = cv2.LUT(out, gain_table(illum))
    return out
