"""Training homing policies with stable-baselines3 (``vc-gym train``).

Shaped like SB3's algorithms over ``common/``: :func:`train` (:mod:`.train`) fits PPO or
SAC on ``vc_gym/Homing-v0`` from a :class:`TrainConfig` (:mod:`.config`), on shared parts:

* :mod:`.environments` -- the envs a run trains on, one per place;
* :mod:`.run_folder` -- what a run's folder holds, its checkpoints, where a resume starts;
* :mod:`.callbacks` -- atomic checkpoints and the training log;
* :mod:`.async_rollouts` -- the collector that steps worker envs without lockstep;
* :mod:`.imitation` and :mod:`.feature_expert` -- the scripted rule as an expert on
  Homing-v0's features, and behaviour cloning from its demonstrations;
* :mod:`.home_offset` -- measuring where a policy stops, to correct its home;
* :mod:`.sweep` -- several training seeds as resumable jobs;
* :mod:`.safe_load` -- loading a ``model.zip`` without running code from it;
* :mod:`.algorithms` -- the algorithms by name.

Importing this package needs stable-baselines3 only when training starts.
"""

from vc_gym.training.algorithms import ALGORITHMS, algorithm_class
from vc_gym.training.feature_expert import HomingFeatureExpert
from vc_gym.training.safe_load import UnsafeModelError, load_sb3_model

__all__ = [
    "ALGORITHMS",
    "HomingFeatureExpert",
    "UnsafeModelError",
    "algorithm_class",
    "load_sb3_model",
]
