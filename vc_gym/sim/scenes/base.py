"""The scene toolkit: :class:`Scene`, :class:`Builder`, :class:`Room` and the parts.

A scene builder (see :func:`vc_gym.sim.scenes.register_scene`) receives a
:class:`Builder` and creates every body of its scene through it:

* :meth:`Builder.mesh` makes a static body of textured quads (floors, walls, ceilings,
  posters, screens, a sky);
* :meth:`Builder.solid` makes furniture from :class:`Part` boxes, cylinders and spheres
  (:func:`box`, :func:`cyl`, :func:`ball`);
* :meth:`Builder.fence` makes an invisible wall;
* :class:`Room` lays out a rectangular room whose four :class:`Wall` canvases are painted
  (doors, windows, pictures: see :mod:`vc_gym.sim.scenes.furniture`) and then built as
  one textured quad each, with the floor and the ceiling (:meth:`Room.build`).

:attr:`Builder.var` (a :class:`Draw`) gives each layout choice its canonical value, or a
random one when the scene is built with ``randomize=True``.

How the scenes are made fast and artefact-free for PyBullet's tiny renderer:

* walls, floors and ceilings are single textured quads into which everything flat is
  painted (doors, windows, boards, posters), so a room is a handful of bodies;
* every quad is a fan of four triangles around an off-centre point: the tiny renderer
  drops triangles that cross the camera's near plane when the eye lies exactly above one
  of their edges, and a fan keeps edges away from round coordinates such as the origin;
* every vertex is nudged off round coordinates by a fraction of a millimetre (the
  renderer drops a triangle with a corner exactly in the eye's plane);
* furniture is made of boxes, cylinders and spheres, at most 16 visual shapes per body
  (``createVisualShapeArray`` crashes above that), with one collision box per piece;
* triangles wound counter-clockwise seen from the room (the renderer culls back faces),
  so the ceiling is invisible from above.
"""

from __future__ import annotations

import colorsys
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple, TypeVar

import numpy as np

from vc_gym.sim import textures as tx

__all__ = [
    "FLOOR_PPM",
    "RGB",
    "WALL_PPM",
    "Builder",
    "Draw",
    "Part",
    "Quad",
    "Room",
    "Scene",
    "SceneLayout",
    "Wall",
    "ball",
    "box",
    "cyl",
]

#: Texture resolution of the walls a :class:`Room` paints (pixels per metre).
WALL_PPM = 128.0
#: Texture resolution the built-in scenes use for their floors (pixels per metre).
FLOOR_PPM = 100.0
_MAX_SHAPES = 16  # createVisualShapeArray segfaults above 16 shapes (pybullet 3.2.7)

#: pybullet (3.2.7) never releases the lists given to ``createVisualShape`` as a mesh's
#: vertices, indices, uvs and normals (nor their rows): every scene build leaked ~20 KB
#: of them, for every env made and closed. Passing the same list objects for the same
#: geometry turns that leak into reference counts on lists kept here once.
_SHARED_LISTS: dict[tuple, list] = {}
_MAX_SHARED_LISTS = 100_000  # randomised scenes make new geometry; bound what is kept


def _shared_list(rows: list) -> list:
    """The one list object kept for this content (see :data:`_SHARED_LISTS`)."""
    nested = bool(rows) and isinstance(rows[0], list)
    key = (nested, tuple(tuple(r) for r in rows) if nested else tuple(rows))
    kept = _SHARED_LISTS.get(key)
    if kept is None:
        if len(_SHARED_LISTS) >= _MAX_SHARED_LISTS:
            _SHARED_LISTS.clear()
        kept = _SHARED_LISTS[key] = [list(r) for r in rows] if nested else list(rows)
    return kept


_FAN = (0.4637, 0.5291)  # interior vertex of every quad (fractions along du, dv)
_NUDGE_M = np.array([2.0e-4, 3.5e-4, 2.7e-4])  # see _nudge
_HASH = np.array([[12.9898, 78.233, 37.719], [39.346, 11.135, 83.155], [73.156, 52.235, 9.151]])
_WALL_T = 0.2  # collision thickness of walls (m)
_OBSTACLE_BELOW = 0.35  # parts lower than this block the robot (m)

#: A colour: three numbers 0..255 (red, green, blue).
RGB = Sequence[float]
#: A quad ``(origin, du, dv, (u0, v0, u1, v1))``: see :meth:`Builder.mesh`.
Quad = tuple[Sequence[float], Sequence[float], Sequence[float], tuple[float, float, float, float]]

_T = TypeVar("_T")


@dataclass(frozen=True)
class Scene:
    """A built scene: where things are, for the env, the robot and the top view.

    Attributes
    ----------
    name : str
        Registered name of the scene (see :func:`vc_gym.sim.scenes.scene_names`).
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


class SceneLayout(NamedTuple):
    """What a scene builder returns (a plain 3-tuple in the same order works too).

    Attributes
    ----------
    room_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces, or of the area the robot
        may reach outdoors (see :attr:`Scene.room_bounds`).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` where the robot may be placed: free of obstacles
        (keep furniture at least 0.2 m away) and inside ``room_bounds``.
    light_direction : tuple of float
        Vector towards the light, pointing up (``z > 0``); :func:`~vc_gym.sim.scenes.
        furniture.sun` gives a canonical or randomised one. Normalised by
        :func:`~vc_gym.sim.scenes.build_scene`.
    """

    room_bounds: tuple[float, float, float, float]
    field_bounds: tuple[float, float, float, float]
    light_direction: tuple[float, float, float]


# ---------------------------------------------------------------------------- helpers


class Draw:
    """Layout choices: drawn from ``rng`` when randomising, else the canonical value.

    Every method takes the canonical value first, then the range to draw from; with
    ``randomize=False`` it returns the canonical value and draws nothing, so the canonical
    scene does not depend on how many choices a builder makes.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the random draws.
    randomize : bool
        Whether to draw (``True``) or return the canonical values (``False``).

    Attributes
    ----------
    rng : numpy.random.Generator
        The generator.
    on : bool
        ``randomize``.
    """

    def __init__(self, rng: np.random.Generator, randomize: bool) -> None:
        self.rng = rng
        self.on = randomize

    def uniform(self, canonical: float, lo: float, hi: float) -> float:
        """``canonical`` or a uniform draw from ``[lo, hi)``.

        Parameters
        ----------
        canonical : float
            Value of the canonical scene.
        lo, hi : float
            Range of the random draw.

        Returns
        -------
        float
            The value.
        """
        return float(self.rng.uniform(lo, hi)) if self.on else float(canonical)

    def integers(self, canonical: int, lo: int, hi: int) -> int:
        """``canonical`` or a draw from ``lo..hi`` (inclusive).

        Parameters
        ----------
        canonical : int
            Value of the canonical scene.
        lo, hi : int
            Range of the random draw, both ends included.

        Returns
        -------
        int
            The value.
        """
        return int(self.rng.integers(lo, hi + 1)) if self.on else int(canonical)

    def choice(self, canonical: _T, options: Sequence[_T]) -> _T:
        """``canonical`` or one of ``options``, each equally likely.

        Parameters
        ----------
        canonical : object
            Value of the canonical scene.
        options : sequence
            What to draw from.

        Returns
        -------
        object
            The value.
        """
        return options[int(self.rng.integers(len(options)))] if self.on else canonical

    def chance(self, canonical: bool, p: float) -> bool:
        """``canonical`` or ``True`` with probability ``p``.

        Parameters
        ----------
        canonical : bool
            Value of the canonical scene.
        p : float
            Probability of ``True`` when randomising.

        Returns
        -------
        bool
            The value.
        """
        return bool(self.rng.uniform() < p) if self.on else bool(canonical)

    def colour(
        self, canonical: RGB, dh: float = 0.04, ds: float = 0.15, dv: float = 0.12
    ) -> np.ndarray:
        """``canonical`` (0..255) or a colour near it in hue, saturation and value.

        Parameters
        ----------
        canonical : sequence of float
            RGB colour (0..255) of the canonical scene.
        dh, ds, dv : float
            Largest change of hue, saturation and value (each on a 0..1 scale) when
            randomising.

        Returns
        -------
        numpy.ndarray
            ``float32`` RGB colour (0..255); multiply it to shade it (``rgb * 0.8``).
        """
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
class Part:
    """One visual shape of a furniture body, in world coordinates.

    Make parts with :func:`box`, :func:`cyl` and :func:`ball` (or :meth:`Room.box`,
    :meth:`Room.cyl`, :meth:`Room.ball`) and build them with :meth:`Builder.solid`.

    Attributes
    ----------
    kind : str
        ``"box"``, ``"cyl"`` or ``"ball"``.
    centre : tuple of float
        Centre ``(x, y, z)`` in metres.
    size : tuple of float
        box: half extents; cyl: ``(r, r, length)``; ball: ``(r, r, r)``.
    rgb : sequence of float
        Colour, 0..255.
    """

    kind: str  # "box", "cyl" or "ball"
    centre: tuple[float, float, float]
    size: tuple[float, float, float]  # box: half extents; cyl: (r, r, length); ball: (r, r, r)
    rgb: RGB

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """Axis-aligned bounds ``(xmin, xmax, ymin, ymax, zmin, zmax)``."""
        (cx, cy, cz), (a, b, c) = self.centre, self.size
        if self.kind == "cyl":
            c = c / 2.0
        return cx - a, cx + a, cy - b, cy + b, cz - c, cz + c


def box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, rgb: RGB) -> Part:
    """An axis-aligned box from ``x0..x1``, ``y0..y1``, ``z0..z1`` (metres).

    Parameters
    ----------
    x0, x1, y0, y1, z0, z1 : float
        Opposite corners (either order).
    rgb : sequence of float
        Colour, 0..255.

    Returns
    -------
    Part
        The box.
    """
    return Part(
        "box",
        ((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2),
        (abs(x1 - x0) / 2, abs(y1 - y0) / 2, abs(z1 - z0) / 2),
        rgb,
    )


def cyl(x: float, y: float, z0: float, z1: float, r: float, rgb: RGB) -> Part:
    """An upright cylinder of radius ``r`` at ``(x, y)`` from height ``z0`` to ``z1``.

    Parameters
    ----------
    x, y : float
        Axis position (m).
    z0, z1 : float
        Bottom and top (m).
    r : float
        Radius (m).
    rgb : sequence of float
        Colour, 0..255.

    Returns
    -------
    Part
        The cylinder.
    """
    return Part("cyl", (x, y, (z0 + z1) / 2), (r, r, z1 - z0), rgb)


def ball(x: float, y: float, z: float, r: float, rgb: RGB) -> Part:
    """A sphere of radius ``r`` centred at ``(x, y, z)``.

    Parameters
    ----------
    x, y, z : float
        Centre (m).
    r : float
        Radius (m).
    rgb : sequence of float
        Colour, 0..255.

    Returns
    -------
    Part
        The sphere.
    """
    return Part("ball", (x, y, z), (r, r, r), rgb)


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


class Builder:
    """Creates bodies in the client and collects their ids and obstacle footprints.

    :func:`~vc_gym.sim.scenes.build_scene` makes one and passes it to the scene's
    builder function; a builder function creates every body through it (or appends the
    ids of bodies it makes itself to :attr:`bodies`).

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client to build into.
    rng : numpy.random.Generator
        Source of every random draw (textures, posters, randomised layout).
    randomize : bool
        Whether :attr:`var` draws layout choices or returns the canonical ones.

    Attributes
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client. Pass nothing else as ``physicsClientId``: its methods add it.
    rng : numpy.random.Generator
        The scene's generator. Draw from it even in the canonical scene (which is built
        with a fixed seed), e.g. for texture noise, so that the canonical scene is varied
        but always the same.
    var : Draw
        Layout choices, canonical or randomised.
    tex : vc_gym.sim.textures.TextureStore
        Loads each texture image once.
    bodies : list of int
        Every body made so far; the first is the floor (see :meth:`floor`).
    obstacles : list of tuple of float
        Floor footprints ``(xmin, xmax, ymin, ymax)`` that block the robot.
    ceilings : list of int
        Bodies hidden in the top view (ceilings, sky lids).
    """

    def __init__(self, bc: Any, rng: np.random.Generator, randomize: bool) -> None:
        self.bc = bc
        self.rng = rng
        self.var = Draw(rng, randomize)
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
        the side ``du x dv`` points to; its back is invisible.

        Parameters
        ----------
        quads : sequence of Quad
            The quads; all share ``image``.
        image : numpy.ndarray, optional
            ``(H, W, 3)`` ``uint8`` RGB texture; paint it with
            :class:`vc_gym.sim.textures.Canvas`. Keep patterns coarse (at least 4-5 cm
            on a wall): fine stripes alias in the 208 x 160 camera.
        rgb : sequence of float
            Colour (0..255) of an untextured body.
        normal : sequence of float, optional
            Overrides the shading normal (e.g. the sky is shaded as if it faced up).
        collision : tuple, optional
            ``(centre, half_extents)`` of a collision box.
        obstacle : bool
            Whether the collision box's footprint becomes an obstacle.

        Returns
        -------
        int
            The body id.
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
            vertices=_shared_list(_nudge(np.array(verts)).tolist()),
            indices=_shared_list(idx),
            uvs=_shared_list(uvs),
            normals=_shared_list(norms),
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
        """Make ``body`` the floor: friction 1.0 (the gait's tuning), first in the ids.

        Parameters
        ----------
        body : int
            A body made by this builder (:meth:`Room.build` calls this for its floor).
        """
        self.bc.changeDynamics(body, -1, lateralFriction=1.0)
        self.bodies.remove(body)
        self.bodies.insert(0, body)

    # ------------------------------------------------------------- solid furniture
    def solid(self, parts: Sequence[Part], *, collide: bool = True) -> None:
        """Static bodies of up to 16 shapes each; one collision box spans all parts.

        Parameters
        ----------
        parts : sequence of Part
            The shapes of one piece of furniture (more than 16 make several bodies).
        collide : bool
            Give the piece a collision box spanning all parts; if it reaches below
            0.35 m its footprint becomes an obstacle. ``False`` for scenery out of reach.
        """
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
        """An invisible wall (collision box, fully transparent visual) and its footprint.

        Parameters
        ----------
        x0, x1, y0, y1 : float
            Footprint (m).
        height : float
            Height (m).
        """
        bc = self.bc
        half = [(x1 - x0) / 2, (y1 - y0) / 2, height / 2]
        vis = bc.createVisualShape(bc.GEOM_BOX, halfExtents=half, rgbaColor=[1, 1, 1, 0])
        col = bc.createCollisionShape(bc.GEOM_BOX, halfExtents=half)
        body = bc.createMultiBody(0, col, vis, [(x0 + x1) / 2, (y0 + y1) / 2, height / 2])
        self.bodies.append(body)
        self.obstacles.append((x0, x1, y0, y1))


# ------------------------------------------------------------------------------ rooms


@dataclass
class Wall:
    """One wall seen from inside: ``u`` runs left to right along it, ``z`` up.

    Paint on :attr:`canvas` (a :class:`vc_gym.sim.textures.Canvas` measured in metres,
    ``(u, z)`` with ``z`` up); record painted or furnished areas with :meth:`take` so that
    later pictures (:func:`~vc_gym.sim.scenes.furniture.hang_pictures`) avoid them.

    Attributes
    ----------
    side : str
        ``"E"``, ``"N"``, ``"W"`` or ``"S"``: the wall at ``x = xmax``, ``y = ymax``,
        ``x = xmin``, ``y = ymin``.
    length, height : float
        Size (m).
    canvas : vc_gym.sim.textures.Canvas
        The wall's texture.
    busy : list of tuple of float
        Taken areas ``(u0, u1, z0, z1)``.
    """

    side: str
    length: float
    height: float
    canvas: tx.Canvas
    busy: list[tuple[float, float, float, float]] = field(default_factory=list)

    def free(self, u0: float, u1: float, z0: float, z1: float, margin: float = 0.12) -> bool:
        """Whether ``u0..u1`` x ``z0..z1`` is on the wall and ``margin`` from taken areas.

        Parameters
        ----------
        u0, u1, z0, z1 : float
            The area (m).
        margin : float
            Least distance from taken areas (m).

        Returns
        -------
        bool
            ``True`` if free.
        """
        if u0 < 0.2 or u1 > self.length - 0.2 or z0 < 0.0 or z1 > self.height - 0.1:
            return False
        return all(
            u1 + margin <= a or u0 - margin >= b or z1 + margin <= c or z0 - margin >= d
            for a, b, c, d in self.busy
        )

    def take(self, u0: float, u1: float, z0: float, z1: float) -> None:
        """Mark ``u0..u1`` x ``z0..z1`` (m) as taken."""
        self.busy.append((u0, u1, z0, z1))


class Room:
    """A rectangular room; positions against a wall are given as (u along, d out of) it.

    Make the room, paint and furnish it, then call :meth:`build` once to create the
    floor, the four walls (with what was painted on them) and the ceiling.

    Parameters
    ----------
    b : Builder
        The scene's builder.
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces (m).
    height : float
        Wall height (m).
    wall_rgb : dict
        Paint of each wall, keyed ``"E"``, ``"N"``, ``"W"``, ``"S"`` (RGB 0..255).

    Attributes
    ----------
    walls : dict of str to Wall
        The walls, keyed by side. Seen from inside, a wall's ``u`` runs from its left
        end (:meth:`origin`) to the right.
    """

    _DIRS = {"E": (0.0, -1.0), "N": (1.0, 0.0), "W": (0.0, 1.0), "S": (-1.0, 0.0)}

    def __init__(
        self,
        b: Builder,
        bounds: tuple[float, float, float, float],
        height: float,
        wall_rgb: dict[str, RGB],
    ) -> None:
        self.b = b
        self.bounds = bounds
        self.height = height
        x0, x1, y0, y1 = bounds
        self.walls: dict[str, Wall] = {}
        for side in "ENWS":
            length = (y1 - y0) if side in "EW" else (x1 - x0)
            canvas = tx.Canvas(length, height, WALL_PPM, wall_rgb[side])
            self.walls[side] = Wall(side, length, height, canvas)

    def origin(self, side: str) -> tuple[float, float]:
        """The wall's left end seen from inside, ``(x, y)``."""
        x0, x1, y0, y1 = self.bounds
        return {"E": (x1, y1), "N": (x0, y1), "W": (x0, y0), "S": (x1, y0)}[side]

    def point(self, side: str, u: float, d: float) -> tuple[float, float]:
        """World ``(x, y)`` at ``u`` along wall ``side`` and ``d`` into the room."""
        ox, oy = self.origin(side)
        ax, ay = self._DIRS[side]
        return ox + u * ax + d * ay, oy + u * ay - d * ax

    def box(
        self,
        side: str,
        u0: float,
        u1: float,
        d0: float,
        d1: float,
        z0: float,
        z1: float,
        rgb: RGB,
    ) -> Part:
        """A box from ``u0..u1`` along wall ``side``, ``d0..d1`` out of it, ``z0..z1``.

        Returns
        -------
        Part
            The box, in world coordinates.
        """
        xa, ya = self.point(side, u0, d0)
        xb, yb = self.point(side, u1, d1)
        return box(min(xa, xb), max(xa, xb), min(ya, yb), max(ya, yb), z0, z1, rgb)

    def cyl(self, side: str, u: float, d: float, z0: float, z1: float, r: float, rgb: RGB) -> Part:
        """An upright cylinder at ``u`` along wall ``side``, ``d`` out of it.

        Returns
        -------
        Part
            The cylinder, in world coordinates.
        """
        x, y = self.point(side, u, d)
        return cyl(x, y, z0, z1, r, rgb)

    def ball(self, side: str, u: float, d: float, z: float, r: float, rgb: RGB) -> Part:
        """A sphere centred ``u`` along wall ``side``, ``d`` out of it, at height ``z``.

        Returns
        -------
        Part
            The sphere, in world coordinates.
        """
        x, y = self.point(side, u, d)
        return ball(x, y, z, r, rgb)

    def quad(self, side: str, u0: float, u1: float, z0: float, z1: float, d: float) -> Quad:
        """A vertical quad parallel to wall ``side``, ``d`` in front of it, facing in.

        Returns
        -------
        Quad
            For :meth:`Builder.mesh` (texture coordinates 0..1).
        """
        x, y = self.point(side, u0, d)
        ax, ay = self._DIRS[side]
        return ((x, y, z0), (ax * (u1 - u0), ay * (u1 - u0), 0.0), (0, 0, z1 - z0), (0, 0, 1, 1))

    def build(self, floor: np.ndarray, ceiling: np.ndarray) -> None:
        """Create the floor, the four walls with their painted textures, the ceiling.

        Parameters
        ----------
        floor : numpy.ndarray
            Floor texture, ``(H, W, 3)`` ``uint8``: u along x, v along y (paint it on a
            ``Canvas(xmax - xmin, ymax - ymin, ...)``).
        ceiling : numpy.ndarray
            Ceiling texture: u along y, v along x (see
            :func:`~vc_gym.sim.scenes.furniture.ceiling_texture`).
        """
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
