"""Agents: policies that act on what the robot knows (never on the true pose).

* :class:`ScriptedHomingPolicy` -- the paper's homing behaviour (section 5.2), and
  :class:`ScriptedHomingAgent`, which names the env it acts in and gives that policy;
* :class:`~vc_gym.agents.learned.LearnedHomingAgent` -- a stable-baselines3 policy
  trained by ``vc-gym train`` (import it from :mod:`vc_gym.agents.learned`; it needs
  stable-baselines3);
* :class:`HomingFeatureExpert` -- the scripted rule on ``vc_gym/Homing-v0``'s features
  and actions, the expert training imitates (it lives in :mod:`vc_gym.training`).

An agent is given the env it acts in: it names that env (``env_id``, ``env_kwargs``,
``observation``) and its ``policy(env)`` acts there; who runs it builds the env
(:func:`vc_gym.experiments.episode.make_agent_env`). The learning phase that comes before homing
belongs to the task (:mod:`vc_gym.envs.learning`), training to :mod:`vc_gym.training`.
"""

from vc_gym.agents.scripted import ScriptedHomingAgent, ScriptedHomingPolicy
from vc_gym.training.feature_expert import HomingFeatureExpert

__all__ = ["HomingFeatureExpert", "ScriptedHomingAgent", "ScriptedHomingPolicy"]
