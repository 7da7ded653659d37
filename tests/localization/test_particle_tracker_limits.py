"""The particle tracker refuses arguments that would exhaust memory or overflow."""

from __future__ import annotations

import pytest

from vc_gym.filters.particle_filter import MAX_PARTICLES
from vc_gym.localization.particle_tracker import ParticleTracker


def test_a_billion_particles_is_a_value_error_at_construction():
    with pytest.raises(ValueError, match=r"n_particles must be an integer in \[1, 1_000_000\]"):
        ParticleTracker(n_particles=10**9)
    assert ParticleTracker(n_particles=MAX_PARTICLES).n_particles == MAX_PARTICLES


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"motion_noise": (1e308, 0.0, 0.0)}, "motion_noise must be within"),
        ({"motion_noise": (0.0, 0.0, 1e308)}, "motion_noise must be within"),
        ({"margin_m": 1e300}, r"margin_m must be at most 1e\+06 m"),
        ({"position_noise_m": 1e300}, r"position_noise_m must be at most 1e\+06 m"),
        ({"bounds": (-1e308, 1e308, -1.0, 1.0)}, "bounds must lie within"),
    ],
)
def test_lengths_beyond_range_are_value_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ParticleTracker(**kwargs)
