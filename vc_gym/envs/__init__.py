"""The tasks on the simulated world: learn a place, then walk home.

* :class:`LearnThenHomeEnv` (``vc_gym/LearnThenHome-v0``) -- the paper's task: a
  learning phase (a :class:`Learner` the task is given) and a homing phase;
* ``vc_gym/Homing-v0`` (:func:`make_homing_env`) -- the homing phase as a learned agent
  sees it: compass features in, (walk, turn, stop) out;
* :mod:`vc_gym.envs.wrappers` -- observation wrappers (:class:`CompassObservation`).

The world itself (robot, scenes, camera, ``vc_gym/AiboRoom-v0``) is :mod:`vc_gym.sim`.
"""

import warnings
from typing import Any

from vc_gym.envs.homing import HomingFeatures, PreviousAction, StopAction, make_homing_env
from vc_gym.envs.learn_then_home import LEARNING_MODES, LearnThenHomeEnv
from vc_gym.envs.learning import (
    GridLearning,
    Learner,
    LearningConfig,
    LearningResult,
    RobotFell,
    ScriptedLearner,
    ScriptedLearning,
    SpotLearning,
    kidnap_pose,
)
from vc_gym.envs.place_pool import PlacePool
from vc_gym.envs.wrappers import CompassObservation

#: Names that moved to :mod:`vc_gym.sim`; importing them from here still works, with a
#: DeprecationWarning, for one release.
_MOVED_TO_SIM = {
    "LOCOMOTION_MODES",
    "SCENES",
    "AiboRoomEnv",
    "HeadCameraSpec",
    "OdometryNoise",
    "Quadruped",
    "Scene",
    "build_scene",
    "register_scene",
    "render_camera",
    "scene_names",
    "unregister_scene",
}


def __getattr__(name: str) -> Any:
    if name in _MOVED_TO_SIM:
        import vc_gym.sim

        warnings.warn(
            f"vc_gym.envs.{name} moved to vc_gym.sim.{name}", DeprecationWarning, stacklevel=2
        )
        return getattr(vc_gym.sim, name)
    raise AttributeError(f"module 'vc_gym.envs' has no attribute {name!r}")


__all__ = [
    "CompassObservation",
    "GridLearning",
    "HomingFeatures",
    "LEARNING_MODES",
    "LearnThenHomeEnv",
    "Learner",
    "LearningConfig",
    "LearningResult",
    "PlacePool",
    "PreviousAction",
    "RobotFell",
    "ScriptedLearner",
    "ScriptedLearning",
    "SpotLearning",
    "StopAction",
    "kidnap_pose",
    "make_homing_env",
]
