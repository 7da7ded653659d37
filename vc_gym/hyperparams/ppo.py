"""RL Baselines3 Zoo hyperparameters of PPO on vc_gym's envs (``-conf vc_gym.hyperparams.ppo``)."""

from vc_gym.hyperparams import zoo_hyperparams

hyperparams = zoo_hyperparams("ppo")
