"""What the robot knows: trackers that fuse the compass and odometry into a pose belief.

This layer joins the two below it: the compass (:mod:`vc_gym.compass`) and the
filters (:mod:`vc_gym.filters`) never import each other; the adapters
(:class:`CompassHeadingSensor`, :class:`AtlasPoseSensor`) and the trackers live here.

Every tracker satisfies :class:`Tracker`: ``reset(atlas, camera, dt_s)`` and
``update(image, head_pan_deg, odometry) -> TrackerState``.

* :class:`GridTracker` -- the paper's heading grid filter (eq. 23-27) and
  translational filter (eq. 30-32);
* :class:`ParticleTracker` -- particles over ``(x, y, θ)`` weighted by the atlas and
  the compass, with injection so a kidnapping is recovered;
* :class:`KalmanTracker` -- an unscented Kalman heading filter and the translational
  filter;
* :class:`PoseTracker` -- a pose belief over the whole field: particles weighed by every
  spot's map re-drawn for their position, sensor resetting when the belief is lost;
* :class:`HomeSwitchTracker` -- the pose tracker's state away from home, the grid
  tracker's near it (``"pose-grid"``);
* :class:`BearingTracker` -- the pose tracker's particles weighed also by the bearings
  of the atlas' landmarks (``"bearings"``).

Each takes ``shortlist=k`` to score only the ``k`` best-fitting spots between full
scorings (:class:`SpotShortlist`): an atlas with many spots then costs about ``k``
maps a frame.

:func:`make_tracker` builds one from a name, a ``{"type": name, **kwargs}`` dict or a
callable; :func:`register_tracker` adds a name.

Position over the whole field from maps on a grid of spots, beyond eq. 30 (which answers
only inside the spots' hull), from the spots' score vectors (:func:`mean_spot_scores`):

* :func:`locate_by_goodness` -- one view: a likelihood calibrated on goodness against
  distance (:func:`calibrate_goodness` on frames at :func:`calibration_points`);
* :func:`locate_by_turn_signature` -- a full turn: the calibration places whose
  turn-averaged scores are nearest.

>>> from vc_gym.localization import make_tracker          # doctest: +SKIP
>>> tracker = make_tracker({"type": "particle", "n_particles": 2000})   # doctest: +SKIP
>>> tracker.reset(atlas, camera, dt_s=0.1)                 # doctest: +SKIP
>>> state = tracker.update(image, head_pan_deg=20.0, odometry=(0.02, 0.0, 1.5))  # doctest: +SKIP
"""

from vc_gym.localization.bearing_tracker import BearingTracker
from vc_gym.localization.compass_sensors import (
    AtlasPoseSensor,
    CompassHeadingSensor,
    best_spot_heading_log_likelihood,
)
from vc_gym.localization.goodness_calibration import (
    GoodnessCalibration,
    calibrate_goodness,
    calibration_points,
    goodness_log_likelihood,
    locate_by_goodness,
)
from vc_gym.localization.grid_tracker import GridTracker
from vc_gym.localization.home_switch_tracker import HomeSwitchTracker
from vc_gym.localization.kalman_tracker import KalmanTracker
from vc_gym.localization.particle_tracker import ParticleTracker
from vc_gym.localization.pose_tracker import PoseTracker
from vc_gym.localization.position import AtlasPositionFilter
from vc_gym.localization.registry import (
    TRACKERS,
    TrackerSpec,
    make_tracker,
    register_tracker,
    tracker_label,
)
from vc_gym.localization.shortlist import SpotShortlist
from vc_gym.localization.spot_scores import mean_spot_scores
from vc_gym.localization.tracker_protocol import Tracker, TrackerState
from vc_gym.localization.turn_signature import locate_by_turn_signature

__all__ = [
    "TRACKERS",
    "AtlasPoseSensor",
    "AtlasPositionFilter",
    "BearingTracker",
    "CompassHeadingSensor",
    "GoodnessCalibration",
    "GridTracker",
    "HomeSwitchTracker",
    "KalmanTracker",
    "ParticleTracker",
    "PoseTracker",
    "SpotShortlist",
    "Tracker",
    "TrackerSpec",
    "TrackerState",
    "best_spot_heading_log_likelihood",
    "calibrate_goodness",
    "calibration_points",
    "goodness_log_likelihood",
    "locate_by_goodness",
    "locate_by_turn_signature",
    "make_tracker",
    "mean_spot_scores",
    "register_tracker",
    "tracker_label",
]
