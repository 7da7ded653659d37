"""The simulated scenes: the paper's robot lab and its "other environments" (section 5).

* ``"robolab"``: the UvA Robolab of the paper, a 7 x 7 m room with a 6 x 4 m green
  carpet field (white outline, centre line, centre circle, penalty boxes) and the two
  RoboCup goals behind its ends, tables with computers and chairs along one side,
  windows with radiators, a bookshelf and robot crates on the opposite side, a
  whiteboard, a cork board, a clock, a door and posters (real photos from matplotlib's
  sample data, maps and procedural posters) on the walls, and a closed ceiling.
* ``"office"``: desks with monitors, tall shelves with binders, a whiteboard, windows
  with blinds, filing cabinets and plants; blue-grey carpet tiles.
* ``"home"``: a living room in warm colours: wooden floor with a rug, sofa, armchair,
  bookshelf, TV on a cabinet, floor lamp, curtains, paintings.
* ``"outdoor_field"``: a grass pitch (mowing stripes, white lines, goals) with pitch-side
  advertising boards, floodlight masts, a grandstand, trees and buildings 15-30 m away,
  inside a sky cylinder with clouds and a far ridge of hills. Invisible fences keep the
  robot inside ``room_bounds``.

Every scene is *closed* (walls and ceiling, or the sky cylinder and its lid), so every
camera ray hits something and :attr:`Scene.background_rgb` is ``None``.

How the scenes are made fast and artefact-free for PyBullet's tiny renderer:

* walls, floors and ceilings are single textured quads into which everything flat is
  painted (doors, windows, boards, posters), so a room is a handful of bodies;
* every quad is a fan of four triangles around an off-centre point: the tiny renderer
  drops triangles that cross the camera's near plane when the eye lies exactly above one
  of their edges, and a fan keeps edges away from round coordinates such as the origin;
* furniture is made of boxes, cylinders and spheres, at most 16 visual shapes per body
  (``createVisualShapeArray`` crashes above that), with one collision box per piece;
* triangles wound counter-clockwise seen from the room (the renderer culls back faces),
  so the ceiling is invisible from above.

``randomize=False`` builds the canonical scene for a name (the same for any ``rng``);
``randomize=True`` draws wall and floor colours, poster selection and placement,
furniture placement, pictures and the light direction from ``rng``.
"""

from __future__ import annotations

import colorsys
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from vc_gym.envs import textures as tx

__all__ = ["SCENES", "Scene", "build_scene"]

#: Names understood by :func:`build_scene`.
SCENES = ("robolab", "office", "home", "outdoor_field")

_CANONICAL_SEEDS = {"robolab": 2006, "office": 16, "home": 2007, "outdoor_field": 5}
_WALL_PPM = 128.0  # wall texture resolution (pixels per metre)
_FLOOR_PPM = 100.0
_MAX_SHAPES = 16  # createVisualShapeArray segfaults above 16 shapes (pybullet 3.2.7)
_FAN = (0.4637, 0.5291)  # interior vertex of every quad (fractions along du, dv)
_NUDGE_M = np.array([2.0e-4, 3.5e-4, 2.7e-4])  # see _nudge
_HASH = np.array([[12.9898, 78.233, 37.719], [39.346, 11.135, 83.155], [73.156, 52.235, 9.151]])
_WALL_T = 0.2  # collision thickness of walls (m)
_OBSTACLE_BELOW = 0.35  # parts lower than this block the robot (m)

RGB = Sequence[float]


@dataclass(frozen=True)
class Scene:
    """A built scene: where things are, for the env, the robot and the top view.

    Attributes
    ----------
    name : str
        Scene name, one of :data:`SCENES`.
    room_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces (outdoor: the area the
        robot may ever reach, fenced by invisible walls).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` where the robot may be placed or kidnapped to
        (robolab: the 6 x 4 m carpet). It is free of obstacles and inside
        ``room_bounds``.
    obstacles : tuple of tuple of float
        Floor-plane footprints ``(xmin, xmax, ymin, ymax)`` of walls, fences and
        furniture that reach below 0.35 m, for kinematic collision checks.
    body_ids : tuple of int
        Every body of the scene; ``body_ids[0]`` is the floor (lateral friction 1.0).
    light_direction : tuple of float
        Unit vector towards the light, for ``getCameraImage(lightDirection=...)``.
    background_rgb : tuple of int or None
        Colour where camera rays hit nothing; ``None`` because every scene is closed.
    ceiling_ids : tuple of int
        Bodies to hide when the scene is viewed from above (ceiling, sky lid). They are
        single-sided, so a camera above them does not see them anyway.
    """

    name: str
    room_bounds: tuple[float, float, float, float]
    field_bounds: tuple[float, float, float, float]
    obstacles: tuple[tuple[float, float, float, float], ...]
    body_ids: tuple[int, ...]
    light_direction: tuple[float, float, float]
    background_rgb: tuple[int, int, int] | None = None
    ceiling_ids: tuple[int, ...] = field(default=())


# ---------------------------------------------------------------------------- helpers


class _Draw:
    """Layout choices: drawn from ``rng`` when randomising, else the canonical value."""

    def __init__(self, rng: np.random.Generator, randomize: bool) -> None:
        self.rng = rng
        self.on = randomize

    def uniform(self, canonical: float, lo: float, hi: float) -> float:
        return float(self.rng.uniform(lo, hi)) if self.on else float(canonical)

    def integers(self, canonical: int, lo: int, hi: int) -> int:
        """``canonical`` or a draw from ``lo..hi`` (inclusive)."""
        return int(self.rng.integers(lo, hi + 1)) if self.on else int(canonical)

    def choice(self, canonical, options: Sequence):
        return options[int(self.rng.integers(len(options)))] if self.on else canonical

    def chance(self, canonical: bool, p: float) -> bool:
        return bool(self.rng.uniform() < p) if self.on else bool(canonical)

    def colour(self, canonical: RGB, dh: float = 0.04, ds: float = 0.15, dv: float = 0.12):
        """``canonical`` (0..255) or a colour near it in hue, saturation and value."""
        rgb = np.asarray(canonical, np.float32)
        if not self.on:
            return rgb
        h, s, v = colorsys.rgb_to_hsv(*(rgb / 255.0))
        return tx.hsv(
            h + self.rng.uniform(-dh, dh),
            s + self.rng.uniform(-ds, ds),
            v + self.rng.uniform(-dv, dv),
        )


@dataclass
class _Part:
    """One visual shape of a furniture body, in world coordinates."""

    kind: str  # "box", "cyl" or "ball"
    centre: tuple[float, float, float]
    size: tuple[float, float, float]  # box: half extents; cyl: (r, r, length); ball: (r, r, r)
    rgb: RGB

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        (cx, cy, cz), (a, b, c) = self.centre, self.size
        if self.kind == "cyl":
            c = c / 2.0
        return cx - a, cx + a, cy - b, cy + b, cz - c, cz + c


def _box(x0, x1, y0, y1, z0, z1, rgb: RGB) -> _Part:
    return _Part(
        "box",
        ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2),
        (abs(x1 - x0) / 2, abs(y1 - y0) / 2, abs(z1 - z0) / 2),
        rgb,
    )


def _cyl(x, y, z0, z1, r, rgb: RGB) -> _Part:
    return _Part("cyl", (x, y, (z0 + z1) / 2), (r, r, z1 - z0), rgb)


def _ball(x, y, z, r, rgb: RGB) -> _Part:
    return _Part("ball", (x, y, z), (r, r, r), rgb)


def _rgba(rgb: RGB, alpha: float = 1.0) -> list[float]:
    c = np.clip(np.asarray(rgb, np.float64) / 255.0, 0.0, 1.0)
    return [float(c[0]), float(c[1]), float(c[2]), float(alpha)]


def _nudge(points: np.ndarray) -> np.ndarray:
    """Move points off round coordinates: by ±0.20, ±0.35 and ±0.27 mm in x, y and z.

    The tiny renderer loses a triangle whose vertex lies exactly in the plane through
    the eye perpendicular to the view direction (w = 0). Scenes are symmetric about
    the field centre and built from round numbers, and experiments put the robot at
    round positions and headings (the centre, 45° steps), which would put room corners
    exactly in that plane. The different step per axis also moves points off diagonal
    planes (``x ± y``: at least 0.15 mm). The signs are a fixed function of the
    position, so equal points get equal nudges and shared edges stay closed.
    """
    p = np.asarray(points, np.float64)
    h = np.sin(p @ _HASH + 0.5) * 43758.5453
    sign = np.where(h - np.floor(h) < 0.5, -1.0, 1.0)
    return p + sign * _NUDGE_M


Quad = tuple[Sequence[float], Sequence[float], Sequence[float], tuple[float, float, float, float]]


class _Builder:
    """Creates bodies in the client and collects their ids and obstacle footprints."""

    def __init__(self, bc, rng: np.random.Generator, randomize: bool) -> None:
        self.bc = bc
        self.rng = rng
        self.var = _Draw(rng, randomize)
        self.tex = tx.TextureStore(bc)
        self.bodies: list[int] = []
        self.obstacles: list[tuple[float, float, float, float]] = []
        self.ceilings: list[int] = []

    # --------------------------------------------------------------- textured meshes
    def mesh(
        self,
        quads: Sequence[Quad],
        image: np.ndarray | None = None,
        rgb: RGB = (255, 255, 255),
        *,
        normal: Sequence[float] | None = None,
        collision: tuple[Sequence[float], Sequence[float]] | None = None,
        obstacle: bool = True,
    ) -> int:
        """One static body made of quads, optionally textured with ``image``.

        Each quad is ``(origin, du, dv, (u0, v0, u1, v1))``: corners ``origin``,
        ``origin + du``, ``origin + du + dv``, ``origin + dv`` with texture coordinates
        from ``(u0, v0)`` to ``(u1, v1)`` (v = 0 is the image's bottom row). Its front is
        the side ``du x dv`` points to. ``normal`` overrides the shading normal (e.g. the
        sky is shaded as if it faced up). ``collision = (centre, half_extents)`` adds a
        collision box whose footprint becomes an obstacle.
        """
        fa, fb = _FAN
        verts: list[list[float]] = []
        uvs: list[list[float]] = []
        norms: list[list[float]] = []
        idx: list[int] = []
        for origin, du, dv, (u0, v0, u1, v1) in quads:
            o, a, b = (np.asarray(v, np.float64) for v in (origin, du, dv))
            n = np.cross(a, b) if normal is None else np.asarray(normal, np.float64)
            n = n / np.linalg.norm(n)
            base = len(verts)
            corners = (o, o + a, o + a + b, o + b, o + fa * a + fb * b)
            corner_uv = ((u0, v0), (u1, v0), (u1, v1), (u0, v1))
            corner_uv += ((u0 + fa * (u1 - u0), v0 + fb * (v1 - v0)),)
            verts += [c.tolist() for c in corners]
            uvs += [[float(u), float(v)] for u, v in corner_uv]
            norms += [n.tolist()] * 5
            for k in range(4):
                idx += [base + k, base + (k + 1) % 4, base + 4]
        bc = self.bc
        vis = bc.createVisualShape(
            bc.GEOM_MESH,
            vertices=_nudge(np.array(verts)).tolist(),
            indices=idx,
            uvs=uvs,
            normals=norms,
            rgbaColor=_rgba(rgb),
        )
        col = -1
        if collision is not None:
            centre, half = collision
            col = bc.createCollisionShape(
                bc.GEOM_BOX, halfExtents=list(half), collisionFramePosition=list(centre)
            )
        body = bc.createMultiBody(0, col, vis, [0.0, 0.0, 0.0])
        if image is not None:
            bc.changeVisualShape(
                body, -1, textureUniqueId=self.tex.load_image(image), rgbaColor=[1, 1, 1, 1]
            )
        if collision is not None and obstacle:
            (cx, cy, _), (hx, hy, _) = collision
            self.obstacles.append((cx - hx, cx + hx, cy - hy, cy + hy))
        self.bodies.append(body)
        return body

    def floor(self, body: int) -> None:
        """Make ``body`` the floor: friction 1.0 (the gait's tuning), first in the ids."""
        self.bc.changeDynamics(body, -1, lateralFriction=1.0)
        self.bodies.remove(body)
        self.bodies.insert(0, body)

    # ------------------------------------------------------------- solid furniture
    def solid(self, parts: Sequence[_Part], *, collide: bool = True) -> None:
        """Static bodies of up to 16 shapes each; one collision box spans all parts."""
        if not parts:
            return
        b = np.array([p.bounds() for p in parts])
        lo = np.array([b[:, 0].min(), b[:, 2].min(), b[:, 4].min()])
        hi = np.array([b[:, 1].max(), b[:, 3].max(), b[:, 5].max()])
        centre = (lo + hi) / 2.0
        bc = self.bc
        for start in range(0, len(parts), _MAX_SHAPES):
            chunk = parts[start : start + _MAX_SHAPES]
            types = {"box": bc.GEOM_BOX, "cyl": bc.GEOM_CYLINDER, "ball": bc.GEOM_SPHERE}
            vis = bc.createVisualShapeArray(
                shapeTypes=[types[p.kind] for p in chunk],
                halfExtents=[list(p.size) for p in chunk],
                radii=[p.size[0] for p in chunk],
                lengths=[p.size[2] for p in chunk],
                rgbaColors=[_rgba(p.rgb) for p in chunk],
                visualFramePositions=[(np.asarray(p.centre) - centre).tolist() for p in chunk],
            )
            col = -1
            if collide and start == 0:
                col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=((hi - lo) / 2).tolist())
            body = bc.createMultiBody(0, col, vis, _nudge(centre).tolist())
            self.bodies.append(body)
        if collide and lo[2] < _OBSTACLE_BELOW:
            self.obstacles.append((float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])))

    def fence(self, x0: float, x1: float, y0: float, y1: float, height: float = 1.0) -> None:
        """An invisible wall (collision box, fully transparent visual) and its footprint."""
        bc = self.bc
        half = [(x1 - x0) / 2, (y1 - y0) / 2, height / 2]
        vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=half, rgbaColor=[1, 1, 1, 0])
        col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=half)
        body = bc.createMultiBody(0, col, vis, [(x0 + x1) / 2, (y0 + y1) / 2, height / 2])
        self.bodies.append(body)
        self.obstacles.append((x0, x1, y0, y1))


# ------------------------------------------------------------------------------ rooms


@dataclass
class _Wall:
    """One wall seen from inside: ``u`` runs left to right along it, ``z`` up."""

    side: str
    length: float
    height: float
    canvas: tx.Canvas
    busy: list[tuple[float, float, float, float]] = field(default_factory=list)

    def free(self, u0: float, u1: float, z0: float, z1: float, margin: float = 0.12) -> bool:
        if u0 < 0.2 or u1 > self.length - 0.2 or z0 < 0.0 or z1 > self.height - 0.1:
            return False
        return all(
            u1 + margin <= a or u0 - margin >= b or z1 + margin <= c or z0 - margin >= d
            for a, b, c, d in self.busy
        )

    def take(self, u0: float, u1: float, z0: float, z1: float) -> None:
        self.busy.append((u0, u1, z0, z1))


class _Room:
    """A rectangular room; positions against a wall are given as (u along, d out of) it."""

    _DIRS = {"E": (0.0, -1.0), "N": (1.0, 0.0), "W": (0.0, 1.0), "S": (-1.0, 0.0)}

    def __init__(
        self,
        b: _Builder,
        bounds: tuple[float, float, float, float],
        height: float,
        wall_rgb: dict[str, RGB],
    ) -> None:
        self.b = b
        self.bounds = bounds
        self.height = height
        x0, x1, y0, y1 = bounds
        self.walls: dict[str, _Wall] = {}
        for side in "ENWS":
            length = (y1 - y0) if side in "EW" else (x1 - x0)
            canvas = tx.Canvas(length, height, _WALL_PPM, wall_rgb[side])
            self.walls[side] = _Wall(side, length, height, canvas)

    def origin(self, side: str) -> tuple[float, float]:
        """The wall's left end seen from inside."""
        x0, x1, y0, y1 = self.bounds
        return {"E": (x1, y1), "N": (x0, y1), "W": (x0, y0), "S": (x1, y0)}[side]

    def point(self, side: str, u: float, d: float) -> tuple[float, float]:
        """World ``(x, y)`` at ``u`` along wall ``side`` and ``d`` into the room."""
        ox, oy = self.origin(side)
        ax, ay = self._DIRS[side]
        return ox + u * ax + d * ay, oy + u * ay - d * ax

    def box(self, side, u0, u1, d0, d1, z0, z1, rgb: RGB) -> _Part:
        """A box from ``u0..u1`` along wall ``side``, ``d0..d1`` out of it, ``z0..z1``."""
        xa, ya = self.point(side, u0, d0)
        xb, yb = self.point(side, u1, d1)
        return _box(min(xa, xb), max(xa, xb), min(ya, yb), max(ya, yb), z0, z1, rgb)

    def cyl(self, side, u, d, z0, z1, r, rgb: RGB) -> _Part:
        x, y = self.point(side, u, d)
        return _cyl(x, y, z0, z1, r, rgb)

    def ball(self, side, u, d, z, r, rgb: RGB) -> _Part:
        x, y = self.point(side, u, d)
        return _ball(x, y, z, r, rgb)

    def quad(self, side, u0, u1, z0, z1, d) -> Quad:
        """A vertical quad parallel to wall ``side``, ``d`` in front of it, facing in."""
        x, y = self.point(side, u0, d)
        ax, ay = self._DIRS[side]
        return ((x, y, z0), (ax * (u1 - u0), ay * (u1 - u0), 0.0), (0, 0, z1 - z0), (0, 0, 1, 1))

    def build(self, floor: np.ndarray, ceiling: np.ndarray) -> None:
        """Create the floor, the four walls with their painted textures, the ceiling."""
        b = self.b
        x0, x1, y0, y1 = self.bounds
        w, d, h = x1 - x0, y1 - y0, self.height
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        floor_id = b.mesh(
            [((x0, y0, 0.0), (w, 0, 0), (0, d, 0), (0, 0, 1, 1))],
            floor,
            collision=((cx, cy, -0.25), (w / 2 + 1.0, d / 2 + 1.0, 0.25)),
            obstacle=False,
        )
        b.floor(floor_id)
        t = _WALL_T / 2
        boxes = {
            "E": ((x1 + t, cy, h / 2), (t, d / 2 + _WALL_T, h / 2)),
            "N": ((cx, y1 + t, h / 2), (w / 2 + _WALL_T, t, h / 2)),
            "W": ((x0 - t, cy, h / 2), (t, d / 2 + _WALL_T, h / 2)),
            "S": ((cx, y0 - t, h / 2), (w / 2 + _WALL_T, t, h / 2)),
        }
        for side, wall in self.walls.items():
            q = self.quad(side, 0.0, wall.length, 0.0, h, 0.0)
            b.mesh([q], wall.canvas.image(), collision=boxes[side])
        ceiling_id = b.mesh([((x0, y0, h), (0, d, 0), (w, 0, 0), (0, 0, 1, 1))], ceiling)
        b.ceilings.append(ceiling_id)


# ---------------------------------------------------------------- painted decorations


def _frame_colour(rng: np.random.Generator) -> tuple[np.ndarray, float]:
    kind = rng.uniform()
    if kind < 0.3:
        return np.array([25, 25, 25], np.float32), 0.035
    if kind < 0.5:
        return tx.hsv(rng.uniform(0.06, 0.1), rng.uniform(0.4, 0.7), rng.uniform(0.3, 0.6)), 0.05
    if kind < 0.7:
        return np.array([235, 235, 232], np.float32), 0.04
    if kind < 0.85:
        return np.array([175, 178, 182], np.float32), 0.025
    return tx.random_colour(rng), 0.04


def _hang_pictures(
    b: _Builder,
    wall: _Wall,
    n: int,
    z_range: tuple[float, float] = (0.5, 2.0),
    width: tuple[float, float] = (0.6, 1.5),
    paintings: bool = False,
) -> int:
    """Hang up to ``n`` framed pictures on free parts of ``wall``; returns how many.

    Posters are real photos, maps or procedural posters (:func:`tx.poster_image`);
    ``paintings`` draws landscapes and abstract paintings only.
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
        frame_rgb, frame_m = _frame_colour(rng)
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


def _door(b: _Builder, wall: _Wall, u0: float, width: float = 0.9) -> None:
    v = b.var
    leaf = v.colour((150, 105, 65), dh=0.5, ds=0.4, dv=0.3)
    casing = v.colour((238, 236, 230), dh=0.1, ds=0.05, dv=0.08)
    wall.canvas.door(u0, u0 + width, 2.05, leaf, casing)
    wall.take(u0 - 0.1, u0 + width + 0.1, 0.0, 2.15)


def _window(
    b: _Builder,
    wall: _Wall,
    u0: float,
    u1: float,
    z0: float,
    z1: float,
    *,
    radiator: bool = True,
    blinds: RGB | None = None,
    curtains: RGB | None = None,
) -> None:
    c = wall.canvas
    if curtains is not None:
        c.curtains(u0, u1, z0 - 0.3, min(z1 + 0.2, wall.height - 0.05), curtains, 0.35)
    c.window(u0, u1, z0, z1, tx.outdoor_view(b.rng), mullions=1 if u1 - u0 > 1.0 else 0)
    if blinds is not None:
        c.blinds(u0 + 0.06, u1 - 0.06, z0 + 0.06, z1 - 0.06, blinds)
    if radiator:
        c.radiator(u0 + 0.1, u1 - 0.1, 0.15, min(0.65, z0 - 0.15))
    pad = 0.45 if curtains is not None else 0.1
    wall.take(u0 - pad, u1 + pad, 0.0 if radiator else z0 - 0.1, z1 + 0.1)


def _baseboard(wall: _Wall, rgb: RGB, height: float = 0.08) -> None:
    wall.canvas.rect(0.0, wall.length, 0.0, height, rgb)


def _ceiling(b: _Builder, bounds, panels: bool = True) -> np.ndarray:
    x0, x1, y0, y1 = bounds
    # the ceiling's texture u runs along y, v along x (see _Room.build)
    c = tx.Canvas(y1 - y0, x1 - x0, 32.0, b.var.colour((240, 240, 236), dv=0.05))
    if panels:
        for u in np.arange(0.9, y1 - y0 - 0.9, 1.8):
            for v in np.arange(0.9, x1 - x0 - 1.2, 2.4):
                c.rect(u, u + 0.6, v, v + 1.2, (252, 252, 255))
                c.outline(u, u + 0.6, v, v + 1.2, 0.04, (200, 200, 200))
    return c.image()


# -------------------------------------------------------------------------- furniture


def _workstation(b: _Builder, room: _Room, side: str, u0: float, width: float = 1.6) -> None:
    """A table against ``side`` with one or two monitors, keyboard, PC box and chair.

    Everything stays within 1.2 m of the wall (the chair is half under the table).
    """
    v, rng = b.var, b.rng
    depth, top = 0.75, 0.74
    wood = v.colour((200, 170, 125), dh=0.05, ds=0.2, dv=0.2)
    leg = v.colour((90, 90, 95), dv=0.2)
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
    _chair(b, room, side, u0 + width / 2 + float(rng.uniform(-0.3, 0.3)), depth - 0.07)


def _chair(b: _Builder, room: _Room, side: str, uc: float, d0: float) -> None:
    """An office chair from ``d0`` to ``d0 + 0.52`` off wall ``side``, its back to the room."""
    v = b.var
    seat = v.colour((45, 70, 150), dh=0.5, ds=0.3, dv=0.3)
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


def _shelf(
    b: _Builder,
    room: _Room,
    side: str,
    u0: float,
    width: float,
    height: float = 1.85,
    depth: float = 0.35,
    frame: RGB = (120, 85, 55),
    binders: bool = False,
) -> None:
    """A bookshelf with coarse blocks of coloured books or binders on its shelves."""
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
                c = tx.random_colour(rng, s=(0.4, 1.0), v=(0.35, 0.95))
                dd = depth - 0.03 if binders else depth - 0.06
                parts.append(room.box(side, u, u + bw, 0.03, dd, z0 + 0.025, zt, c))
            u += bw + 0.01
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, height)


def _cabinet(
    b: _Builder, room: _Room, side: str, u0: float, width: float, height: float, rgb: RGB
) -> list[_Part]:
    """A low cabinet or chest of drawers; returns its parts (not yet built)."""
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


def _plant(b: _Builder, room: _Room, side: str, u: float, d: float, big: bool = True) -> None:
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


def _sofa(b: _Builder, room: _Room, side: str, u0: float, width: float, rgb: RGB) -> None:
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
        pillow = tx.random_colour(rng, s=(0.5, 1.0), v=(0.6, 1.0))
        parts.append(room.box(side, ua, ua + 0.4, 0.3, 0.45, 0.53, 0.88, pillow))
    for ua in (u0 + 0.03, u0 + width - 0.08):
        parts.append(room.box(side, ua, ua + 0.05, 0.1, 0.15, 0.0, 0.08, (50, 35, 25)))
        parts.append(
            room.box(side, ua, ua + 0.05, depth - 0.1, depth - 0.05, 0.0, 0.08, (50, 35, 25))
        )
    b.solid(parts)
    room.walls[side].take(u0, u0 + width, 0.0, 0.95)


def _floor_lamp(b: _Builder, room: _Room, side: str, u: float, d: float) -> None:
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


def _goal(b: _Builder, x_mouth: float, sign: float, rgb: RGB) -> None:
    """A RoboCup 4-legged goal (0.8 m wide, 0.3 m high, 0.25 m deep) behind ``x_mouth``."""
    white = (245, 245, 245)
    xb = x_mouth + sign * 0.25
    xa, xz = min(x_mouth, xb), max(x_mouth, xb)
    hw, h, t = 0.4, 0.3, 0.03
    back = (xb - sign * t, xb)
    parts = [
        _box(min(back), max(back), -hw, hw, 0.0, h, rgb),
        _box(xa, xz, -hw - t, -hw, 0.0, h, rgb),
        _box(xa, xz, hw, hw + t, 0.0, h, rgb),
        _box(xa, xz, -hw - t, hw + t, h, h + 0.02, rgb),
        _box(x_mouth - 0.02, x_mouth + 0.02, -hw - t, -hw, 0.0, h + 0.02, white),
        _box(x_mouth - 0.02, x_mouth + 0.02, hw, hw + t, 0.0, h + 0.02, white),
        _box(x_mouth - 0.02, x_mouth + 0.02, -hw - t, hw + t, h, h + 0.03, white),
    ]
    b.solid(parts)


# ----------------------------------------------------------------------------- scenes


def _sun(b: _Builder, canonical: tuple[float, float, float]) -> tuple[float, float, float]:
    if b.var.on:
        az = b.rng.uniform(0.0, 2.0 * math.pi)
        el = b.rng.uniform(math.radians(35.0), math.radians(75.0))
        vec = (math.cos(az) * math.cos(el), math.sin(az) * math.cos(el), math.sin(el))
    else:
        vec = canonical
    n = math.sqrt(sum(c * c for c in vec))
    return (vec[0] / n, vec[1] / n, vec[2] / n)


def _wall_colours(b: _Builder, canonical: RGB, spread: float = 0.0) -> dict[str, np.ndarray]:
    """The same paint on all walls (canonical) or a random light paint (randomised)."""
    v = b.var
    if v.on:
        if b.rng.uniform() < 0.6:
            base = tx.hsv(b.rng.uniform(), b.rng.uniform(0.02, 0.2), b.rng.uniform(0.82, 0.95))
        else:
            base = tx.hsv(b.rng.uniform(), b.rng.uniform(0.15, 0.45), b.rng.uniform(0.6, 0.9))
    else:
        base = np.asarray(canonical, np.float32)
    return {s: base for s in "ENWS"}


def _robolab(b: _Builder) -> tuple:
    v, rng = b.var, b.rng
    bounds, field_b, height = (-3.5, 3.5, -3.5, 3.5), (-3.0, 3.0, -2.0, 2.0), 2.8
    colours = _wall_colours(b, (232, 228, 212))
    desk_side = v.choice("N", ("N", "S"))
    window_side = "S" if desk_side == "N" else "N"
    accent_side = v.choice("W", ("E", "W", "none"))
    if accent_side != "none":
        colours[accent_side] = v.colour((120, 160, 200), dh=0.5, ds=0.2, dv=0.15)
    room = _Room(b, bounds, height, colours)
    base_rgb = v.colour((95, 95, 100), dh=0.5, ds=0.2, dv=0.2)
    for wall in room.walls.values():
        _baseboard(wall, base_rgb)
        wall.canvas.mottle(rng, 0.02, 1.0)

    # tables with computers and chairs along one side (paper, section 5)
    u = v.uniform(0.2, 0.1, 0.5)
    for _ in range(v.integers(3, 2, 3)):
        width = v.uniform(1.6, 1.2, 1.8)
        if u + width > 6.8:
            break
        _workstation(b, room, desk_side, u, width)
        u += width + v.uniform(0.25, 0.1, 0.6)
    if u + 1.0 < 6.9:
        _door(b, room.walls[desk_side], max(u + 0.1, v.uniform(5.9, u + 0.1, 6.0)))
    else:
        _door(b, room.walls["E"], v.uniform(5.6, 4.8, 5.9))

    # windows with radiators, a bookshelf and a cabinet with robot crates opposite
    win = room.walls[window_side]
    _shelf(b, room, window_side, v.uniform(0.15, 0.1, 0.4), 0.9, frame=v.colour((125, 90, 60)))
    n_win = v.integers(2, 1, 3)
    span0, span1 = 1.5, 5.6
    slot = (span1 - span0) / n_win
    for k in range(n_win):
        ww = v.uniform(1.5, 0.8, min(1.8, slot - 0.3))
        uc = span0 + (k + 0.5) * slot + v.uniform(0.0, -0.15, 0.15)
        _window(b, win, uc - ww / 2, uc + ww / 2, 0.95, 2.3)
    cab = _cabinet(b, room, window_side, 5.85, 1.0, 0.75, v.colour((200, 200, 195)))
    crates = [(210, 40, 40), (40, 90, 200), (240, 200, 30)]
    for k in range(2):
        c = crates[int(rng.integers(3))] if v.on else crates[k]
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
        _hang_pictures(b, room.walls[side], counts[side], (0.5, 2.05))

    # floor: grey linoleum, the green carpet with coarse white lines
    fx0, fx1, fy0, fy1 = field_b
    floor = tx.Canvas(7.0, 7.0, _FLOOR_PPM, v.colour((165, 165, 160), dv=0.1))
    floor.mottle(rng, 0.04, 0.7)
    green = v.colour((45, 120, 55), dh=0.03, ds=0.1, dv=0.1)
    sx, sy = fx0 - bounds[0], fy0 - bounds[2]  # field corner in canvas coordinates
    carpet = tx.Canvas(fx1 - fx0, fy1 - fy0, _FLOOR_PPM, green)
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
    room.build(floor.image(), _ceiling(b, bounds))
    return bounds, field_b, _sun(b, (0.35, -0.45, 0.82))


def _office(b: _Builder) -> tuple:
    v, rng = b.var, b.rng
    bounds, field_b, height = (-3.0, 3.0, -2.5, 2.5), (-2.0, 2.0, -1.0, 1.0), 2.7
    colours = _wall_colours(b, (240, 240, 236))
    accent = v.choice("W", ("E", "N", "W", "S"))
    colours[accent] = v.colour((70, 140, 150), dh=0.5, ds=0.25, dv=0.2)
    room = _Room(b, bounds, height, colours)
    for wall in room.walls.values():
        _baseboard(wall, (70, 72, 78), 0.1)
        wall.canvas.mottle(rng, 0.015, 1.0)
    desk_side = v.choice("N", ("N", "S"))
    window_side = "S" if desk_side == "N" else "N"

    # desks with monitors along one long wall
    u = v.uniform(0.3, 0.15, 0.8)
    for _ in range(v.integers(3, 2, 3)):
        width = v.uniform(1.6, 1.3, 1.8)
        if u + width > 5.85:
            break
        _workstation(b, room, desk_side, u, width)
        u += width + v.uniform(0.3, 0.15, 0.5)

    # tall shelves with binders on the east wall (or west)
    shelf_side = v.choice("E", ("E", "W"))
    board_side = "W" if shelf_side == "E" else "E"
    u = v.uniform(0.4, 0.2, 1.2)
    frame = v.colour((150, 155, 160), dh=0.5, ds=0.2, dv=0.2)
    for _ in range(v.integers(3, 2, 4)):
        if u + 0.9 > 4.8:
            break
        _shelf(b, room, shelf_side, u, 0.9, 1.95, 0.4, frame, binders=True)
        u += 0.92
    # windows with blinds, filing cabinets and a plant
    win = room.walls[window_side]
    blinds = v.colour((215, 215, 210), dh=0.5, ds=0.3, dv=0.1)
    for uc in (1.6, 4.4) if not v.on else sorted(rng.uniform(1.2, 4.8, 2)):
        if win.free(uc - 0.75, uc + 0.75, 0.8, 2.3, 0.05):
            _window(b, win, uc - 0.75, uc + 0.75, 0.8, 2.3, blinds=blinds)
    cab_rgb = v.colour((120, 125, 135), dh=0.5, ds=0.3, dv=0.2)
    cu = v.uniform(0.15, 0.1, 0.4)
    parts = _cabinet(b, room, window_side, cu, 0.5, 1.05, cab_rgb)
    parts += _cabinet(b, room, window_side, cu + 0.52, 0.5, 1.05, cab_rgb)
    b.solid(parts)
    printer = [room.box(window_side, 5.2, 5.8, 0.0, 0.5, 0.0, 0.75, (225, 225, 220))]
    printer.append(room.box(window_side, 5.25, 5.75, 0.05, 0.45, 0.75, 0.95, (90, 90, 95)))
    printer.append(room.box(window_side, 5.3, 5.7, 0.5, 0.53, 0.5, 0.6, (60, 60, 65)))
    b.solid(printer)
    room.walls[window_side].take(5.2, 5.8, 0.0, 1.0)
    _plant(b, room, shelf_side, v.uniform(4.6, 4.5, 4.7), 0.3)

    # whiteboard, door and posters
    board = room.walls[board_side]
    wu = v.uniform(1.0, 0.5, 2.4)
    board.canvas.board(rng, wu, wu + 2.2, 0.85, 2.05, "white")
    board.take(wu, wu + 2.2, 0.8, 2.05)
    _door(b, board, v.uniform(3.8, 3.6, 3.9))
    clock_wall = room.walls[v.choice(desk_side, ("E", "N", "W", "S"))]
    cu = v.uniform(2.9, 0.6, 5.0)
    if clock_wall.free(cu - 0.18, cu + 0.18, 2.1, 2.5, 0.05):
        clock_wall.canvas.clock(cu, 2.3, 0.17, (200, 40, 40))
        clock_wall.take(cu - 0.18, cu + 0.18, 2.1, 2.5)
    for side in "ENWS":
        _hang_pictures(b, room.walls[side], v.integers(4, 3, 5), (0.6, 2.1))

    # floor: blue-grey carpet tiles; ceiling with light panels
    floor = tx.Canvas(6.0, 5.0, _FLOOR_PPM, v.colour((95, 105, 125), dh=0.5, ds=0.2, dv=0.15))
    for i in range(12):
        for j in range(10):
            floor.shade(i * 0.5, i * 0.5 + 0.5, j * 0.5, j * 0.5 + 0.5, rng.uniform(0.93, 1.07))
    floor.mottle(rng, 0.03, 0.4)
    room.build(floor.image(), _ceiling(b, bounds))
    return bounds, field_b, _sun(b, (-0.3, -0.5, 0.8))


def _home(b: _Builder) -> tuple:
    v, rng = b.var, b.rng
    bounds, field_b, height = (-2.75, 2.75, -2.4, 2.4), (-1.5, 1.5, -1.2, 1.2), 2.6
    colours = _wall_colours(b, (236, 218, 186))
    if v.on and rng.uniform() < 0.5:  # warm paints in randomised homes
        colours = {
            s: tx.hsv(rng.uniform(0.0, 0.15), rng.uniform(0.15, 0.45), rng.uniform(0.7, 0.92))
            for s in "ENWS"
        }
    accent = v.choice("N", ("E", "N", "W", "S"))
    colours[accent] = v.colour((185, 105, 75), dh=0.06, ds=0.15, dv=0.15)
    room = _Room(b, bounds, height, colours)
    for wall in room.walls.values():
        _baseboard(wall, (245, 242, 235), 0.1)
        wall.canvas.mottle(rng, 0.02, 1.0)
    sofa_side = v.choice("N", ("N", "S"))
    tv_side = "S" if sofa_side == "N" else "N"

    # sofa with paintings above it, lamp and side table
    sofa_w = v.uniform(2.2, 1.8, 2.4)
    su = v.uniform(1.6, 1.2, 2.9)
    _sofa(b, room, sofa_side, su, sofa_w, v.colour((170, 60, 45), dh=0.5, ds=0.3, dv=0.2))
    _floor_lamp(b, room, sofa_side, su - 0.35, 0.35)
    st = su + sofa_w + 0.1
    if st + 0.5 < 5.3:
        wood = v.colour((120, 80, 50), dv=0.15)
        b.solid(
            [
                room.box(sofa_side, st, st + 0.5, 0.05, 0.55, 0.52, 0.56, wood),
                room.box(sofa_side, st + 0.05, st + 0.45, 0.1, 0.5, 0.0, 0.52, wood * 0.8),
                room.cyl(sofa_side, st + 0.25, 0.3, 0.56, 0.8, 0.07, tx.random_colour(rng)),
            ]
        )
        room.walls[sofa_side].take(st, st + 0.5, 0.0, 0.85)
    _hang_pictures(b, room.walls[sofa_side], v.integers(3, 2, 4), (1.0, 2.2), (0.6, 1.3), True)

    # TV on a low cabinet, plant, window with curtains
    tu = v.uniform(1.95, 1.2, 2.5)
    tv_parts = _cabinet(b, room, tv_side, tu, 1.6, 0.5, v.colour((80, 55, 40), dv=0.2))
    tc = tu + 0.8
    tv_parts.append(room.box(tv_side, tc - 0.15, tc + 0.15, 0.1, 0.3, 0.5, 0.53, (20, 20, 22)))
    tv_parts.append(room.box(tv_side, tc - 0.04, tc + 0.04, 0.14, 0.18, 0.53, 0.65, (20, 20, 22)))
    tv_parts.append(room.box(tv_side, tc - 0.62, tc + 0.62, 0.14, 0.2, 0.62, 1.33, (20, 20, 22)))
    b.solid(tv_parts)
    show = tx.procedural_poster(rng, (90, 160), str(rng.choice(["landscape", "chart", "text"])))
    b.mesh([room.quad(tv_side, tc - 0.58, tc + 0.58, 0.66, 1.29, 0.202)], show)
    room.walls[tv_side].take(tu, tu + 1.6, 0.0, 1.4)
    _plant(b, room, tv_side, v.uniform(0.45, 0.35, 0.8), 0.35)
    curtain = v.colour((150, 40, 50), dh=0.5, ds=0.2, dv=0.2)
    win_u = v.uniform(4.3, 4.0, 4.5) if tu + 1.6 < 3.9 else 0.9
    _window(b, room.walls[tv_side], win_u - 0.2, win_u + 0.65, 1.0, 2.15, curtains=curtain)

    # bookshelf and armchair on one end wall, window, sideboard and clock on the other
    shelf_side = v.choice("E", ("E", "W"))
    other = "W" if shelf_side == "E" else "E"
    _shelf(b, room, shelf_side, v.uniform(2.6, 2.4, 3.3), 1.2, 1.95, 0.35, v.colour((110, 75, 45)))
    arm = v.colour((70, 110, 90), dh=0.5, ds=0.2, dv=0.2)
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
    _door(b, room.walls[shelf_side], v.uniform(3.95, 3.9, 3.95), 0.85)
    o = room.walls[other]
    _window(b, o, 1.5, 3.3, 0.95, 2.1, radiator=False, curtains=curtain)
    sb = _cabinet(b, room, other, 0.25, 1.0, 0.85, v.colour((95, 60, 40), dv=0.15))
    sb.append(room.cyl(other, 0.55, 0.22, 0.85, 1.15, 0.08, tx.random_colour(rng)))
    b.solid(sb)
    o.canvas.clock(4.1, 1.95, 0.18, (90, 60, 35))
    o.take(3.9, 4.3, 1.75, 2.15)
    _plant(b, room, other, 4.3, 0.3)
    for side in "ENWS":
        if side != sofa_side:
            _hang_pictures(b, room.walls[side], v.integers(3, 2, 4), (0.7, 2.2), (0.5, 1.2), True)

    # floor: wooden boards with a big patterned rug under the free area
    wood = v.colour((160, 110, 70), dh=0.03, ds=0.15, dv=0.15)
    floor = tx.Canvas(5.5, 4.8, _FLOOR_PPM, wood)
    bw = 0.18
    for i in range(int(4.8 / bw) + 1):
        x = float(-rng.uniform(0.0, 1.5))
        while x < 5.5:
            ln = float(rng.uniform(0.8, 1.8))
            floor.shade(x, x + ln - 0.01, i * bw, (i + 1) * bw - 0.01, rng.uniform(0.88, 1.1))
            x += ln
    floor.mottle(rng, 0.03, 0.5)
    rug = v.colour((150, 40, 40), dh=0.5, ds=0.2, dv=0.2)
    border = v.colour((230, 200, 120), dh=0.5, ds=0.2, dv=0.1)
    rx0, rx1, ry0, ry1 = 1.15, 4.35, 1.3, 3.5
    floor.rect(rx0, rx1, ry0, ry1, border)
    floor.rect(rx0 + 0.15, rx1 - 0.15, ry0 + 0.15, ry1 - 0.15, rug)
    floor.disc((rx0 + rx1) / 2, (ry0 + ry1) / 2, 0.6, border)
    floor.disc((rx0 + rx1) / 2, (ry0 + ry1) / 2, 0.4, rug * 0.6)
    room.build(floor.image(), _ceiling(b, bounds, panels=False))
    return bounds, field_b, _sun(b, (0.5, 0.35, 0.8))


def _outdoor(b: _Builder) -> tuple:
    v, rng = b.var, b.rng
    reach, field_b = (-7.0, 7.0, -5.0, 5.0), (-3.0, 3.0, -2.0, 2.0)
    radius, sky_h, ground = 34.0, 22.0, 35.0

    # grass: mowing stripes, white lines of a 44 x 28 m pitch
    g = v.colour((70, 135, 55), dh=0.03, ds=0.15, dv=0.12)
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
                _box(xg - 0.06, xg + 0.06, -2.56, -2.44, 0.0, 2.0, post),
                _box(xg - 0.06, xg + 0.06, 2.44, 2.56, 0.0, 2.0, post),
                _box(xg - 0.06, xg + 0.06, -2.56, 2.56, 1.9, 2.02, post),
                _box(min(xb, xb - sgn * 0.03), max(xb, xb - sgn * 0.03), -2.5, 2.5, 0.0, 1.6, net),
                _box(xa, xz, -2.53, -2.5, 0.0, 1.9, net),
                _box(xa, xz, 2.5, 2.53, 0.0, 1.9, net),
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
            parts.append(_cyl(sx, sy, 0.0, 14.0, 0.18, mast))
            parts.append(_box(sx - 1.0, sx + 1.0, sy - 0.2, sy + 0.2, 13.6, 14.8, (235, 235, 225)))
    b.solid(parts, collide=False)
    stand_side = v.choice(1.0, (1.0, -1.0))
    _grandstand(b, stand_side, v.colour((30, 80, 170), dh=0.5, ds=0.2, dv=0.2))
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
        trees.append(_cyl(x, y, 0.0, h * 0.5, 0.25, (95, 70, 45)))
        if rng.uniform() < 0.6:
            trees.append(_ball(x, y, h * 0.65, h * 0.3, leaf))
        else:
            trees.append(_cyl(x, y, h * 0.35, h, h * 0.22, leaf))
    b.solid(trees, collide=False)

    # invisible fences round the area the robot may reach
    x0, x1, y0, y1 = reach
    t = 0.2
    b.fence(x1, x1 + t, y0 - t, y1 + t)
    b.fence(x0 - t, x0, y0 - t, y1 + t)
    b.fence(x0, x1, y1, y1 + t)
    b.fence(x0, x1, y0 - t, y0)
    return reach, field_b, _sun(b, (0.3, -0.4, 0.85))


def _grandstand(b: _Builder, side: float, seat: RGB) -> None:
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
        parts.append(_box(-12.0, 12.0, y0, y1, 0.0, 0.5 + s * 0.5, concrete))
        colour = seat if s % 2 == 0 else seat * np.float32(0.8)
        parts.append(_box(-12.0, 12.0, y0, y1, 0.5 + s * 0.5, 0.8 + s * 0.5, colour))
    parts.append(_box(-12.2, 12.2, *ys(4.0, 4.3), 0.0, 4.2, grey))
    parts.append(_box(-12.5, 12.5, *ys(-0.5, 4.3), 4.2, 4.5, b.var.colour((180, 40, 40), dh=0.5)))
    for xp in (-12.0, 0.0, 12.0):
        parts.append(_box(xp - 0.1, xp + 0.1, *ys(-0.4, -0.2), 0.0, 4.2, grey))
    b.solid(parts)


def _building(
    b: _Builder, rng: np.random.Generator, cx: float, cy: float, w: float, d: float, h: float
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
    b.solid([_box(x0 - 0.2, x1 + 0.2, y0 - 0.2, y1 + 0.2, h, h + 0.4, roof)], collide=False)


_BUILDERS = {"robolab": _robolab, "office": _office, "home": _home, "outdoor_field": _outdoor}


def build_scene(
    bc, name: str = "robolab", rng: np.random.Generator | None = None, randomize: bool = False
) -> Scene:
    """Build scene ``name`` into the client ``bc``.

    The caller owns the client and calls ``bc.resetSimulation()`` before building a new
    scene into it (textures are freed only then); this function never connects or resets.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client (its ``physicsClientId`` goes into every call).
    name : str
        One of :data:`SCENES`.
    rng : numpy.random.Generator, optional
        Source of every random draw when ``randomize`` (required then); ignored
        otherwise. The same generator state gives the same scene.
    randomize : bool
        ``False``: the canonical scene for ``name``, the same for any ``rng``. ``True``:
        domain randomisation of wall, floor and furniture colours, posters (selection,
        pictures, size and placement), furniture placement, windows and doors, and the
        light direction.

    Returns
    -------
    Scene
        Bounds, obstacles, body ids and light of the built scene.

    Raises
    ------
    ValueError
        On an unknown name (the message lists :data:`SCENES`), an ``rng`` that is not a
        ``numpy.random.Generator``, a non-bool ``randomize``, or ``randomize=True``
        without an ``rng``.
    """
    if not isinstance(name, str) or name not in SCENES:
        raise ValueError(f"unknown scene {name!r}; choose one of {', '.join(SCENES)}")
    if rng is not None and not isinstance(rng, np.random.Generator):
        raise ValueError(
            "rng must be a numpy.random.Generator (np.random.default_rng(seed)) or None, "
            f"got {type(rng).__name__}; scenes: {', '.join(SCENES)}"
        )
    if not isinstance(randomize, bool | np.bool_):
        raise ValueError(f"randomize must be a bool, got {randomize!r}")
    if randomize and rng is None:
        raise ValueError("randomize=True needs rng=np.random.default_rng(seed)")
    gen = rng if randomize else np.random.default_rng(_CANONICAL_SEEDS[name])
    b = _Builder(bc, gen, bool(randomize))
    with b.tex:  # removes the temporary texture folder, also if the build fails
        bounds, field_b, light = _BUILDERS[name](b)
    return Scene(
        name=name,
        room_bounds=tuple(float(c) for c in bounds),
        field_bounds=tuple(float(c) for c in field_b),
        obstacles=tuple(tuple(float(c) for c in o) for o in b.obstacles),
        body_ids=tuple(b.bodies),
        light_direction=tuple(float(c) for c in light),
        background_rgb=None,
        ceiling_ids=tuple(b.ceilings),
    )
