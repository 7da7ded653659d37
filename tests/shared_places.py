"""Places that several test modules learn alike, so that the run's place cache learns each
once (``tests/conftest.py``'s ``place_cache_dir``): a test that pins one of these learning
seeds with the same settings loads the place instead of learning it again."""

from __future__ import annotations

from gymnasium.utils import seeding


def drawn_learning_seed(reset_seed: int) -> int:
    """The learning seed a task env without ``learning_seed`` draws at
    ``reset(seed=reset_seed)`` (its first draw from the reset's generator)."""
    return int(seeding.np_random(reset_seed)[0].integers(2**31))


#: The ``pose-home`` place of robolab at ``learn_time_s=0.2``, learned by ``vc-gym demo
#: --seed 2 --mode pose-home`` (the episode tests), the pose-home env test and the
#: training speed benchmark's test.
POSE_HOME_SEED = drawn_learning_seed(2)
