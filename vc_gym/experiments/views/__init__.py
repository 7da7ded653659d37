"""Views from poses on the field: the core of the orientation experiment (paper 5.1, fig. 4).

The paper's robot learned the panorama at a single spot (the centre of the rear field
half) and was then moved by hand over a 3 × 3 m grid at about 33 cm resolution; at
every grid point its heading estimate was recorded (fig. 4 left: the estimates point
to one place on the far wall; fig. 4 right: the mean error exceeds 10° only beyond
2 m from the training spot, where the mean spread reaches about 50°). Figure 5 (right)
shows, on a 50 cm grid, the goodness ``L_i`` (eq. 28) of one spot's map.

The pieces an experiment runner combines into jobs, each pure per call (its result
depends on its arguments, seeds included, never on what the same process computed
before), one concept a module:

* :mod:`~.poses` -- :func:`field_grid` and :func:`view_poses`: where the robot is put;
* :mod:`~.frames` -- :func:`frames_at_pose`: reset an :class:`~vc_gym.sim.aibo_room.AiboRoomEnv`
  at a pose and let the robot stand there, scanning with its head, for some frames;
  :func:`learning_turn`: a full turn's frames with their true camera yaws;
* :mod:`~.evaluation` -- :func:`evaluate_view`: feed the frames to every tracker and
  record what each believed (and the single-frame compass); :func:`spot_goodness`: the
  mean normalised goodness ``L̂_i`` of every spot;
* :mod:`~.error_vs_distance` -- :func:`distance_table` and
  :func:`plot_error_vs_distance`: errors and spreads per distance from the training
  spot (fig. 4 right);
* :mod:`~.arrow_field` -- :func:`plot_arrow_field` (fig. 4 left);
* :mod:`~.goodness_field` -- :func:`plot_goodness_field` (fig. 5 right).

Typical use (one spot learned with :class:`~vc_gym.envs.learning.SpotLearning`)::

    room.reset(seed=0)
    atlas = SpotLearning((-1.5, 0.0))(room, LearningConfig()).atlas
    for i, pose in enumerate(view_poses(field_grid(bounds, 0.33), 1, rng)):
        frames = frames_at_pose(room, pose, frames=15, seed=i)
        figures, timing = evaluate_view(frames, atlas, camera, room.control_dt,
                                        pose[2], {"grid": "grid"})
"""

from vc_gym.deprecation import moved_names
from vc_gym.experiments.views import frames
from vc_gym.experiments.views.arrow_field import plot_arrow_field
from vc_gym.experiments.views.checks import spots_array
from vc_gym.experiments.views.error_vs_distance import (
    PAPER_ERROR_DEG,
    PAPER_RANGE_M,
    distance_table,
    plot_error_vs_distance,
)
from vc_gym.experiments.views.evaluation import COMPASS, evaluate_view, spot_goodness
from vc_gym.experiments.views.frames import Frame, frames_at_pose, learning_turn
from vc_gym.experiments.views.goodness_field import plot_goodness_field
from vc_gym.experiments.views.poses import field_grid, view_poses

__all__ = [
    "COMPASS",
    "PAPER_ERROR_DEG",
    "PAPER_RANGE_M",
    "Frame",
    "distance_table",
    "evaluate_view",
    "field_grid",
    "learning_turn",
    "frames_at_pose",
    "plot_arrow_field",
    "plot_error_vs_distance",
    "plot_goodness_field",
    "spot_goodness",
    "spots_array",
    "view_poses",
]

__getattr__ = moved_names(__name__, {"look": (frames, "frames_at_pose")})
