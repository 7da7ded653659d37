"""Wrappers of the tasks: what an agent observes of them."""

from vc_gym.envs.wrappers.compass_observation import CompassObservation

__all__ = ["CompassObservation"]
