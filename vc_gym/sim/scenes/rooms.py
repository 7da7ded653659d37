"""Rectangular rooms: a :class:`Room` of four painted :class:`Wall` canvases, floor and ceiling.

Lay out the room, paint its walls (doors, windows, pictures: see
:mod:`vc_gym.sim.scenes.furniture`) and furnish it, then :meth:`Room.build` creates each
wall as one textured quad, with the floor and the ceiling.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vc_gym.sim.scenes.builder import Builder, Quad
from vc_gym.sim.scenes.parts import RGB, Part, ball, box, cyl
from vc_gym.worlds.canvas import Canvas

__all__ = ["FLOOR_PPM", "WALL_PPM", "Room", "Wall"]

#: Texture resolution of the walls a :class:`Room` paints (pixels per metre).
WALL_PPM = 128.0
#: Texture resolution the built-in scenes use for their floors (pixels per metre).
FLOOR_PPM = 100.0
_WALL_T = 0.2  # collision thickness of walls (m)


@dataclass
class Wall:
    """One wall seen from inside: ``u`` runs left to right along it, ``z`` up.

    Paint on :attr:`canvas` (a :class:`vc_gym.worlds.canvas.Canvas` measured in metres,
    ``(u, z)`` with ``z`` up); record painted or furnished areas with :meth:`take` so that
    later pictures (:func:`~vc_gym.sim.scenes.furniture.hang_pictures`) avoid them.

    Attributes
    ----------
    side : str
        ``"E"``, ``"N"``, ``"W"`` or ``"S"``: the wall at ``x = xmax``, ``y = ymax``,
        ``x = xmin``, ``y = ymin``.
    length, height : float
        Size (m).
    canvas : vc_gym.worlds.canvas.Canvas
        The wall's texture.
    busy : list of tuple of float
        Taken areas ``(u0, u1, z0, z1)``.
    """

    side: str
    length: float
    height: float
    canvas: Canvas
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
            canvas = Canvas(length, height, WALL_PPM, wall_rgb[side])
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
