"""The simulated scenes: the paper's robot lab and its "other environments" (section 5).

Every scene is built from a few primitives into a caller-owned PyBullet client:
tessellated floor and ceiling meshes (large single triangles render black in PyBullet's
tiny renderer when they cross the near plane), wall boxes, textured poster quads
(a box face would show only part of a texture) and furniture boxes. Outdoor scenes get a
"sky box" of four distant textured quads carrying the sky and the far surroundings.
``randomize=False`` builds the canonical scene for a name; ``randomize=True`` draws
textures, poster placement, furniture placement, colours and the light direction from
the generator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from vc_gym.envs.textures import (
    TextureStore,
    carpet,
    photo_posters,
    procedural_poster,
    random_colour,
    sky_panorama,
)

__all__ = ["SCENES", "Scene", "build_scene"]

SCENES = ("robolab", "office", "home", "outdoor_field")
_CANONICAL_SEEDS = {"robolab": 2006, "office": 16, "home": 2007, "outdoor_field": 5}
_WALL_T = 0.1  # wall thickness (m)


@dataclass(frozen=True)
class Scene:
    """A built scene: where things are, for the env, the robot and the top view.

    Attributes
    ----------
    name : str
        Scene name.
    room_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces (outdoor: the area the
        robot may reach).
    field_bounds : tuple of float
        Where the robot may be placed or kidnapped to (robolab: the 6×4 m field).
    obstacles : tuple of tuple
        Floor-plane footprints ``(xmin, xmax, ymin, ymax)`` of walls and furniture.
    body_ids : tuple of int
        Every body of the scene.
    light_direction : tuple of float
        Direction of the light for ``getCameraImage``.
    ceiling_ids : tuple of int
        Bodies hidden when the scene is rendered from above (ceiling, sky lid).
    """

    name: str
    room_bounds: tuple[float, float, float, float]
    field_bounds: tuple[float, float, float, float]
    obstacles: tuple[tuple[float, float, float, float], ...]
    body_ids: tuple[int, ...]
    light_direction: tuple[float, float, float]
    ceiling_ids: tuple[int, ...] = field(default=())


class _Builder:
    """Collects bodies and obstacles while a scene is built."""

    def __init__(self, bc, rng: np.random.Generator):
        self.bc = bc
        self.rng = rng
        self.tex = TextureStore(bc)
        self.bodies: list[int] = []
        self.obstacles: list[tuple[float, float, float, float]] = []
        self.ceilings: list[int] = []

    # -------------------------------------------------------------- primitives
    def box(self, he, pos, rgb, *, solid=True, yaw_deg=0.0) -> int:
        """A static box (half extents ``he``) with a colour; solid boxes also collide."""
        bc = self.bc
        rgba = [*(np.asarray(rgb, float) / 255.0), 1.0]
        orn = bc.getQuaternionFromEuler([0, 0, math.radians(yaw_deg)])
        vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=he, rgbaColor=rgba)
        col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=he) if solid else -1
        body = bc.createMultiBody(0, col, vis, pos, orn)
        if solid:
            bc.changeDynamics(body, -1, lateralFriction=1.0)
            c, s = abs(math.cos(math.radians(yaw_deg))), abs(math.sin(math.radians(yaw_deg)))
            ex, ey = c * he[0] + s * he[1], s * he[0] + c * he[1]
            if pos[2] - he[2] < 0.35:  # reaches down to where the robot walks
                self.obstacles.append((pos[0] - ex, pos[0] + ex, pos[1] - ey, pos[1] + ey))
        self.bodies.append(body)
        return body

    def grid(self, x0, x1, y0, y1, z, tex_id=None, rgb=(255, 255, 255), cell=0.5, down=False):
        """A horizontal mesh of ``cell``-sized quads (uvs span the whole rectangle)."""
        nx, ny = max(1, int(round((x1 - x0) / cell))), max(1, int(round((y1 - y0) / cell)))
        xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
        gx, gy = np.meshgrid(xs, ys)
        verts = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)], axis=1)
        uvs = np.stack([(gx.ravel() - x0) / (x1 - x0), (gy.ravel() - y0) / (y1 - y0)], axis=1)
        a = (np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]).ravel()
        b, c, d = a + 1, a + nx + 1, a + nx + 2
        tris = (
            np.stack([a, b, d, a, d, c], axis=1)
            if not down
            else np.stack([a, d, b, a, c, d], axis=1)
        )
        normal = [0, 0, -1] if down else [0, 0, 1]
        vis = self.bc.createVisualShape(
            self.bc.GEOM_MESH,
            vertices=verts.tolist(),
            indices=tris.ravel().tolist(),
            uvs=uvs.tolist(),
            normals=[normal] * len(verts),
            rgbaColor=[*(np.asarray(rgb, float) / 255.0), 1.0],
        )
        body = self.bc.createMultiBody(0, -1, vis, [0, 0, 0])
        if tex_id is not None:
            self.bc.changeVisualShape(body, -1, textureUniqueId=tex_id)
        self.bodies.append(body)
        return body

    def quad(self, centre, facing_deg, width, height, tex_id=None, rgb=(255, 255, 255)) -> int:
        """A vertical textured rectangle at ``centre`` whose front faces ``facing_deg``.

        uv (0, 0) is the image's bottom-left as seen from the front.
        """
        f = math.radians(facing_deg)
        nx, ny = math.cos(f), math.sin(f)
        rx, ry = -ny, nx  # "right" as seen by a viewer looking at the front
        hw, hh = width / 2.0, height / 2.0
        verts = [
            [-rx * hw, -ry * hw, -hh],
            [rx * hw, ry * hw, -hh],
            [rx * hw, ry * hw, hh],
            [-rx * hw, -ry * hw, hh],
        ]
        vis = self.bc.createVisualShape(
            self.bc.GEOM_MESH,
            vertices=verts,
            indices=[0, 1, 2, 0, 2, 3],
            uvs=[[0, 0], [1, 0], [1, 1], [0, 1]],
            normals=[[nx, ny, 0]] * 4,
            rgbaColor=[*(np.asarray(rgb, float) / 255.0), 1.0],
        )
        body = self.bc.createMultiBody(0, -1, vis, list(centre))
        if tex_id is not None:
            self.bc.changeVisualShape(body, -1, textureUniqueId=tex_id)
        self.bodies.append(body)
        return body

    # -------------------------------------------------------------- composites
    def floor(self, x0, x1, y0, y1, tex_id=None, rgb=(128, 128, 128)) -> None:
        """Visual floor mesh at z=0 on a thick collision box whose top is at z=0."""
        self.grid(x0, x1, y0, y1, 0.0, tex_id, rgb)
        he = [(x1 - x0) / 2 + 1, (y1 - y0) / 2 + 1, 0.25]
        bc = self.bc
        col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=he)
        # every body needs a visual (a collision-only one is drawn as a checker); this
        # one sits 1 cm below the floor mesh, so it is never seen
        vis = bc.createVisualShape(
            bc.GEOM_BOX,
            halfExtents=he,
            rgbaColor=[0.3, 0.3, 0.3, 1],
            visualFramePosition=[0, 0, -0.01],
        )
        body = bc.createMultiBody(0, col, vis, [(x0 + x1) / 2, (y0 + y1) / 2, -0.25])
        bc.changeDynamics(body, -1, lateralFriction=1.0)
        self.bodies.append(body)

    def walls(self, bounds, height, colours) -> None:
        """Four walls (inner faces on ``bounds``) in the given colours (E, N, W, S)."""
        x0, x1, y0, y1 = bounds
        t, h2 = _WALL_T / 2, height / 2
        w, d = x1 - x0, y1 - y0
        self.box([t, d / 2 + _WALL_T, h2], [x1 + t, (y0 + y1) / 2, h2], colours[0])
        self.box([w / 2 + _WALL_T, t, h2], [(x0 + x1) / 2, y1 + t, h2], colours[1])
        self.box([t, d / 2 + _WALL_T, h2], [x0 - t, (y0 + y1) / 2, h2], colours[2])
        self.box([w / 2 + _WALL_T, t, h2], [(x0 + x1) / 2, y0 - t, h2], colours[3])
        # dark baseboards: a strong horizontal edge just above the floor
        for i, (cx, cy, facing) in enumerate(((x1, 0, 180), (0, y1, 270), (x0, 0, 0), (0, y0, 90))):
            length = d if i % 2 == 0 else w
            cx = cx if i % 2 == 0 else (x0 + x1) / 2
            cy = cy if i % 2 == 1 else (y0 + y1) / 2
            f = math.radians(facing)
            self.quad(
                (cx + 0.005 * math.cos(f), cy + 0.005 * math.sin(f), 0.05),
                facing,
                length,
                0.1,
                rgb=(60, 50, 45),
            )

    def poster(self, wall: str, bounds, along: float, z: float, width, height, tex_id):
        """A poster on a wall (``"E"``, ``"N"``, ``"W"``, ``"S"``) at a position along it."""
        x0, x1, y0, y1 = bounds
        eps = 0.01
        if wall == "E":
            return self.quad((x1 - eps, along, z), 180.0, width, height, tex_id)
        if wall == "W":
            return self.quad((x0 + eps, along, z), 0.0, width, height, tex_id)
        if wall == "N":
            return self.quad((along, y1 - eps, z), 270.0, width, height, tex_id)
        return self.quad((along, y0 + eps, z), 90.0, width, height, tex_id)


def _poster_textures(b: _Builder, n: int) -> list[int]:
    photos = photo_posters()
    ids = [b.tex.load(f"photo{i}", lambda im=im: im) for i, im in enumerate(photos)]
    for i in range(max(0, n - len(ids))):
        ids.append(b.tex.load(f"poster{i}", lambda: procedural_poster(b.rng)))
    order = b.rng.permutation(len(ids))
    return [ids[i] for i in order]


def _hang_posters(b: _Builder, bounds, n: int, walls: str = "ENWS", z_range=(0.9, 1.7)) -> None:
    """Hang ``n`` posters spread over the given walls, without overlaps."""
    x0, x1, y0, y1 = bounds
    textures = _poster_textures(b, n)
    per_wall = {w: [] for w in walls}
    for i, tex in enumerate(textures[:n]):
        wall = walls[i % len(walls)]
        lo, hi = (y0, y1) if wall in "EW" else (x0, x1)
        size = float(b.rng.uniform(0.6, 1.3))
        for _ in range(20):
            along = float(b.rng.uniform(lo + size / 2 + 0.2, hi - size / 2 - 0.2))
            if all(abs(along - a) > (size + s) / 2 + 0.1 for a, s in per_wall[wall]):
                per_wall[wall].append((along, size))
                z = float(b.rng.uniform(*z_range))
                b.poster(wall, bounds, along, z, size, size * b.rng.uniform(0.7, 1.2), tex)
                break


def _desk_row(b: _Builder, x_from, x_to, y_wall, facing_south=True) -> None:
    """Tables with monitors and PC boxes along a wall, chairs in front."""
    sign = -1 if facing_south else 1
    x = x_from
    while x + 1.4 <= x_to:
        y = y_wall + sign * 0.4
        b.box([0.65, 0.35, 0.02], [x + 0.7, y, 0.73], (150, 110, 70))  # table top
        for dx in (0.05, 1.35):  # side panels instead of thin legs (legs alias)
            b.box([0.02, 0.33, 0.36], [x + dx, y, 0.36], (120, 90, 60))
        b.box([0.25, 0.03, 0.18], [x + 0.7, y_wall + sign * 0.15, 0.98], (30, 30, 35))  # monitor
        b.quad(
            (x + 0.7, y_wall + sign * 0.185, 0.98),
            90 if facing_south else 270,
            0.44,
            0.3,
            rgb=tuple(int(v) for v in random_colour(b.rng, s=(0.3, 0.8), v=(0.6, 1.0))),
        )
        b.box([0.1, 0.22, 0.22], [x + 1.15, y, 0.22], (200, 200, 205))  # PC box under the table
        chair = tuple(int(v) for v in random_colour(b.rng, v=(0.3, 0.7)))
        b.box([0.22, 0.22, 0.03], [x + 0.7, y + sign * 0.55, 0.45], chair)  # seat
        b.box([0.22, 0.03, 0.25], [x + 0.7, y + sign * 0.77, 0.72], chair)  # back
        b.box([0.05, 0.05, 0.21], [x + 0.7, y + sign * 0.55, 0.21], (40, 40, 40))  # post
        x += 1.6 + float(b.rng.uniform(0, 0.3))


def _closed_room(b: _Builder, bounds, height, wall_rgb, floor_tex, ceiling_rgb) -> None:
    x0, x1, y0, y1 = bounds
    b.floor(x0, x1, y0, y1, floor_tex)
    b.walls(bounds, height, wall_rgb)
    b.ceilings.append(b.grid(x0, x1, y0, y1, height, rgb=ceiling_rgb, down=True))


def _wall_colours(b: _Builder, base, spread: float) -> list[tuple[int, int, int]]:
    out = []
    for _ in range(4):
        c = np.asarray(base, float) + b.rng.uniform(-spread, spread, 3)
        out.append(tuple(int(v) for v in np.clip(c, 0, 255)))
    return out


def _robolab(b: _Builder) -> tuple:
    bounds, field_b = (-3.5, 3.5, -3.5, 3.5), (-3.0, 3.0, -2.0, 2.0)
    green = tuple(
        int(v) for v in np.clip(np.array([40, 125, 50]) + b.rng.uniform(-15, 15, 3), 0, 255)
    )
    floor_tex = b.tex.load("carpet", lambda: carpet(7.0, 7.0, field_b, green, rng=b.rng))
    _closed_room(b, bounds, 2.5, _wall_colours(b, (225, 220, 205), 20), floor_tex, (238, 238, 238))
    _desk_row(b, -3.3, 3.3, 3.5)  # tables, chairs and computers along the north wall
    b.quad((3.49, -1.8, 1.05), 180.0, 0.9, 2.1, rgb=(120, 80, 50))  # door (east)
    b.quad((-3.49, 1.2, 1.5), 0.0, 1.6, 1.0, rgb=(170, 205, 235))  # window (west)
    _hang_posters(b, bounds, 9, walls="ESW")
    return bounds, field_b


def _office(b: _Builder) -> tuple:
    bounds, field_b = (-3.0, 3.0, -2.5, 2.5), (-2.0, 2.0, -1.5, 1.5)
    floor_tex = b.tex.load("floor", lambda: carpet(6.0, 5.0, None, (110, 110, 125), rng=b.rng))
    _closed_room(b, bounds, 2.6, _wall_colours(b, (200, 210, 225), 15), floor_tex, (245, 245, 240))
    _desk_row(b, -2.9, 1.0, -2.5, facing_south=False)
    for i in range(3):  # shelves full of coloured binders
        x = 1.4 + i * 0.5
        b.box([0.22, 0.18, 0.9], [x, -2.3, 0.9], (90, 70, 50))
        b.quad(
            (x, -2.11, 1.2),
            90.0,
            0.4,
            0.5,
            b.tex.load(f"binders{i}", lambda: procedural_poster(b.rng)),
        )
    b.quad((2.99, 0.2, 1.4), 180.0, 1.8, 1.0, rgb=(245, 245, 245))  # whiteboard
    b.quad((2.985, 0.2, 1.4), 180.0, 1.2, 0.5, b.tex.load("wb", lambda: procedural_poster(b.rng)))
    b.quad((-2.99, 0.0, 1.5), 0.0, 2.2, 1.1, rgb=(165, 200, 235))  # window
    b.quad((0.5, 2.49, 1.05), 270.0, 0.9, 2.1, rgb=(100, 70, 45))  # door
    _hang_posters(b, bounds, 5, walls="NE")
    return bounds, field_b


def _home(b: _Builder) -> tuple:
    bounds, field_b = (-3.0, 3.0, -3.0, 3.0), (-1.8, 1.8, -1.8, 1.8)
    floor_tex = b.tex.load("wood", lambda: carpet(6.0, 6.0, None, (150, 105, 65), rng=b.rng))
    _closed_room(b, bounds, 2.5, _wall_colours(b, (235, 215, 185), 20), floor_tex, (250, 245, 235))
    rug = tuple(int(v) for v in random_colour(b.rng, s=(0.5, 0.8), v=(0.4, 0.7)))
    b.grid(-1.2, 1.2, -0.8, 0.8, 0.003, rgb=rug)
    sofa = tuple(int(v) for v in random_colour(b.rng, s=(0.5, 0.9), v=(0.4, 0.7)))
    b.box([1.0, 0.4, 0.22], [0.0, 2.5, 0.22], sofa)  # seat
    b.box([1.0, 0.12, 0.4], [0.0, 2.85, 0.45], sofa)  # back
    b.box([0.5, 0.25, 0.3], [0.0, -2.7, 0.3], (70, 50, 40))  # TV stand
    b.quad((0.0, -2.74, 0.95), 90.0, 1.1, 0.65, rgb=(20, 20, 25))  # TV
    b.box([0.2, 0.5, 1.0], [2.75, 1.5, 1.0], (110, 75, 45))  # bookshelf
    b.quad((2.54, 1.5, 1.2), 180.0, 0.9, 1.5, b.tex.load("books", lambda: procedural_poster(b.rng)))
    curtain = tuple(int(v) for v in random_colour(b.rng, v=(0.5, 0.9)))
    for y in (-1.4, 0.2):  # curtains framing a window on the west wall
        b.quad((-2.99, y, 1.3), 0.0, 0.5, 2.2, rgb=curtain)
    b.quad((-2.995, -0.6, 1.5), 0.0, 1.3, 1.0, rgb=(170, 205, 235))
    _hang_posters(b, bounds, 5, walls="NES", z_range=(1.2, 1.8))
    return bounds, field_b


def _outdoor(b: _Builder) -> tuple:
    reach, field_b = (-6.0, 6.0, -6.0, 6.0), (-3.0, 3.0, -2.0, 2.0)
    grass = b.tex.load(
        "grass", lambda: carpet(40.0, 40.0, None, (70, 140, 60), px_per_m=8, rng=b.rng)
    )
    b.floor(-20, 20, -20, 20, grass)
    b.grid(-3.0, 3.0, -2.0, 2.0, 0.003, rgb=(60, 150, 60))  # the field's mown turf
    # sky box: a 360 deg band of sky and far surroundings split over four quads 30 m
    # away, each seen from inside; the band's horizon line sits at about eye height
    band = sky_panorama(b.rng)
    w = band.shape[1] // 4
    d = 30.0
    for i, facing in enumerate((180.0, 270.0, 0.0, 90.0)):  # quads at +x, +y, -x, -y
        tex = b.tex.load(f"sky{i}", lambda i=i: np.ascontiguousarray(band[:, i * w : (i + 1) * w]))
        f = math.radians(facing + 180.0)
        b.quad((d * math.cos(f), d * math.sin(f), 14.0), facing, 2 * d, 40.0, tex)
    b.ceilings.append(b.grid(-d, d, -d, d, 34.0, rgb=(80, 130, 210), down=True, cell=10.0))
    for x, y in ((-8.0, 0.0), (8.0, 0.0)):  # two soccer goals, white, 3 m wide
        for dy in (-1.5, 1.5):
            b.box([0.06, 0.06, 1.0], [x, y + dy, 1.0], (245, 245, 245))
        b.box([0.06, 1.56, 0.06], [x, y, 2.0], (245, 245, 245), solid=False)
    for _ in range(6):  # trees at 10-15 m
        a, r = b.rng.uniform(0, 2 * math.pi), b.rng.uniform(10, 15)
        x, y = r * math.cos(a), r * math.sin(a)
        b.box([0.15, 0.15, 1.0], [x, y, 1.0], (95, 65, 35))
        crown = tuple(
            int(v) for v in random_colour(b.rng, s=(0.6, 0.9), v=(0.3, 0.6)) * [0.5, 1, 0.5]
        )
        b.box([1.0, 1.0, 1.2], [x, y, 2.8], crown, yaw_deg=float(b.rng.uniform(0, 90)))
    return reach, field_b


_BUILDERS = {"robolab": _robolab, "office": _office, "home": _home, "outdoor_field": _outdoor}


def build_scene(
    bc, name: str = "robolab", rng: np.random.Generator | None = None, randomize: bool = False
) -> Scene:
    """Build scene ``name`` into the client ``bc`` (call ``bc.resetSimulation()`` first).

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client (owned by the caller).
    name : str
        One of :data:`SCENES`.
    rng : numpy.random.Generator, optional
        Source of the randomisation (only used when ``randomize``).
    randomize : bool
        Domain randomisation of colours, textures, posters, furniture and light.

    Returns
    -------
    Scene
    """
    if name not in SCENES:
        raise ValueError(f"unknown scene {name!r}; choose one of {SCENES}")
    if rng is not None and not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    if randomize:
        gen = rng if rng is not None else np.random.default_rng()
    else:
        gen = np.random.default_rng(_CANONICAL_SEEDS[name])
    b = _Builder(bc, gen)
    bounds, field_b = _BUILDERS[name](b)
    if randomize:
        az, el = gen.uniform(0, 2 * math.pi), gen.uniform(0.5, 1.3)
        light = (math.cos(az) * math.cos(el), math.sin(az) * math.cos(el), math.sin(el))
    else:
        light = (0.4, 0.3, 0.87)
    return Scene(
        name=name,
        room_bounds=bounds,
        field_bounds=field_b,
        obstacles=tuple(b.obstacles),
        body_ids=tuple(b.bodies),
        light_direction=light,
        ceiling_ids=tuple(b.ceilings),
    )
