"""vc_gym: the appearance-based visual compass of Sturm & Visser as a research tool.

Importing the package registers its Gymnasium environments (idempotently, without
importing PyBullet): ``gym.make("vc_gym/AiboRoom-v0")`` after ``import vc_gym``, or
``gym.make("vc_gym:vc_gym/AiboRoom-v0")`` from anywhere, including fresh subprocesses.
"""

from vc_gym.angles import circular_mean, circular_std, wrap180, wrap360

__version__ = "0.1.0"

#: Registered environment ids -> (entry point, max_episode_steps).
ENV_SPECS = {
    "vc_gym/AiboRoom-v0": ("vc_gym.sim.aibo_room:AiboRoomEnv", 1000),
    # ends itself: stop, fall, or its own homing/learning time limits
    "vc_gym/LearnThenHome-v0": ("vc_gym.envs.learn_then_home:LearnThenHomeEnv", None),
    # the task as a learned agent sees it: compass features in, (walk, turn, stop) out
    "vc_gym/Homing-v0": ("vc_gym.envs.homing:make_homing_env", None),
}


def register_envs() -> None:
    """Register every vc_gym environment with Gymnasium (safe to call repeatedly)."""
    from gymnasium.envs.registration import register, registry

    for env_id, (entry_point, max_steps) in ENV_SPECS.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point, max_episode_steps=max_steps)


register_envs()

__all__ = [
    "ENV_SPECS",
    "__version__",
    "circular_mean",
    "circular_std",
    "register_envs",
    "wrap180",
    "wrap360",
]
