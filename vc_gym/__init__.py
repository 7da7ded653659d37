"""vc_gym: the appearance-based visual compass of Sturm & Visser as a research tool.

Importing the package registers its Gymnasium environments (idempotently, without
importing PyBullet): ``gym.make("vc_gym/AiboRoom-v0")`` after ``import vc_gym``, or
``gym.make("vc_gym:vc_gym/AiboRoom-v0")`` from anywhere, including fresh subprocesses.
"""

from vc_gym.angles import circular_mean, circular_std, wrap180, wrap360

__version__ = "0.1.0"

#: Default seconds per control step of the simulated robot (``control_dt`` of
#: ``vc_gym/AiboRoom-v0`` and the tasks on it).
CONTROL_DT_S = 0.1
#: Default homing time limit of ``vc_gym/LearnThenHome-v0`` and ``vc_gym/Homing-v0``
#: (``max_homing_s``, seconds): an episode not ended by a stop or a fall is truncated then.
MAX_HOMING_S = 60.0
#: Default limit of the agent's own learning phase (``max_learning_s``, seconds,
#: ``learning="agent"``): the phase then ends as if the agent had finished it.
MAX_LEARNING_S = 300.0


def time_limit_steps(seconds: float, control_dt: float) -> int:
    """The step at which an env that advances ``control_dt`` per step reaches ``seconds``.

    The tasks count their own steps with this rule (``k * control_dt >= seconds``, with a
    tolerance of 1 ns for the rounding of the product), and the registered
    ``max_episode_steps`` is computed with it from the default limits, so that
    Gymnasium's ``TimeLimit`` and a task's own truncation fall on the same step.

    Parameters
    ----------
    seconds, control_dt : float
        Finite and positive.

    Returns
    -------
    int
        The smallest ``k >= 1`` with ``k * control_dt >= seconds - 1e-9``.
    """
    import math

    if (
        not (math.isfinite(seconds) and math.isfinite(control_dt))
        or seconds <= 0
        or control_dt <= 0
    ):
        raise ValueError(
            f"seconds and control_dt must be finite and positive, got {seconds!r}, {control_dt!r}"
        )
    k = max(1, math.ceil((seconds - 1e-9) / control_dt))
    while k > 1 and (k - 1) * control_dt >= seconds - 1e-9:
        k -= 1
    while k * control_dt < seconds - 1e-9:
        k += 1
    return k


#: Registered environment ids -> (entry point, max_episode_steps). The tasks truncate
#: themselves after ``max_homing_s`` of homing; their registered horizon is that limit's
#: step count at the default settings (one decision of ``vc_gym/Homing-v0`` takes at
#: least one step, so it cannot outlast it either).
ENV_SPECS = {
    "vc_gym/AiboRoom-v0": ("vc_gym.sim.aibo_room:AiboRoomEnv", 1000),
    # ends itself: stop, fall, or its own homing/learning time limits
    "vc_gym/LearnThenHome-v0": (
        "vc_gym.envs.learn_then_home:LearnThenHomeEnv",
        time_limit_steps(MAX_HOMING_S, CONTROL_DT_S),
    ),
    # the task as a learned agent sees it: compass features in, (walk, turn, stop) out
    "vc_gym/Homing-v0": (
        "vc_gym.envs.homing:HomingEnv",
        time_limit_steps(MAX_HOMING_S, CONTROL_DT_S),
    ),
}


def register_envs() -> None:
    """Register every vc_gym environment with Gymnasium (safe to call repeatedly)."""
    from gymnasium.envs.registration import register, registry

    for env_id, (entry_point, max_steps) in ENV_SPECS.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point, max_episode_steps=max_steps)


register_envs()

__all__ = [
    "CONTROL_DT_S",
    "ENV_SPECS",
    "MAX_HOMING_S",
    "MAX_LEARNING_S",
    "__version__",
    "circular_mean",
    "circular_std",
    "register_envs",
    "time_limit_steps",
    "wrap180",
    "wrap360",
]
