"""Procedural, seamless 360° panoramas painted from a numpy random generator.

:func:`make_panorama` paints an indoor room or an outdoor scene on a
:meth:`Canvas.panorama <vc_gym.worlds.canvas.Canvas.panorama>` and returns a
:class:`~vc_gym.worlds.panorama.Panorama` (whose docstring gives the pixel conventions:
moving right turns clockwise, rows are equirectangular elevations). Every feature is
painted with modular column indices (:meth:`Canvas.columns
<vc_gym.worlds.canvas.Canvas.columns>`), so it may straddle the 0/360 seam without a
discontinuity. The scene is coarse (large uniform regions and straight or smoothly curved
edges) so that a 208 x 160 camera does not alias it, and depends only on the generator.
"""

from __future__ import annotations

import math

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.validation import int_at_least, nonnegative_float
from vc_gym.worlds.canvas import Canvas
from vc_gym.worlds.paint import hsv, random_color, value_noise
from vc_gym.worlds.panorama import Panorama

__all__ = ["PANORAMA_KINDS", "make_panorama"]

#: Scene kinds understood by :func:`make_panorama`.
PANORAMA_KINDS = ("room", "outdoor")

#: Saturation and value ranges of the "any colour" items (rugs, books, posters, ...).
_VARIED = {"s": (0.15, 0.9), "v": (0.25, 0.95)}


def _free_spot(
    rng: np.random.Generator,
    occupied: list[tuple[float, float]],
    half_width: float,
    tries: int = 25,
) -> float | None:
    """A centre azimuth whose interval does not overlap the ``occupied`` ones."""
    for _ in range(tries):
        c = float(rng.uniform(0.0, 360.0))
        if all(abs(wrap180(c - oc)) > half_width + ohw + 1.0 for oc, ohw in occupied):
            return c
    return None


def _draw_room(rng: np.random.Generator, canvas: Canvas) -> None:
    """An indoor room seen by a low camera (a robot dog) in a rectangular room."""
    az, el = canvas.column_coords, canvas.row_coords  # azimuth, elevation
    height, width = el.size, az.size
    img = canvas.img

    # --- geometry (metres): rectangular room, camera at (cam_x, cam_y, cam_h)
    size_x, size_y = rng.uniform(3.5, 7.0, 2)
    cam_x = rng.uniform(0.3, 0.7) * size_x
    cam_y = rng.uniform(0.3, 0.7) * size_y
    cam_h = rng.uniform(0.2, 0.45)
    room_h = rng.uniform(2.5, 3.0)
    phi = np.radians(az)
    c, s = np.cos(phi), np.sin(phi)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 1e-12, (size_x - cam_x) / c, np.where(c < -1e-12, -cam_x / c, np.inf))
        ty = np.where(s > 1e-12, (size_y - cam_y) / s, np.where(s < -1e-12, -cam_y / s, np.inf))
    dist = np.minimum(tx, ty)  # horizontal distance to the wall in each column
    # azimuths of the four corners: nothing is hung across a corner
    corners = [
        (math.degrees(math.atan2(y - cam_y, x - cam_x)), 0.0)
        for x in (0.0, size_x)
        for y in (0.0, size_y)
    ]
    wall = np.where(tx <= ty, np.where(c > 0, 0, 2), np.where(s > 0, 1, 3))
    tan_e = np.tan(np.radians(el)).astype(np.float32)
    # height at which each pixel's ray meets the wall plane of its column
    z = np.float32(cam_h) + dist.astype(np.float32)[None, :] * tan_e[:, None]

    # --- walls: one paint, lit differently per wall (the corners become vertical edges)
    wall_rgb = hsv(rng.uniform(), rng.uniform(0.05, 0.4), rng.uniform(0.65, 0.92))
    light = rng.uniform(0.72, 1.05, 4).astype(np.float32)[wall]
    img[:] = wall_rgb * light[None, :, None]
    img *= (1.0 + 0.04 * value_noise(rng, height, width, 60, 15))[:, :, None]

    # --- baseboard
    base_h = rng.uniform(0.06, 0.12)
    base_rgb = hsv(rng.uniform(), rng.uniform(0.0, 0.3), rng.uniform(0.2, 0.95))
    img[(z >= 0) & (z < base_h)] = base_rgb * 0.95

    # --- floor: carpet (green or grey) with coarse texture, maybe a rug
    if rng.uniform() < 0.55:
        carpet = hsv(rng.uniform(0.22, 0.42), rng.uniform(0.2, 0.55), rng.uniform(0.3, 0.6))
    else:
        carpet = hsv(rng.uniform(), rng.uniform(0.0, 0.1), rng.uniform(0.3, 0.65))
    r0 = int(np.searchsorted(-el, 0.0, side="right"))  # first row below the horizon
    rows = slice(r0, height)  # every floor pixel is in these rows
    n_rows = height - r0
    tex = 0.10 * value_noise(rng, n_rows, width, 72, 9) + 0.05 * value_noise(
        rng, n_rows, width, 180, 22
    )
    floor_img = carpet[None, None, :] * (1.0 + tex)[:, :, None]
    np.copyto(img[rows], floor_img, where=(z[rows] < 0)[:, :, None])
    if rng.uniform() < 0.7:
        ground_dist = cam_h / -tan_e[rows]  # horizontal distance of each floor row
        gx = cam_x + ground_dist[:, None] * c[None, :].astype(np.float32)
        gy = cam_y + ground_dist[:, None] * s[None, :].astype(np.float32)
        rx, ry = rng.uniform(0.25, 0.75) * size_x, rng.uniform(0.25, 0.75) * size_y
        hx = rng.uniform(0.5, min(1.5, 0.45 * size_x))
        hy = rng.uniform(0.5, min(1.5, 0.45 * size_y))
        border = rng.uniform(0.1, 0.25)
        outer = (np.abs(gx - rx) < hx) & (np.abs(gy - ry) < hy)
        inner = (np.abs(gx - rx) < hx - border) & (np.abs(gy - ry) < hy - border)
        floor = z[rows] < 0
        img[rows][outer & floor] = random_color(rng, **_VARIED)
        img[rows][inner & floor] = random_color(rng, **_VARIED)

    # --- things on the walls. Floor-standing items stay below 0.95 m, wall-mounted
    # ones above 1.0 m; doors and bookcases take both layers.
    low: list[tuple[float, float]] = []
    high: list[tuple[float, float]] = []
    n_items = int(rng.integers(10, 17))
    kinds = rng.choice(
        ["door", "bookcase", "window", "cabinet", "table", "poster"],
        size=n_items,
        p=[0.12, 0.12, 0.16, 0.16, 0.14, 0.30],
    )
    order = {"door": 0, "bookcase": 1, "window": 2, "cabinet": 3, "table": 4, "poster": 5}
    for kind in sorted(kinds, key=order.__getitem__):
        hw = rng.uniform(5.0, 40.0) / 2.0
        layers = {"door": (low, high), "bookcase": (low, high), "window": (high,),
                  "poster": (high,), "cabinet": (low,), "table": (low,)}[kind]  # fmt: skip
        centre = _free_spot(rng, corners + [o for layer in layers for o in layer], hw)
        if centre is None:
            continue
        for layer in layers:
            layer.append((centre, hw))
        cols, rel = canvas.columns(centre, hw)
        zb = z[:, cols]
        u = rel / hw  # -1 (right edge) .. 1 (left edge)
        # approximate width in metres (exact for a wall facing the camera)
        d_centre = float(dist[cols[np.argmin(np.abs(rel))]])
        width_m = 2.0 * d_centre * math.tan(math.radians(hw))
        wall_cols = wall_rgb * light[cols][:, None]
        _draw_room_item(rng, canvas, kind, cols, u, hw, zb, wall_cols, room_h, width_m)

    # --- ceiling
    ceiling_rgb = hsv(rng.uniform(), rng.uniform(0.0, 0.08), rng.uniform(0.82, 0.96))
    ceiling = z[:r0] > room_h  # only rows above the horizon can see the ceiling
    if ceiling.any():
        rows = slice(0, int(np.flatnonzero(ceiling.any(axis=1))[-1]) + 1)
        # a little darker towards the far walls
        shade = 1.0 - 0.1 * dist[None, :] / (1.0 + dist[None, :])
        shade = shade * (1.0 - 0.06 * value_noise(rng, rows.stop, width, 36, 4))
        ceiling_img = ceiling_rgb[None, None, :] * shade.astype(np.float32)[:, :, None]
        np.copyto(img[rows], ceiling_img, where=ceiling[rows][:, :, None])


def _draw_room_item(
    rng: np.random.Generator,
    canvas: Canvas,
    kind: str,
    cols: np.ndarray,
    u: np.ndarray,
    hw: float,
    zb: np.ndarray,
    wall_cols: np.ndarray,
    room_h: float,
    width_m: float,
) -> None:
    """Paint one door / bookcase / window / cabinet / table / poster on the wall.

    ``u`` is the column position across the item (-1 right edge .. 1 left edge), ``hw``
    its angular half-width and ``zb`` the wall height each pixel of its columns sees.
    """
    au = np.abs(u)[None, :]

    def inside(frac: float, min_deg: float = 0.6) -> np.ndarray:
        """Columns inside a border of ``frac`` of the half-width, at least ``min_deg``
        wide (thinner vertical bars would alias in a 208-pixel camera)."""
        return au < 1.0 - max(frac, min_deg / hw)

    def band(z0: float, z1: float) -> np.ndarray:
        return (zb >= z0) & (zb < z1)

    if kind == "door":
        top = rng.uniform(1.9, 2.15)
        if rng.uniform() < 0.5:
            leaf = hsv(rng.uniform(0.05, 0.11), rng.uniform(0.4, 0.75), rng.uniform(0.3, 0.65))
        else:
            leaf = random_color(rng, **_VARIED)
        casing = hsv(rng.uniform(), rng.uniform(0.0, 0.15), rng.uniform(0.75, 0.95))
        canvas.paint(cols, band(0.0, top + 0.08), casing)
        canvas.paint(cols, band(0.0, top) & inside(0.12), leaf)
    elif kind == "bookcase":
        top = rng.uniform(1.3, 2.0)
        frame = random_color(rng, **_VARIED)
        canvas.paint(cols, band(0.0, top), frame)
        n_shelves = int(rng.integers(3, 6))
        board = rng.uniform(0.04, 0.07)
        edges = np.linspace(0.08, top - board, n_shelves + 1)
        interior = frame * rng.uniform(0.3, 0.5)
        for lo, hi in zip(edges[:-1], edges[1:], strict=True):
            lo_in, hi_in = lo + board, hi
            canvas.paint(cols, band(lo_in, hi_in) & inside(0.1), interior)
            # a few coarse blocks of "books"/boxes per compartment
            x = 0.9
            while x > -0.9:
                w = rng.uniform(max(0.3, 1.0 / hw), 0.9)  # at least 0.5° wide
                if rng.uniform() < 0.7:
                    book_top = lo_in + rng.uniform(0.55, 0.95) * (hi_in - lo_in)
                    m = band(lo_in, book_top) & (u[None, :] <= x) & (u[None, :] > x - w)
                    canvas.paint(cols, m & inside(0.1), random_color(rng, **_VARIED))
                x -= w
    elif kind == "window":
        z0, z1 = rng.uniform(1.0, 1.2), min(rng.uniform(2.0, 2.3), room_h - 0.15)
        frame = hsv(rng.uniform(), rng.uniform(0.0, 0.12), rng.uniform(0.8, 0.97))
        canvas.paint(cols, band(z0, z1), frame)
        t = np.clip((zb - z0) / (z1 - z0), 0.0, 1.0)
        hue = rng.uniform(0.52, 0.62)
        lower = hsv(hue, rng.uniform(0.05, 0.25), rng.uniform(0.75, 0.9))
        upper = hsv(hue, rng.uniform(0.2, 0.5), rng.uniform(0.85, 1.0))
        mullion = max(0.07, 0.5 / hw)
        pane_mask = band(z0 + 0.06, z1 - 0.06) & inside(0.1) & (au > mullion)
        if pane_mask.any():
            block = canvas.img[:, cols]
            sky = lower[None, None, :] * (1 - t[:, :, None]) + upper[None, None, :] * t[:, :, None]
            block[pane_mask] = sky[pane_mask]
            canvas.img[:, cols] = block
        if rng.uniform() < 0.6:  # curtains on both sides
            curtain = random_color(rng, **_VARIED)
            canvas.paint(cols, band(z0 - 0.25, z1 + 0.1) & ~inside(0.22, 1.0), curtain)
    elif kind == "cabinet":
        top = rng.uniform(0.45, 0.95)
        body = random_color(rng, **_VARIED)
        slab = (
            body * rng.uniform(0.55, 0.8) if rng.uniform() < 0.5 else random_color(rng, **_VARIED)
        )
        canvas.paint(cols, band(0.0, top), body)
        canvas.paint(cols, band(top - rng.uniform(0.04, 0.08), top), slab)
        canvas.paint(cols, band(0.0, 0.07), body * 0.4)  # plinth shadow
    elif kind == "table":
        top = rng.uniform(0.6, 0.8)
        wood = random_color(rng, **_VARIED)
        thick = rng.uniform(0.05, 0.09)
        shadow = wall_cols[None, :, :] * np.float32(rng.uniform(0.45, 0.65))
        under = band(0.0, top - thick)
        if under.any():
            block = canvas.img[:, cols]
            block[under] = np.broadcast_to(shadow, block.shape)[under]
            canvas.img[:, cols] = block
        canvas.paint(cols, band(top - thick, top), wood)
        canvas.paint(cols, band(0.0, top) & ~inside(0.14, 0.8), wood * 0.8)  # legs
    else:  # poster / painting
        z0 = rng.uniform(1.05, 1.5)
        z1 = min(z0 + max(rng.uniform(0.5, 1.2) * width_m, 0.25), room_h - 0.2)
        outer = random_color(rng, **_VARIED)
        canvas.paint(cols, band(z0, z1), outer)
        inset = rng.uniform(0.08, 0.2)
        dz = inset * (z1 - z0)
        inner = band(z0 + dz, z1 - dz) & inside(inset)
        canvas.paint(cols, inner, random_color(rng, **_VARIED))
        if rng.uniform() < 0.5:  # two-tone picture (a "landscape")
            split = z0 + dz + rng.uniform(0.3, 0.6) * (z1 - z0 - 2 * dz)
            canvas.paint(cols, inner & (zb < split), random_color(rng, **_VARIED))


def _draw_outdoor(rng: np.random.Generator, canvas: Canvas) -> None:
    """Sky, distant hills, buildings and trees on the horizon, grass below."""
    az, el = canvas.column_coords, canvas.row_coords  # azimuth, elevation
    height, width = el.size, az.size
    img = canvas.img
    phi = np.radians(az)

    # --- sky: gradient from a pale horizon to a deeper zenith, soft coarse clouds
    hue = rng.uniform(0.54, 0.63)
    horizon = hsv(hue + rng.uniform(-0.03, 0.03), rng.uniform(0.08, 0.25), rng.uniform(0.85, 0.97))
    zenith = hsv(hue, rng.uniform(0.45, 0.75), rng.uniform(0.65, 0.9))
    t = (np.clip(el / 45.0, 0.0, 1.0) ** 0.6).astype(np.float32)[:, None, None]
    img[:] = horizon * (1.0 - t) + zenith * t
    clouds = value_noise(rng, height, width, 24, 8) + 0.5 * value_noise(rng, height, width, 60, 20)
    cover = np.clip((clouds - rng.uniform(0.1, 0.6)) / 0.35, 0.0, 1.0)
    cover *= np.clip((el - 2.0) / 10.0, 0.0, 1.0).astype(np.float32)[:, None]
    cloud_rgb = hsv(hue, 0.03, rng.uniform(0.9, 1.0))
    img += (cloud_rgb - img) * cover[:, :, None]

    # --- grass below the horizon: darker and hazier far away, coarse patches
    g_hue, g_sat = rng.uniform(0.2, 0.32), rng.uniform(0.4, 0.7)
    near = hsv(g_hue, g_sat, rng.uniform(0.5, 0.7))
    far = hsv(g_hue + 0.02, g_sat * 0.6, rng.uniform(0.4, 0.55))
    ground = el < 0
    tg = (np.clip(-el / 45.0, 0.0, 1.0) ** 0.5).astype(np.float32)[ground][:, None, None]
    n_ground = int(ground.sum())
    patches = 0.12 * value_noise(rng, n_ground, width, 48, 10) + 0.05 * value_noise(
        rng, n_ground, width, 150, 30
    )
    img[ground] = (far * (1.0 - tg) + near * tg) * (1.0 + patches)[:, :, None]

    # --- distant hills: periodic ridge line (seamless by construction)
    k = np.arange(1, 7)
    amp = rng.uniform(0.3, 1.0, k.size) * 3.0 / k
    ph = rng.uniform(0.0, 2 * np.pi, k.size)
    ridge = rng.uniform(2.5, 6.0) + (amp[:, None] * np.sin(k[:, None] * phi + ph[:, None])).sum(0)
    ridge = np.maximum(ridge, 0.5).astype(np.float32)
    hill_rgb = 0.55 * far + 0.45 * horizon * rng.uniform(0.7, 0.9)
    hills = (el[:, None] >= 0) & (el[:, None] < ridge[None, :])
    img[hills] = hill_rgb

    # --- buildings: blocks with a darker roof, a shaded side, maybe big windows
    occupied: list[tuple[float, float]] = []
    for _ in range(int(rng.integers(3, 8))):
        hw = rng.uniform(5.0, 40.0) / 2.0
        centre = _free_spot(rng, occupied, hw)
        if centre is None:
            continue
        occupied.append((centre, hw))
        cols, rel = canvas.columns(centre, hw)
        u = (rel / hw)[None, :]
        top = rng.uniform(4.0, 22.0)
        base = -rng.uniform(0.0, 1.0)
        e = el[:, None]
        body = hsv(rng.uniform(), rng.uniform(0.05, 0.45), rng.uniform(0.4, 0.85))
        canvas.paint(cols, (e >= base) & (e < top) & (u >= 0), body)
        canvas.paint(cols, (e >= base) & (e < top) & (u < 0), body * rng.uniform(0.6, 0.8))
        roof_h = rng.uniform(0.1, 0.2) * (top - base)
        canvas.paint(cols, (e >= top - roof_h) & (e < top), random_color(rng, **_VARIED) * 0.6)
        if top - base > 9.0 and hw > 6.0 and rng.uniform() < 0.7:
            glass = hsv(rng.uniform(0.5, 0.65), rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.45))
            cell_e, cell_a = rng.uniform(3.5, 5.0), rng.uniform(4.5, 7.0)
            fe = np.mod(e - base, cell_e) / cell_e  # position within a window cell
            fa = np.mod(rel[None, :] + hw, cell_a) / cell_a
            m = (fe > 0.35) & (fe < 0.8) & (fa > 0.25) & (fa < 0.75)
            m &= (e > base + 1.0) & (e < top - roof_h - 0.8) & (np.abs(u) < 0.88)
            canvas.paint(cols, m, glass)

    # --- trees: round or conical crowns on trunks, some in front of the horizon
    for _ in range(int(rng.integers(8, 19))):
        hw = rng.uniform(2.0, 8.0)
        centre = float(rng.uniform(0.0, 360.0))
        cols, rel = canvas.columns(centre, hw)
        base = -rng.uniform(0.0, 3.0)
        crown_h = hw * rng.uniform(1.0, 1.6)
        trunk = crown_h * rng.uniform(0.3, 0.7)
        e = el[:, None]
        a = rel[None, :]
        canvas.paint(
            cols,
            (np.abs(a) < max(0.16 * hw, 0.4)) & (e >= base) & (e < base + trunk + crown_h),
            hsv(rng.uniform(0.05, 0.1), rng.uniform(0.4, 0.7), rng.uniform(0.2, 0.4)),
        )
        leaves = hsv(rng.uniform(0.2, 0.4), rng.uniform(0.4, 0.85), rng.uniform(0.18, 0.5))
        bottom = base + trunk
        if rng.uniform() < 0.6:  # round crown
            ce = bottom + crown_h / 2.0
            m = (a / hw) ** 2 + ((e - ce) / (crown_h / 2.0)) ** 2 <= 1.0
        else:  # conifer
            m = (e >= bottom) & (np.abs(a) <= hw * (1.0 - (e - bottom) / (1.6 * crown_h)))
        canvas.paint(cols, m, leaves)

    # --- bushes, rocks and flower beds in the foreground (flat-bottomed mounds)
    for _ in range(int(rng.integers(3, 8))):
        hw = rng.uniform(4.0, 15.0)
        cols, rel = canvas.columns(float(rng.uniform(0.0, 360.0)), hw)
        ce, he = rng.uniform(-30.0, -4.0), rng.uniform(2.0, 7.0)
        m = ((rel[None, :] / hw) ** 2 + ((el[:, None] - ce) / he) ** 2 <= 1.0) & (el[:, None] >= ce)
        if rng.uniform() < 0.5:
            color = hsv(rng.uniform(0.2, 0.4), rng.uniform(0.4, 0.8), rng.uniform(0.2, 0.45))
        else:
            color = random_color(rng, **_VARIED)
        canvas.paint(cols, m, color)


def make_panorama(
    rng: np.random.Generator,
    width: int = 3600,
    height: int = 900,
    *,
    kind: str = "room",
    noise: float = 4.0,
) -> Panorama:
    """Paint a procedural, seamless 360° panorama.

    The scene is coarse (large uniform regions and straight or smoothly curved edges,
    no fine stripes that a 208 x 160 camera would alias) and depends only on ``rng``;
    the global ``numpy.random`` state is neither used nor changed. All features are
    drawn with modular column indices, so they may straddle the 0/360 seam without a
    discontinuity.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of all randomness (``np.random.default_rng(seed)``).
    width, height : int
        Panorama size; ``width >= 360``, ``height >= 90``. The image covers 360° of
        azimuth and elevations +45° (top) to -45° (bottom), so the default 3600 x 900
        has 10 pixels per degree; column 0 starts at azimuth 0 and azimuth decreases to
        the right (see the module conventions).
    kind : {"room", "outdoor"}
        ``"room"``: the inside of a rectangular room seen from a low camera: carpet
        floor below the horizon (maybe with a rug), walls lit differently per wall
        with a baseboard, doors, windows, bookcases, cabinets, tables and posters
        (5°-40° wide, random colours and heights), and the ceiling near the top.
        ``"outdoor"``: sky gradient with soft clouds, distant hills, building and tree
        silhouettes of random heights on the horizon, grass with bushes below.
    noise : float
        Standard deviation (grey levels) of per-pixel Gaussian noise, ``>= 0``. The
        noise is drawn last, so the same seed gives the same scene for any noise.

    Returns
    -------
    Panorama
        ``uint8`` RGB image, ``elev_top_deg=45``, ``elev_bottom_deg=-45``,
        ``azimuth0_deg=0``.

    Raises
    ------
    ValueError
        On a bad size, kind or noise level.
    TypeError
        If ``rng`` is not a ``numpy.random.Generator``.
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"rng must be a numpy.random.Generator (np.random.default_rng(seed)), got "
            f"{type(rng).__name__}"
        )
    width = int_at_least("width", width, 360)
    height = int_at_least("height", height, 90)
    if kind not in PANORAMA_KINDS:
        raise ValueError(f"kind must be one of {PANORAMA_KINDS}, got {kind!r}")
    sigma = nonnegative_float("noise", noise)

    top, bottom, azimuth0 = 45.0, -45.0, 0.0
    canvas = Canvas.panorama(width, height, top, bottom, azimuth0)
    if kind == "room":
        _draw_room(rng, canvas)
    else:
        _draw_outdoor(rng, canvas)
    img = canvas.img
    img *= (1.0 + 0.05 * value_noise(rng, height, width, 36, 9))[:, :, None]  # soft lighting
    if sigma > 0.0:
        img += rng.standard_normal(img.shape, dtype=np.float32) * np.float32(sigma)
    return Panorama(canvas.image(), top, bottom, azimuth0)
