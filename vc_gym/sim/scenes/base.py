"""Deprecated: the scene toolkit now lives in one module per concept.

Import from :mod:`vc_gym.sim.scenes` (which exports every name below) or from the
modules themselves:

* :mod:`vc_gym.sim.scenes.scene`: :class:`Scene`, :class:`SceneLayout`;
* :mod:`vc_gym.sim.scenes.choices`: :class:`Draw` (layout choices);
* :mod:`vc_gym.sim.scenes.parts`: :class:`Part`, :func:`box`, :func:`cyl`, :func:`ball`,
  ``RGB``;
* :mod:`vc_gym.sim.scenes.builder`: :class:`Builder`, ``Quad``;
* :mod:`vc_gym.sim.scenes.rooms`: :class:`Room`, :class:`Wall`, ``WALL_PPM``,
  ``FLOOR_PPM``.

Reading any name from this module warns with a ``DeprecationWarning`` and returns the
same object.
"""

from __future__ import annotations

from vc_gym.deprecation import moved_names
from vc_gym.sim.scenes import builder, choices, parts, rooms, scene

_MOVED = {
    "Scene": scene,
    "SceneLayout": scene,
    "Draw": choices,
    "RGB": parts,
    "Part": parts,
    "ball": parts,
    "box": parts,
    "cyl": parts,
    "Builder": builder,
    "Quad": builder,
    "FLOOR_PPM": rooms,
    "WALL_PPM": rooms,
    "Room": rooms,
    "Wall": rooms,
}


__getattr__ = moved_names(__name__, _MOVED)
