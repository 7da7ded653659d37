"""Furniture primitives: a :class:`Part` is a box, cylinder or sphere in world coordinates.

Make parts with :func:`box`, :func:`cyl` and :func:`ball` (or against a wall with
:meth:`Room.box <vc_gym.sim.scenes.rooms.Room.box>` and its siblings) and build a piece
of furniture from them with :meth:`Builder.solid <vc_gym.sim.scenes.builder.Builder.solid>`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["RGB", "Part", "ball", "box", "cyl"]

#: A colour: three numbers 0..255 (red, green, blue).
RGB = Sequence[float]


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
