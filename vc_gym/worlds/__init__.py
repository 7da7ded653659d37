"""Simulated worlds without a physics engine: seeded panoramas and a ray-cast room.

The compass is tested, demonstrated and benchmarked on camera views whose true pose is
known. This package makes them with numpy and OpenCV only (no PyBullet):

* :mod:`vc_gym.worlds.panorama`: 360° panoramas (:class:`Panorama`), real
  equirectangular photos (:func:`equirectangular`) and the pinhole view a
  :class:`~vc_gym.compass.Camera` sees in them (:func:`render_view`): rotation only, the
  scene is at infinity;
* :mod:`vc_gym.worlds.panorama_painters`: procedural, seamless 360° panoramas
  (:func:`make_panorama`);
* :mod:`vc_gym.worlds.room`: a procedural rectangular robot lab (:func:`make_room`)
  and a 2.5-D ray caster that renders it from any position (:func:`render_room_view`):
  translation too, with parallax;
* :mod:`vc_gym.worlds.rays`: the per-pixel camera rays both renderers cast
  (:func:`ray_grid`, docs/design.md's pinhole convention);
* :mod:`vc_gym.worlds.canvas`: :class:`~vc_gym.worlds.canvas.Canvas`, the one painting
  surface of the panoramas and of the PyBullet scene textures (:mod:`vc_gym.sim.textures`);
* :mod:`vc_gym.worlds.paint`: the colour and noise helpers every painter uses.

Every scene depends only on the ``numpy.random.Generator`` passed in.

>>> import numpy as np                                                   # doctest: +SKIP
>>> from vc_gym.compass import Camera                                    # doctest: +SKIP
>>> from vc_gym.worlds import make_panorama, render_view                  # doctest: +SKIP
>>> pano = make_panorama(np.random.default_rng(0))                       # doctest: +SKIP
>>> image = render_view(pano, Camera(yaw_deg=90.0))                      # doctest: +SKIP

Layering: worlds may use the compass (its :class:`~vc_gym.compass.Camera`), never the
envs; the compass never imports worlds.
"""

from vc_gym.worlds.panorama import Panorama, equirectangular, render_view
from vc_gym.worlds.panorama_painters import PANORAMA_KINDS, make_panorama
from vc_gym.worlds.rays import RayGrid, ray_grid
from vc_gym.worlds.room import FLOOR_TILE_M, Room, make_room, render_room_view

__all__ = [
    "FLOOR_TILE_M",
    "PANORAMA_KINDS",
    "Panorama",
    "RayGrid",
    "Room",
    "equirectangular",
    "make_panorama",
    "make_room",
    "ray_grid",
    "render_room_view",
    "render_view",
]
