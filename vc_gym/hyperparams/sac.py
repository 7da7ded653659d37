"""RL Baselines3 Zoo hyperparameters of SAC on vc_gym's envs (``-conf vc_gym.hyperparams.sac``)."""

from vc_gym.hyperparams import zoo_hyperparams

hyperparams = zoo_hyperparams("sac")
