"""The PyBullet world: the quadruped and its gait, the head camera, scenes, textures.

:class:`AiboRoomEnv` (``vc_gym/AiboRoom-v0``) exposes the raw world through Gymnasium:
the robot in a scene, driven by walk and head commands. The tasks built on it
(:mod:`vc_gym.envs`) use the same parts. Importing this package imports PyBullet;
``import vc_gym`` alone registers the envs without it.
"""

from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.head_camera import HeadCameraSpec, render_camera
from vc_gym.sim.odometry import OdometryNoise
from vc_gym.sim.robot import LOCOMOTION_MODES, Quadruped
from vc_gym.sim.scenes import (
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
    "HeadCameraSpec",
    "OdometryNoise",
    "Quadruped",
    "Scene",
    "build_scene",
    "register_scene",
    "render_camera",
    "scene_names",
    "unregister_scene",
]
