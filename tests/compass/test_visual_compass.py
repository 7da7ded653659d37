"""The compass on synthetic panoramas whose true heading is known."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.compass import (
    Camera,
    CompassConfig,
    MapFileError,
    NotLearnedError,
    VisualCompass,
    wrap180,
)
from vc_gym.worlds.panorama import render_view


def test_recovers_random_yaws_in_a_room(room_pano, room_compass, view_heading_errors):
    yaws = np.random.default_rng(11).uniform(0.0, 360.0, 60)
    errs = view_heading_errors(room_compass, room_pano, yaws)
    assert np.mean(errs < 5.0) >= 0.95, np.sort(errs)[-5:]


def test_recovers_random_yaws_outdoors(outdoor_pano, make_learned_compass, view_heading_errors):
    vc = make_learned_compass(outdoor_pano)
    yaws = np.random.default_rng(12).uniform(0.0, 360.0, 40)
    errs = view_heading_errors(vc, outdoor_pano, yaws)
    assert np.mean(errs < 5.0) >= 0.95, np.sort(errs)[-5:]


def test_three_colour_classes_suffice(room_pano, make_learned_compass, view_heading_errors):
    vc = make_learned_compass(room_pano, CompassConfig(n_colors=3))
    yaws = np.random.default_rng(13).uniform(0.0, 360.0, 30)
    assert np.mean(view_heading_errors(vc, room_pano, yaws) < 5.0) >= 0.9


def test_sparse_scanning_grid_still_works(room_pano, make_learned_compass, view_heading_errors):
    # paper 5.3: coverage can go below 1 % without much loss
    vc = make_learned_compass(room_pano, CompassConfig(coverage=0.01))
    assert vc.config.grid_steps == (10, 10)
    yaws = np.random.default_rng(14).uniform(0.0, 360.0, 30)
    assert np.median(view_heading_errors(vc, room_pano, yaws)) < 5.0


def test_wrap_around_zero(room_pano, room_compass, view_heading_errors):
    errs = view_heading_errors(room_compass, room_pano, [359.6, 0.0, 0.4, 358.0, 2.0])
    assert np.all(errs < 3.0)
    est = room_compass.estimate(render_view(room_pano, Camera(yaw_deg=-0.3)), Camera())
    assert 0.0 <= est.heading_deg < 360.0


def test_learning_across_zero_updates_sectors_on_both_sides(room_pano):
    vc = VisualCompass()
    vc.fit_colors([render_view(room_pano, Camera())])
    n = vc.learn(render_view(room_pano, Camera(yaw_deg=1.0)), Camera(yaw_deg=1.0))
    seen = np.flatnonzero(vc.sector_observations)
    assert n == seen.size
    assert 0 in seen and vc.config.n_sectors - 1 in seen
    # only the sectors in view (hfov 56.9 deg around 1 deg) are updated
    directions = (seen + 0.5) * vc.config.sector_deg
    assert np.all(np.abs(wrap180(directions - 1.0)) < 56.9 / 2 + vc.config.sector_deg)


def test_pitch_is_handled(room_pano, room_compass, view_heading_errors):
    yaws = np.random.default_rng(15).uniform(0.0, 360.0, 15)
    errs = view_heading_errors(room_compass, room_pano, yaws, pitch_deg=8.0)
    assert np.mean(errs < 5.0) >= 0.9


@pytest.mark.parametrize(
    "camera",
    [
        Camera(),
        Camera(pitch_deg=8.0),
        Camera(hfov_deg=90.0, principal_point=(70.0, 60.0)),
        Camera(hfov_deg=20.0),
    ],
)
def test_sector_counts_are_the_columns_summed_by_sector(room_pano, room_compass, camera):
    """Each (heading phase, relative sector) row sums the scanned columns that look into
    that sector (the counts behind eq. 11, per sector)."""
    image = render_view(room_pano, camera.replace(yaw_deg=33.0))
    geom, counts, total = room_compass._sector_features(image, camera)
    pixels = image[geom.row_slice, geom.col_slice]
    colcounts = room_compass._column_counts(room_compass._scanned_classes(pixels))
    delta = room_compass.config.sector_deg
    headings = room_compass._headings
    phases = np.unique(np.round(headings - np.floor(headings / delta + 1e-9) * delta, 9))
    expected = np.zeros_like(counts)
    for p, phase in enumerate(phases):
        k = np.floor((phase + geom.grid.offsets_deg) / delta).astype(int) - geom.kmin
        for u in range(colcounts.shape[0]):
            expected[p * geom.n_rel + k[u]] += colcounts[u]
    np.testing.assert_array_equal(counts, expected)
    np.testing.assert_array_equal(total, expected.sum(axis=1))


@pytest.mark.parametrize("illumination", [0.5, 0.25, 1.5])
def test_exposure_mean_undoes_illumination_changes(
    room_pano, illumination, make_learned_compass, view_heading_errors
):
    # paper 5.3 tests half the illumination of learning; exposure="mean" undoes it
    vc = make_learned_compass(room_pano, CompassConfig(exposure="mean"))
    yaws = np.random.default_rng(16).uniform(0.0, 360.0, 20)
    errs = view_heading_errors(vc, room_pano, yaws, illumination)
    assert np.mean(errs < 5.0) >= 0.95, np.round(errs, 1)


def test_exposure_reference_survives_save_load(tmp_path, room_pano, make_learned_compass):
    vc = make_learned_compass(room_pano, CompassConfig(exposure="mean", n_colors=4))
    loaded = VisualCompass.load(vc.save(tmp_path / "m.npz"))
    img = render_view(room_pano, Camera(yaw_deg=33.0), illumination=0.5)
    np.testing.assert_array_equal(
        loaded.log_likelihood(img, Camera()), vc.log_likelihood(img, Camera())
    )


def test_compasses_sharing_exposure_normalised_colours_learn_and_localise(
    tmp_path, room_pano, make_learned_compass
):
    # the learners fit colours once and give them to every spot's compass; the
    # exposure reference must travel with the classes (without it the gain is 0)
    first = make_learned_compass(room_pano, CompassConfig(exposure="mean", n_colors=4))
    assert first.colors.exposure_reference > 0
    second = VisualCompass(first.config, first.colors)
    for yaw in range(0, 360, 30):
        second.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    img = render_view(room_pano, Camera(yaw_deg=200.0), illumination=0.5)
    assert abs(wrap180(second.estimate(img, Camera()).heading_deg - 200.0)) < 5.0
    arrays = first.colors.to_arrays()
    assert float(arrays["colors_exposure_reference"]) == first.colors.exposure_reference


def test_likelihood_shape_and_estimate_fields(room_pano, room_compass):
    img = render_view(room_pano, Camera(yaw_deg=123.0))
    ll = room_compass.log_likelihood(img, Camera())
    assert ll.shape == room_compass.headings_deg.shape == (360,)
    assert ll.dtype == np.float64 and np.all(np.isfinite(ll))
    est = room_compass.estimate(img, Camera())
    assert est.n_sectors in (12, 13, 14)
    assert est.score <= 0.0
    assert 0.0 <= est.spread_deg < 10.0
    np.testing.assert_array_equal(est.log_likelihood, ll)


def test_unlearned_sectors_are_neutral(room_pano):
    vc = VisualCompass(CompassConfig(n_colors=4))
    vc.fit_colors([render_view(room_pano, Camera())])
    vc.learn(render_view(room_pano, Camera(yaw_deg=0.0)), Camera(yaw_deg=0.0))
    # a view of the opposite side sees only sectors the map never learned
    ll = vc.log_likelihood(render_view(room_pano, Camera(yaw_deg=180.0)), Camera())
    far = np.abs(wrap180(vc.headings_deg - 180.0)) < 20.0
    np.testing.assert_allclose(ll[far], 0.0, atol=1e-9)


def test_temperature_scales_log_likelihood(room_pano, room_compass):
    img = render_view(room_pano, Camera(yaw_deg=40.0))
    hot = VisualCompass.__new__(VisualCompass)
    hot.__dict__.update(room_compass.__dict__)
    hot.config = CompassConfig(temperature=4.0)
    np.testing.assert_allclose(
        hot.log_likelihood(img, Camera()), room_compass.log_likelihood(img, Camera()) / 4.0
    )


def test_bgr_input_scores_worse_than_rgb(room_pano, room_compass):
    """Documented behaviour: BGR cannot be detected, but it fits the map visibly worse."""
    img = render_view(room_pano, Camera(yaw_deg=70.0))
    rgb = room_compass.estimate(img, Camera()).score
    bgr = room_compass.estimate(np.ascontiguousarray(img[..., ::-1]), Camera()).score
    assert bgr < rgb


def test_transposed_image_is_rejected(room_pano, room_compass):
    img = render_view(room_pano, Camera(yaw_deg=70.0))
    with pytest.raises(ValueError, match="transposed"):
        room_compass.log_likelihood(np.ascontiguousarray(img.transpose(1, 0, 2)), Camera())


def test_nothing_above_horizon(room_pano, room_compass):
    img = render_view(room_pano, Camera(yaw_deg=10.0, pitch_deg=-80.0))
    ll = room_compass.log_likelihood(img, Camera(pitch_deg=-80.0))
    assert np.all(ll == 0.0)
    vc = VisualCompass()
    vc.fit_colors([img])
    assert vc.learn(img, Camera(pitch_deg=-80.0)) == 0
    assert vc.frames_learned == 0


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((160, 208, 3), dtype=np.float32),
        np.zeros((160, 208), dtype=np.uint8),
        np.zeros((160, 208, 4), dtype=np.uint8),
        np.zeros((3, 160, 208), dtype=np.uint8),  # channels first
        np.zeros((0, 208, 3), dtype=np.uint8),
        [[1, 2, 3]],
    ],
)
def test_bad_images_are_rejected(room_compass, bad):
    with pytest.raises(ValueError):
        room_compass.log_likelihood(bad, Camera())
    with pytest.raises(ValueError):
        room_compass.learn(bad, Camera())


def test_not_learned_errors(room_pano):
    img = render_view(room_pano, Camera())
    vc = VisualCompass()
    with pytest.raises(NotLearnedError, match="fit_colors"):
        vc.learn(img, Camera())
    vc.fit_colors([img])
    with pytest.raises(NotLearnedError, match="empty"):
        vc.log_likelihood(img, Camera())
    with pytest.raises(NotLearnedError):
        VisualCompass().save("never.npz")


def test_refitting_colours_needs_reset(room_pano, room_compass, make_learned_compass):
    img = render_view(room_pano, Camera())
    vc = make_learned_compass(room_pano, CompassConfig(n_colors=3))
    with pytest.raises(ValueError, match="reset_map"):
        vc.fit_colors([img])
    vc.fit_colors([img], reset_map=True)
    assert vc.frames_learned == 0 and not vc.is_learned


def test_bad_camera_argument(room_pano, room_compass):
    img = render_view(room_pano, Camera())
    with pytest.raises(ValueError, match="Camera"):
        room_compass.log_likelihood(img, {"hfov_deg": 56.9})


def test_config_validation():
    for bad in (
        {"n_colors": 0},
        {"sector_deg": 7.0},
        {"n_bins": 1},
        {"coverage": 0.0},
        {"coverage": float("nan")},
        {"coverage": 1e-9},  # would learn nothing
        {"coverage": 0.0009},
        {"heading_step_deg": 0.7},
        {"heading_step_deg": 1e-9},  # divides 360, but 3.6e11 headings
        {"sector_deg": 0.001, "n_colors": 32, "n_bins": 32},  # 1.2e10 counts
        {"sector_deg": 0.5, "n_colors": 32, "n_bins": 32},  # 23.6 million counts
        {"smoothing": -1.0},
        {"temperature": 0.0},
        {"n_colors": 2.5},
    ):
        with pytest.raises(ValueError):
            CompassConfig(**bad)
    # the largest map still allowed: 1° sectors, 32 classes, 32 bins
    assert CompassConfig(sector_deg=1.0, n_colors=32, n_bins=32).n_sectors == 360


# ------------------------------------------------------------------ persistence
def test_save_load_round_trip_gives_identical_likelihoods(tmp_path, room_pano, room_compass):
    path = room_compass.save(tmp_path / "map")
    assert path.suffix == ".npz" and path.exists()
    loaded = VisualCompass.load(path)
    assert loaded.config == room_compass.config
    assert loaded.frames_learned == room_compass.frames_learned
    for yaw in (0.0, 91.0, 250.5):
        img = render_view(room_pano, Camera(yaw_deg=yaw))
        np.testing.assert_array_equal(
            loaded.log_likelihood(img, Camera()), room_compass.log_likelihood(img, Camera())
        )
    assert not list(tmp_path.glob("*.tmp")), "temporary file left behind"


def test_load_rejects_truncated_file(tmp_path, room_compass):
    path = room_compass.save(tmp_path / "map.npz")
    data = path.read_bytes()
    bad = tmp_path / "truncated.npz"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(MapFileError, match="truncated.npz"):
        VisualCompass.load(bad)


def test_load_rejects_empty_missing_and_garbage(tmp_path):
    empty = tmp_path / "empty.npz"
    empty.write_bytes(b"")
    with pytest.raises(MapFileError, match="empty"):
        VisualCompass.load(empty)
    with pytest.raises(MapFileError, match="no such file"):
        VisualCompass.load(tmp_path / "missing.npz")
    garbage = tmp_path / "garbage.npz"
    garbage.write_bytes(b"not a zip file at all" * 10)
    with pytest.raises(MapFileError):
        VisualCompass.load(garbage)


def _rewrite(path, out, **changes):
    with np.load(path, allow_pickle=False) as d:
        arrays = {k: d[k] for k in d.files}
    arrays.update(changes)
    np.savez(out, **arrays)
    return out


def test_load_rejects_other_version_schema_and_config(tmp_path, room_compass):
    path = room_compass.save(tmp_path / "map.npz")
    with pytest.raises(MapFileError, match="version 99"):
        VisualCompass.load(_rewrite(path, tmp_path / "v.npz", schema_version=np.array(99)))
    with pytest.raises(MapFileError, match="expected"):
        VisualCompass.load(_rewrite(path, tmp_path / "s.npz", schema=np.array("other")))
    with pytest.raises(MapFileError, match="was learned with"):
        VisualCompass.load(path, config=CompassConfig(n_colors=3))
    wrong = np.zeros((3, 3, 3), dtype=np.uint32)
    with pytest.raises(MapFileError, match="counts"):
        VisualCompass.load(_rewrite(path, tmp_path / "c.npz", counts=wrong))
    with pytest.raises(MapFileError, match="colour classes"):
        VisualCompass.load(
            _rewrite(path, tmp_path / "n.npz", colors_means=np.full((10, 3), np.nan))
        )
    # a config that would allocate 3.6e11 headings is refused, not obeyed
    with np.load(path) as d:
        cfg = json.loads(str(d["config"]))
    cfg["heading_step_deg"] = 1e-9
    with pytest.raises(MapFileError, match="heading_step_deg"):
        VisualCompass.load(_rewrite(path, tmp_path / "h.npz", config=np.array(json.dumps(cfg))))


def test_load_never_unpickles(tmp_path, room_compass):
    path = room_compass.save(tmp_path / "map.npz")
    with np.load(path, allow_pickle=False) as d:
        arrays = {k: d[k] for k in d.files}
    arrays["config"] = np.array([{"evil": 1}], dtype=object)
    evil = tmp_path / "evil.npz"
    np.savez(evil, **arrays)
    with pytest.raises(MapFileError):
        VisualCompass.load(evil)


def test_save_is_atomic_and_keeps_old_file_on_failure(tmp_path, room_compass, monkeypatch):
    path = room_compass.save(tmp_path / "map.npz")
    before = path.read_bytes()

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez_compressed", boom)
    with pytest.raises(OSError, match="disk full"):
        room_compass.save(path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.npz"]


def test_merging_maps_equals_learning_all_their_frames(room_pano):
    fit = [render_view(room_pano, Camera(yaw_deg=a)) for a in range(0, 360, 45)]
    whole, first = VisualCompass(), VisualCompass()
    whole.fit_colors(fit)
    first.fit_colors(fit)
    second = VisualCompass(colors=first.colors)
    yaws = np.arange(0.0, 360.0, 20.0)
    for k, yaw in enumerate(yaws):
        image, cam = render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw)
        whole.learn(image, cam)
        (first if k % 2 else second).learn(image, cam)
    assert first.merge(second) is first
    assert first.frames_learned == whole.frames_learned == len(yaws)
    np.testing.assert_array_equal(first.sector_observations, whole.sector_observations)
    probe = render_view(room_pano, Camera(yaw_deg=123.0))
    np.testing.assert_array_equal(
        first.log_likelihood(probe, Camera()), whole.log_likelihood(probe, Camera())
    )


def test_merge_refuses_other_configs_or_colours(room_pano, room_compass):
    with pytest.raises(ValueError, match="CompassConfig"):
        VisualCompass(CompassConfig(n_colors=3)).merge(room_compass)
    other = VisualCompass()
    other.fit_colors([render_view(room_pano, Camera(yaw_deg=a)) for a in (10.0, 200.0)])
    with pytest.raises(ValueError, match="colour classes"):
        other.merge(room_compass)
    with pytest.raises(ValueError, match="VisualCompass"):
        other.merge("map.npz")


@pytest.mark.parametrize("colour", [(0, 0, 0), (255, 255, 255), (90, 140, 200)])
def test_a_frame_without_colour_changes_gives_a_flat_likelihood(room_pano, room_compass, colour):
    # scored like any frame, all-black would fit better (-0.097) than the true frame,
    # with a 3.7° spread
    frame = np.empty((160, 208, 3), np.uint8)
    frame[:] = colour
    ll = room_compass.log_likelihood(frame, Camera())
    assert np.all(ll == 0.0)
    est = room_compass.estimate(frame, Camera())
    assert est.n_sectors == 0 and est.spread_deg > 90.0
    assert not est.has_evidence and est.heading_deg == 0.0
    true = room_compass.estimate(render_view(room_pano, Camera(yaw_deg=40.0)), Camera())
    assert true.n_sectors > 0 and abs(wrap180(true.heading_deg - 40.0)) < 3.0
    assert true.has_evidence


def _noise(kind: str, rng: np.random.Generator) -> np.ndarray:
    if kind == "uniform":
        return rng.integers(0, 256, (160, 208, 3), dtype=np.uint8)
    if kind == "grey":
        return np.repeat(rng.integers(0, 256, (160, 208, 1), dtype=np.uint8), 3, axis=2)
    small = rng.integers(0, 256, (80, 104, 3), dtype=np.uint8)  # 2-pixel blocks
    return np.repeat(np.repeat(small, 2, axis=0), 2, axis=1)


@pytest.mark.parametrize("kind", ["uniform", "grey", "blocks2"])
def test_a_frame_of_noise_gives_a_flat_likelihood(room_pano, room_compass, kind):
    # scored like any frame, uniform noise would get a confident (1.9° spread) and
    # arbitrary heading
    frame = _noise(kind, np.random.default_rng(3))
    assert np.all(room_compass.log_likelihood(frame, Camera()) == 0.0)
    est = room_compass.estimate(frame, Camera())
    assert est.n_sectors == 0 and est.spread_deg > 90.0 and not est.has_evidence


def test_a_noisy_camera_frame_still_gives_its_heading(room_pano, room_compass):
    """Sensor noise on a real view is not mistaken for a frame of noise."""
    rng = np.random.default_rng(4)
    view = render_view(room_pano, Camera(yaw_deg=75.0)).astype(np.float64)
    noisy = np.clip(view + rng.normal(0.0, 8.0, view.shape), 0, 255).astype(np.uint8)
    est = room_compass.estimate(noisy, Camera())
    assert est.n_sectors > 0 and abs(wrap180(est.heading_deg - 75.0)) < 5.0


def test_an_estimate_prints_in_one_short_line():
    from vc_gym.compass.visual_compass import CompassEstimate

    text = repr(CompassEstimate(12.3456, 0.5, -1.23456, 7, np.zeros(360)))
    assert text == (
        "CompassEstimate(heading_deg=12.35, spread_deg=0.50, score=-1.2346, n_sectors=7, "
        "log_likelihood=<360 headings>)"
    )
