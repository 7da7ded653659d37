"""vc_gym: the appearance-based visual compass of Sturm & Visser as a research tool."""

from vc_gym.angles import circular_mean, circular_std, wrap180, wrap360

__version__ = "0.1.0"

__all__ = ["__version__", "wrap180", "wrap360", "circular_mean", "circular_std"]
