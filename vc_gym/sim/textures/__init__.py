"""Textures for the simulated scenes: real photos, procedural pictures and painted surfaces.

* :mod:`~vc_gym.sim.textures.photos`: real photos and elevation maps from matplotlib's
  sample data, which vc_gym already depends on (:func:`sample_photo`, :func:`map_image`);
* :mod:`~vc_gym.sim.textures.painters`: procedural posters of several styles
  (:func:`procedural_poster`), window views, screens, advertising boards, facades and
  sky, painted from a numpy ``Generator``;
* :class:`Canvas` (from :mod:`vc_gym.worlds.canvas`) paints a flat surface measured in
  metres (a wall, a floor, a sky band) with doors, windows, framed pictures, boards...;
  the scene builder bakes whole walls into one texture, which renders much faster than
  one body per picture;
* :mod:`~vc_gym.sim.textures.store`: :class:`TextureStore` writes images as PNG files
  into a private temporary folder, loads each once into a PyBullet client
  (``loadTexture`` memory is freed only by ``resetSimulation``/``disconnect``), deletes
  each file right after loading and the folder when it is closed.

The colour helpers :func:`hsv`, :func:`random_color` and :func:`smooth_noise` of
:mod:`vc_gym.worlds.paint` are re-exported here for scene builders.

All images are ``(H, W, 3)`` ``uint8`` RGB arrays; row 0 is the top of the picture. All
randomness comes from the ``numpy.random.Generator`` passed in.
"""

from vc_gym.deprecation import moved_names
from vc_gym.sim.textures.painters import (
    POSTER_STYLES,
    ad_board,
    desktop_screen,
    facade,
    outdoor_view,
    poster_image,
    procedural_poster,
    sky_band,
    sky_cap,
)
from vc_gym.sim.textures.photos import (
    MAP_IMAGES,
    SAMPLE_PHOTOS,
    map_image,
    photo_posters,
    sample_photo,
)
from vc_gym.sim.textures.store import TEXTURE_DIR_PREFIX, TextureStore
from vc_gym.worlds import paint as _paint
from vc_gym.worlds.canvas import Canvas
from vc_gym.worlds.paint import hsv, random_color, smooth_noise

__all__ = [
    "Canvas",
    "MAP_IMAGES",
    "POSTER_STYLES",
    "SAMPLE_PHOTOS",
    "TextureStore",
    "ad_board",
    "desktop_screen",
    "facade",
    "hsv",
    "map_image",
    "outdoor_view",
    "photo_posters",
    "poster_image",
    "procedural_poster",
    "random_color",
    "sample_photo",
    "sky_band",
    "sky_cap",
    "smooth_noise",
    "TEXTURE_DIR_PREFIX",
]

# deprecated: random_colour, the British spelling of random_color, served for one release
__getattr__ = moved_names(__name__, {"random_colour": (_paint, "random_color")})
