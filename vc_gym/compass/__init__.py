"""The visual compass of Sturm & Visser (paper sections 3.1-3.4 and 3.6.1).

Pure numpy + OpenCV: it knows nothing of the simulator and works on any camera image.

>>> from vc_gym.compass import Camera, CompassConfig, VisualCompass   # doctest: +SKIP
>>> vc = VisualCompass(CompassConfig(n_colors=10, sector_deg=4.5))     # doctest: +SKIP
>>> vc.fit_colors(images); vc.learn(image, Camera(yaw_deg=90.0))        # doctest: +SKIP
>>> vc.estimate(new_image, Camera()).heading_deg                        # doctest: +SKIP
"""

from vc_gym.angles import circular_mean, circular_std, wrap180, wrap360
from vc_gym.compass.atlas import AtlasEstimate, CompassAtlas
from vc_gym.compass.camera import AIBO_HFOV_DEG, AIBO_RESOLUTION, Camera
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.features import log2_bin
from vc_gym.compass.parallax import ParallaxMap, learn_depths
from vc_gym.compass.protocol import ImageCompass
from vc_gym.compass.visual_compass import CompassEstimate, VisualCompass
from vc_gym.errors import MapFileError, NotLearnedError

__all__ = [
    "AIBO_HFOV_DEG",
    "AIBO_RESOLUTION",
    "AtlasEstimate",
    "Camera",
    "ColorClasses",
    "CompassAtlas",
    "CompassConfig",
    "CompassEstimate",
    "ImageCompass",
    "MapFileError",
    "NotLearnedError",
    "ParallaxMap",
    "VisualCompass",
    "circular_mean",
    "circular_std",
    "learn_depths",
    "log2_bin",
    "wrap180",
    "wrap360",
]
