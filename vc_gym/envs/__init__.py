"""The simulated world: PyBullet scenes, the quadruped, its head camera, Gymnasium envs.

Importing this package imports PyBullet; ``import vc_gym`` alone registers the envs
without it.
"""

from vc_gym.envs.aibo_room import AiboRoomEnv
from vc_gym.envs.compass_observation import CompassObservation
from vc_gym.envs.head_camera import HeadCameraSpec, render_camera
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
from vc_gym.envs.robot import LOCOMOTION_MODES, OdometryNoise, Quadruped
from vc_gym.envs.scenes import (
    SCENES,
    Scene,
    build_scene,
    register_scene,
    scene_names,
    unregister_scene,
)

__all__ = [
    "LOCOMOTION_MODES",
    "SCENES",
    "AiboRoomEnv",
    "CompassObservation",
    "GridLearning",
    "HeadCameraSpec",
    "HomingFeatures",
    "PreviousAction",
    "LEARNING_MODES",
    "LearnThenHomeEnv",
    "Learner",
    "LearningConfig",
    "LearningResult",
    "OdometryNoise",
    "PlacePool",
    "Quadruped",
    "RobotFell",
    "Scene",
    "ScriptedLearner",
    "ScriptedLearning",
    "SpotLearning",
    "StopAction",
    "build_scene",
    "kidnap_pose",
    "make_homing_env",
    "register_scene",
    "render_camera",
    "scene_names",
    "unregister_scene",
]
