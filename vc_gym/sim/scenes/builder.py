"""The :class:`Builder`: creates a scene's bodies in a PyBullet client and records them.

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

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from vc_gym.sim.scenes.choices import Draw
from vc_gym.sim.scenes.parts import RGB, Part
from vc_gym.sim.textures import TextureStore

__all__ = ["Builder", "Quad"]

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
_OBSTACLE_BELOW = 0.35  # parts lower than this block the robot (m)

#: A quad ``(origin, du, dv, (u0, v0, u1, v1))``: see :meth:`Builder.mesh`.
Quad = tuple[Sequence[float], Sequence[float], Sequence[float], tuple[float, float, float, float]]


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
        Whether :attr:`choices` draws layout choices or returns the canonical ones.

    Attributes
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client. Pass nothing else as ``physicsClientId``: its methods add it.
    rng : numpy.random.Generator
        The scene's generator. Draw from it even in the canonical scene (which is built
        with a fixed seed), e.g. for texture noise, so that the canonical scene is varied
        but always the same.
    choices : Draw
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
        self.choices = Draw(rng, randomize)
        self.tex = TextureStore(bc)
        self.bodies: list[int] = []
        self.obstacles: list[tuple[float, float, float, float]] = []
        self.ceilings: list[int] = []

    @property
    def var(self) -> Draw:
        """Deprecated name of :attr:`choices`."""
        warnings.warn(
            "Builder.var is deprecated; use Builder.choices", DeprecationWarning, stacklevel=2
        )
        return self.choices

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
            :class:`vc_gym.worlds.canvas.Canvas`. Keep patterns coarse (at least 4-5 cm
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
            A body made by this builder (:meth:`vc_gym.sim.scenes.rooms.Room.build` calls
            this for its floor).
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
