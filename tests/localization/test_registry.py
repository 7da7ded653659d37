"""make_tracker: names, dicts, callables, import paths and instances (the HighwayEnv way)."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from vc_gym.localization import (
    TRACKERS,
    GridTracker,
    KalmanTracker,
    ParticleTracker,
    TrackerState,
    make_tracker,
    register_tracker,
)


class StillTracker:
    """A user's tracker: always at home, facing east, not sure of anything."""

    def reset(self, atlas, camera, dt_s):
        self.n = len(atlas)

    def update(self, image, head_pan_deg, odometry):
        return TrackerState(
            heading_deg=0.0,
            heading_spread_deg=180.0,
            position=(0.0, 0.0),
            position_std_m=(10.0, 10.0),
            goodness=np.ones(self.n),
            belief=np.full(360, 1 / 360),
            atlas_position=(0.0, 0.0),
        )


@pytest.mark.parametrize(
    ("spec", "cls"),
    [
        (None, GridTracker),
        ("grid", GridTracker),
        ("particle", ParticleTracker),
        ("kalman", KalmanTracker),
        ({"type": "particle", "n_particles": 77}, ParticleTracker),
        (StillTracker, StillTracker),
        (functools.partial(GridTracker, half_life_s=1.0), GridTracker),
        (f"{__name__}:StillTracker", StillTracker),
    ],
)
def test_specs(spec, cls):
    assert type(make_tracker(spec)) is cls


def test_dict_kwargs_reach_the_constructor():
    assert make_tracker({"type": "particle", "n_particles": 77}).n_particles == 77
    assert make_tracker({"type": "grid", "half_life_s": 1.5}).half_life_s == 1.5


def test_an_instance_is_used_as_is():
    t = StillTracker()
    assert make_tracker(t) is t


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("kalmann", "known: \\['bearings', 'grid', 'kalman', 'particle'"),
        ({"n_particles": 5}, "'type'"),
        ({"type": "magic"}, "unknown tracker"),
        ({"type": "grid", "lambda": 0.2}, "bad arguments"),
        ({"type": "grid", "half_life_s": -1.0}, "half_life_s"),
        (lambda: "not a tracker", "has no reset"),
        ("tests.localization.nowhere:Tracker", "cannot import"),
        ("numpy:pi", "not callable"),
        (42, "name, a"),
    ],
)
def test_bad_specs_are_clear_errors(spec, match):
    with pytest.raises(ValueError, match=match):
        make_tracker(spec)


def test_register_tracker():
    register_tracker("still", StillTracker)
    try:
        assert type(make_tracker("still")) is StillTracker
        assert type(make_tracker({"type": "still"})) is StillTracker
        with pytest.raises(ValueError, match="registered already"):
            register_tracker("still", GridTracker)
        register_tracker("still", GridTracker, overwrite=True)
        assert type(make_tracker("still")) is GridTracker
        with pytest.raises(ValueError):
            register_tracker("", StillTracker)
        with pytest.raises(ValueError):
            register_tracker("x", "not callable")
    finally:
        TRACKERS.pop("still", None)


def test_a_spec_has_a_short_label_for_titles():
    from vc_gym.localization import GridTracker, tracker_label

    assert tracker_label("pose-grid") == "pose-grid"
    assert tracker_label({"type": "bearings", "search_every": 1}) == "bearings"
    assert tracker_label({"n_particles": 10}) == "custom"  # no type: not a name
    assert tracker_label(GridTracker) == "custom" and tracker_label(GridTracker()) == "custom"
