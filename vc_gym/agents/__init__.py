"""Agents: policies that act on what the robot knows (never on the true pose).

* :class:`ScriptedHomingPolicy` -- the paper's homing behaviour (section 5.2);
* :class:`HomingFeatureExpert` -- the same rule on ``vc_gym/Homing-v0``'s features and
  actions (the demonstrations a learned agent is warm-started from);
* :class:`~vc_gym.agents.learned.LearnedHomingAgent` -- a stable-baselines3 policy
  trained by ``vc-gym train`` (import it from :mod:`vc_gym.agents.learned`; it needs
  stable-baselines3).

The learning phase that comes before homing belongs to the task
(:mod:`vc_gym.envs.learning`), training to :mod:`vc_gym.experiments.training`.
"""

from vc_gym.agents.feature_expert import HomingFeatureExpert
from vc_gym.agents.scripted import ScriptedHomingPolicy

__all__ = ["HomingFeatureExpert", "ScriptedHomingPolicy"]
