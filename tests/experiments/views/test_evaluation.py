"""What every tracker believes after a view's frames (paper 5.1) and how well each spot
fits them (eq. 28, fig. 5 right): right at the spot, pure, clear errors."""

from __future__ import annotations

import pytest

from vc_gym.experiments.views.evaluation import COMPASS, evaluate_view, spot_goodness
from vc_gym.experiments.views.frames import frames_at_pose
from vc_gym.localization import ParticleTracker

#: The training spot of the ``learned`` fixture (robolab's rear half centre, 5.1).
SPOT = (-1.5, 0.0)

TRACKERS = {"grid": "grid", "kalman": "kalman", "particle": {"type": "particle", "seed": 3}}


@pytest.mark.parametrize("yaw", [30.0, 245.0])
def test_every_tracker_is_right_at_the_spot(room, learned, yaw):
    atlas, camera = learned
    frames = frames_at_pose(room, (*SPOT, yaw), frames=10, seed=4)
    figures, timing = evaluate_view(frames, atlas, camera, room.control_dt, yaw, TRACKERS)
    assert set(figures) == set(timing) == {*TRACKERS, COMPASS}
    for name, fig in figures.items():
        assert set(fig) == {"heading_deg", "heading_error_deg", "heading_spread_deg"}
        assert all(type(v) is float for v in fig.values())
        assert abs(fig["heading_error_deg"]) < 10.0, (name, fig)
        assert fig["heading_deg"] == pytest.approx((yaw + fig["heading_error_deg"]) % 360)
        assert 0.0 <= fig["heading_spread_deg"] <= 180.0
        assert type(timing[name]) is float and timing[name] > 0.0


def test_evaluate_view_is_pure(room, learned):
    atlas, camera = learned
    frames = frames_at_pose(room, (-0.5, 0.5, 300.0), frames=5, seed=1)
    reused = ParticleTracker(n_particles=300, seed=5)
    trackers = {**TRACKERS, "reused": reused}
    a, _ = evaluate_view(frames, atlas, camera, room.control_dt, 300.0, trackers)
    b, _ = evaluate_view(frames, atlas, camera, room.control_dt, 300.0, trackers)
    assert a == b


def test_spot_goodness_is_one_at_the_spot_and_lower_far_away(room, learned):
    atlas, camera = learned
    near = spot_goodness(frames_at_pose(room, (*SPOT, 70.0), frames=4, seed=0), atlas, camera)
    far = spot_goodness(frames_at_pose(room, (2.0, 1.2, 70.0), frames=4, seed=0), atlas, camera)
    assert list(near) == ["spot"] and type(near["spot"]) is float
    assert near["spot"] == pytest.approx(1.0, abs=0.05)
    assert far["spot"] < near["spot"]


def test_bad_views(room, learned):
    atlas, camera = learned
    frames = frames_at_pose(room, (*SPOT, 0.0), frames=2, seed=0)
    dt = room.control_dt
    with pytest.raises(ValueError, match="reserved"):
        evaluate_view(frames, atlas, camera, dt, 0.0, {COMPASS: "grid"})
    with pytest.raises(ValueError, match="frames"):
        evaluate_view([], atlas, camera, dt, 0.0, TRACKERS)
    with pytest.raises(ValueError, match="unknown tracker"):
        evaluate_view(frames, atlas, camera, dt, 0.0, {"x": "no-such-tracker"})
    with pytest.raises(ValueError, match="true_heading_deg"):
        evaluate_view(frames, atlas, camera, dt, float("inf"), TRACKERS)
    with pytest.raises(ValueError, match="CompassAtlas"):
        spot_goodness(frames, "atlas", camera)
