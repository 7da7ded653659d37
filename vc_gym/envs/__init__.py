"""The tasks on the simulated world: learn a place, then walk home.

* :class:`LearnThenHomeEnv` (``vc_gym/LearnThenHome-v0``) -- the paper's task: a
  learning phase (a :class:`Learner` the task is given) and a homing phase;
* :class:`HomingEnv` (``vc_gym/Homing-v0``) -- the homing phase as a learned agent
  sees it: compass features in, (walk, turn, stop) out;
* :class:`PlaceCache` -- learned places kept on disk, shared by every env and run;
* :mod:`vc_gym.envs.wrappers` -- observation wrappers (:class:`CompassObservation`).

The world itself (robot, scenes, camera, ``vc_gym/AiboRoom-v0``) is :mod:`vc_gym.sim`.
"""


import vc_gym.sim
from vc_gym.deprecation import moved_names
from vc_gym.envs.homing import (
    HomingEnv,
    HomingFeatures,
    PreviousAction,
    StopAction,
    make_homing_env,
)
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
from vc_gym.envs.place_cache import PlaceCache
from vc_gym.envs.place_pool import PlacePool
from vc_gym.envs.wrappers import CompassObservation

# the public names of vc_gym.sim, served here for one release with a DeprecationWarning
__getattr__ = moved_names(__name__, dict.fromkeys(vc_gym.sim.__all__, vc_gym.sim))


__all__ = [
    "CompassObservation",
    "GridLearning",
    "HomingEnv",
    "HomingFeatures",
    "LEARNING_MODES",
    "LearnThenHomeEnv",
    "Learner",
    "LearningConfig",
    "LearningResult",
    "PlaceCache",
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
