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

import vc_gym.sim
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


def __getattr__(name: str) -> Any:
    # every public name of vc_gym.sim lived here before it moved: still served, for one
    # release, with a DeprecationWarning
    if name in vc_gym.sim.__all__:
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
