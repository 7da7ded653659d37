"""Views from poses on the field (paper 5.1, fig. 4 and 5 right): known answers, purity."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera
from vc_gym.envs import LearningConfig, SpotLearning
from vc_gym.experiments.views import (
    COMPASS,
    distance_table,
    evaluate_view,
    field_grid,
    look,
    plot_arrow_field,
    plot_error_vs_distance,
    plot_goodness_field,
    spot_goodness,
    view_poses,
)
from vc_gym.localization import ParticleTracker
from vc_gym.sim import AiboRoomEnv

#: robolab's field and the centre of its rear half (the paper's training spot, 5.1)
FIELD = (-3.0, 3.0, -2.0, 2.0)
SPOT = (-1.5, 0.0)
TRACKERS = {"grid": "grid", "kalman": "kalman", "particle": {"type": "particle", "seed": 3}}


@pytest.fixture(scope="module")
def room():
    env = AiboRoomEnv()
    try:
        yield env
    finally:
        env.close()


@pytest.fixture(scope="module")
def learned(room):
    room.reset(seed=0)
    config = LearningConfig(learn_time_s=0.5, normalise_directions=6)
    atlas = SpotLearning(SPOT)(room, config).atlas
    return atlas, Camera(hfov_deg=room.camera.hfov_deg)


# ---------------------------------------------------------------------- the simulator
@pytest.mark.parametrize("yaw", [30.0, 245.0])
def test_every_tracker_is_right_at_the_spot(room, learned, yaw):
    atlas, camera = learned
    frames = look(room, (*SPOT, yaw), frames=10, seed=4)
    figures, timing = evaluate_view(frames, atlas, camera, room.control_dt, yaw, TRACKERS)
    assert set(figures) == set(timing) == {*TRACKERS, COMPASS}
    for name, fig in figures.items():
        assert set(fig) == {"heading_deg", "heading_error_deg", "heading_spread_deg"}
        assert all(type(v) is float for v in fig.values())
        assert abs(fig["heading_error_deg"]) < 10.0, (name, fig)
        assert fig["heading_deg"] == pytest.approx((yaw + fig["heading_error_deg"]) % 360)
        assert 0.0 <= fig["heading_spread_deg"] <= 180.0
        assert type(timing[name]) is float and timing[name] > 0.0


def test_look_is_history_independent(room):
    pose = (0.4, -0.7, 123.0)
    first = look(room, pose, frames=4, seed=11)
    look(room, (2.0, 1.0, 10.0), frames=3, seed=2)  # something else in between
    again = look(room, pose, frames=4, seed=11)
    fresh_env = AiboRoomEnv()
    try:
        fresh = look(fresh_env, pose, frames=4, seed=11)
    finally:
        fresh_env.close()
    for other in (again, fresh):
        assert len(other) == len(first) == 4
        for (im_a, pan_a, odo_a), (im_b, pan_b, odo_b) in zip(first, other, strict=True):
            assert im_a.tobytes() == im_b.tobytes()
            assert (pan_a, odo_a) == (pan_b, odo_b)
    image, pan, odo = first[0]
    assert image.dtype == np.uint8 and image.shape == (160, 208, 3)
    assert pan == 0.0 and odo == (0.0, 0.0, 0.0)
    # the default scan: 0 -> -20 -> 0 -> 20 (the head moves at a bounded speed)
    pans = [f[1] for f in first]
    assert pans[1] < -10.0 and abs(pans[2]) < 5.0 and pans[3] > 10.0
    assert all(type(v) is float for f in first for v in f[2])


def test_evaluate_view_is_pure(room, learned):
    atlas, camera = learned
    frames = look(room, (-0.5, 0.5, 300.0), frames=5, seed=1)
    reused = ParticleTracker(n_particles=300, seed=5)
    trackers = {**TRACKERS, "reused": reused}
    a, _ = evaluate_view(frames, atlas, camera, room.control_dt, 300.0, trackers)
    b, _ = evaluate_view(frames, atlas, camera, room.control_dt, 300.0, trackers)
    assert a == b


def test_spot_goodness_is_one_at_the_spot_and_lower_far_away(room, learned):
    atlas, camera = learned
    near = spot_goodness(look(room, (*SPOT, 70.0), frames=4, seed=0), atlas, camera)
    far = spot_goodness(look(room, (2.0, 1.2, 70.0), frames=4, seed=0), atlas, camera)
    assert list(near) == ["spot"] and type(near["spot"]) is float
    assert near["spot"] == pytest.approx(1.0, abs=0.05)
    assert far["spot"] < near["spot"]


def test_bad_looks_and_views(room, learned):
    atlas, camera = learned
    with pytest.raises(ValueError, match="AiboRoomEnv"):
        look(object(), (0.0, 0.0, 0.0), 2, seed=0)
    for kwargs, match in [
        ({"pose": (0.0, float("nan"), 0.0)}, "pose"),
        ({"pose": (0.0, 0.0)}, "pose"),
        ({"frames": 0}, "frames"),
        ({"seed": -1}, "seed"),
        ({"seed": 1.5}, "seed"),
        ({"head_scan_deg": (100.0,)}, "head_scan_deg"),
        ({"head_scan_deg": ()}, "head_scan_deg"),
    ]:
        args = {"pose": (0.0, 0.0, 0.0), "frames": 2, "seed": 0, **kwargs}
        with pytest.raises(ValueError, match=match):
            look(room, **args)
    frames = look(room, (*SPOT, 0.0), frames=2, seed=0)
    dt = room.control_dt
    with pytest.raises(ValueError, match="reserved"):
        evaluate_view(frames, atlas, camera, dt, 0.0, {COMPASS: "grid"})
    with pytest.raises(ValueError, match="frames"):
        evaluate_view([], atlas, camera, dt, 0.0, TRACKERS)
    with pytest.raises(ValueError, match="unknown tracker"):
        evaluate_view(frames, atlas, camera, dt, 0.0, {"x": "no-such-tracker"})
    with pytest.raises(ValueError, match="true_heading_deg"):
        evaluate_view(frames, atlas, camera, dt, float("inf"), TRACKERS)


# ---------------------------------------------------------------------- poses
def test_field_grid_known_answers():
    g = field_grid(FIELD, 0.5)  # 0.25 margin: 5.5 x 3.5 m at 0.5 m
    assert g.shape == (12 * 8, 2) and g.dtype == np.float64
    assert g[0].tolist() == [-2.75, -1.75] and g[-1].tolist() == [2.75, 1.75]
    assert g[1].tolist() == [-2.75, -1.25]  # ordered by x, then y
    # spare length split evenly: 1 m at 0.4 m -> 0.1, 0.5, 0.9
    np.testing.assert_allclose(np.unique(field_grid((0, 1, 0, 1), 0.4, 0.0)[:, 0]), [0.1, 0.5, 0.9])
    one = field_grid((0.0, 1.0, 0.0, 2.0), 0.3, margin_m=0.5)  # x extent exactly used up
    np.testing.assert_allclose(np.unique(one[:, 0]), [0.5])
    paper = field_grid((-3.0, 0.0, -1.5, 1.5), 0.33, 0.0)  # 3 x 3 m at ~33 cm (5.1)
    assert paper.shape == (10 * 10, 2)


@pytest.mark.parametrize(
    "args, match",
    [
        (((0, 1, 0), 0.5), "bounds"),
        (((1, 0, 0, 1), 0.5), "xmin < xmax"),
        (((0, 1, 0, float("nan")), 0.5), "finite"),
        (("abcd", 0.5), "bounds"),
        (((0, 1, 0, 1), 0.0), "spacing_m"),
        (((0, 1, 0, 1), float("inf")), "spacing_m"),
        (((0, 1, 0, 1), 0.5, -0.1), "margin_m"),
        (((0, 1, 0, 1), 0.5, 0.6), "margin_m"),
        (((0, 6, 0, 4), 1e-5), "too many"),
    ],
)
def test_field_grid_rejects_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        field_grid(*args)


def test_view_poses():
    positions = field_grid(FIELD, 1.0)
    poses = view_poses(positions, 3, np.random.default_rng(0))
    assert poses.shape == (3 * len(positions), 3)
    np.testing.assert_array_equal(poses[:, :2], np.repeat(positions, 3, axis=0))
    assert poses[:, 2].min() >= 0.0 and poses[:, 2].max() < 360.0
    assert len(np.unique(poses[:, 2])) == len(poses)
    np.testing.assert_array_equal(poses, view_poses(positions, 3, np.random.default_rng(0)))
    for bad, match in [
        (([[0.0, 0.0, 0.0]], 1, np.random.default_rng(0)), "shape"),
        (([[0.0, float("nan")]], 1, np.random.default_rng(0)), "finite"),
        (([[0.0, 0.0]], 0, np.random.default_rng(0)), "headings_per_position"),
        (([[0.0, 0.0]], 1.5, np.random.default_rng(0)), "headings_per_position"),
        (([[0.0, 0.0]], 1, 0), "Generator"),
    ]:
        with pytest.raises(ValueError, match=match):
            view_poses(*bad)


# ---------------------------------------------------------------------- tables and plots
def test_distance_table_known_answer():
    rows = distance_table(
        [0.1, 0.3, 0.6, 2.2, 2.4],
        [1.0, -3.0, 350.0, 20.0, -40.0],  # 350° is a -10° error
        [2.0, 4.0, 6.0, 8.0, 10.0],
        bin_m=0.5,
    )
    assert [(r["bin_start_m"], r["bin_end_m"], r["n"]) for r in rows] == [
        (0.0, 0.5, 2),
        (0.5, 1.0, 1),
        (2.0, 2.5, 2),
    ]
    assert [r["mean_abs_error_deg"] for r in rows] == pytest.approx([2.0, 10.0, 30.0])
    assert [r["median_abs_error_deg"] for r in rows] == pytest.approx([2.0, 10.0, 30.0])
    assert [r["mean_spread_deg"] for r in rows] == pytest.approx([3.0, 6.0, 9.0])
    assert [r["distance_m"] for r in rows] == pytest.approx([0.2, 0.6, 2.3])
    assert distance_table([], [], []) == []
    for bad, match in [
        (([0.1, 0.2], [1.0], [1.0, 1.0]), "one length"),
        (([-0.1], [1.0], [1.0]), ">= 0"),
        (([0.1], [float("nan")], [1.0]), "errors"),
        (([0.1], [1.0], [1.0], 0.0), "bin_m"),
    ]:
        with pytest.raises(ValueError, match=match):
            distance_table(*bad)


def _is_png(path) -> bool:
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plots_write_pngs(tmp_path):
    rng = np.random.default_rng(1)
    poses = view_poses(field_grid(FIELD, 0.66), 1, rng)
    dist = np.hypot(poses[:, 0] - SPOT[0], poses[:, 1] - SPOT[1])
    errors = rng.normal(0.0, 2.0 + 8.0 * dist)
    estimated = poses[:, 2] + errors
    table = distance_table(dist, errors, 5.0 + 20.0 * dist)
    plot_error_vs_distance(tmp_path / "err.png", {"grid": table, "kalman": table[:-1]})
    plot_arrow_field(tmp_path / "arrows.png", poses, estimated, SPOT, FIELD, "fig. 4 left")
    plot_arrow_field(tmp_path / "ref.png", poses, estimated, SPOT, FIELD, "ref", reference_deg=0)
    grid = field_grid(FIELD, 0.5)
    goodness = np.exp(-0.05 * np.hypot(grid[:, 0] - SPOT[0], grid[:, 1] - SPOT[1]))
    plot_goodness_field(tmp_path / "good.png", grid, goodness, SPOT, FIELD)
    plot_goodness_field(
        tmp_path / "scatter.png",
        poses[:, :2] + 0.01 * rng.normal(size=(len(poses), 2)),
        dist,
        SPOT,
        FIELD,
    )
    for name in ("err", "arrows", "ref", "good", "scatter"):
        assert _is_png(tmp_path / f"{name}.png"), name
    with pytest.raises(ValueError, match="estimated_headings"):
        plot_arrow_field(tmp_path / "x.png", poses, estimated[:-1], SPOT, FIELD, "x")
    with pytest.raises(ValueError, match="goodness"):
        plot_goodness_field(tmp_path / "x.png", grid, goodness[:-1], SPOT, FIELD)
    with pytest.raises(ValueError, match="table_by_tracker"):
        plot_error_vs_distance(tmp_path / "x.png", {})
    assert not (tmp_path / "x.png").exists()
