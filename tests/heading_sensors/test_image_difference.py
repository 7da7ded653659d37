"""The rotational image difference compass (Zeil et al. 2003, Labrosse 2006)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.compass import Camera
from vc_gym.errors import MapFileError, NotLearnedError
from vc_gym.experiments.real_data import load_rotation_set
from vc_gym.experiments.real_rotation import rotation_set_errors
from vc_gym.heading_sensors.image_difference import ImageDifferenceCompass
from vc_gym.heading_sensors.strip import angular_strip, strip_offsets
from vc_gym.persistence import save_npz_atomic
from vc_gym.worlds.panorama import render_view

#: Yaws of the learning frames: 8 body directions x 3 head pans (as tests/conftest.py).
LEARN_YAWS = [body + pan for body in range(0, 360, 45) for pan in (-22.5, 0.0, 22.5)]


def _views(pano, yaws, illumination=1.0, **camera):
    return [render_view(pano, Camera(yaw_deg=y, **camera), illumination=illumination) for y in yaws]


def _learned(images, yaws, **kwargs) -> ImageDifferenceCompass:
    c = ImageDifferenceCompass(**kwargs)
    for image, yaw in zip(images, yaws, strict=True):
        c.learn(image, Camera(yaw_deg=yaw))
    return c


def _errors(compass, images, yaws, camera=None):
    camera = camera or Camera()
    return np.array(
        [
            abs(wrap180(compass.estimate(im, camera).heading_deg - y))
            for im, y in zip(images, yaws, strict=True)
        ]
    )


@pytest.fixture(scope="module")
def learn_views(room_pano, outdoor_pano):
    return {"room": _views(room_pano, LEARN_YAWS), "outdoor": _views(outdoor_pano, LEARN_YAWS)}


@pytest.fixture(scope="module")
def maps(learn_views):
    return {kind: _learned(views, LEARN_YAWS) for kind, views in learn_views.items()}


@pytest.fixture(scope="module")
def panos(room_pano, outdoor_pano):
    return {"room": room_pano, "outdoor": outdoor_pano}


RANDOM_YAWS = np.random.default_rng(11).uniform(0.0, 360.0, 20)


# ---------------------------------------------------------------- known answers
@pytest.mark.parametrize("kind", ["room", "outdoor"])
def test_random_yaws_at_the_spot(kind, maps, panos):
    errors = _errors(maps[kind], _views(panos[kind], RANDOM_YAWS), RANDOM_YAWS)
    # measured on 100 views: all within 0.6 deg (median 0.04)
    assert np.mean(errors < 5.0) >= 0.9, errors
    assert np.median(errors) < 1.0, errors


def test_log_likelihood_peaks_at_the_true_heading_and_ignores_the_yaw(maps, room_pano):
    c = maps["room"]
    image = render_view(room_pano, Camera(yaw_deg=123.0))
    ll = c.log_likelihood(image, Camera())
    assert ll.shape == (360,) and np.all(np.isfinite(ll))
    assert int(np.argmax(ll)) == 123
    assert np.array_equal(ll, c.log_likelihood(image, Camera(yaw_deg=77.0)))
    est = c.estimate(image, Camera())
    assert est.n_sectors == 57  # the Aibo's 56.9 deg: whole-degree columns -28..28
    at = c.heading_log_likelihood((image, Camera()), np.array([123.0, 10.0]))
    assert np.allclose(at, ll[[123, 10]])


def test_log_likelihood_is_the_documented_gaussian_of_the_brute_force_msd(maps, room_pano):
    """Known answer for the FFT path: the masked mean squared difference at every
    heading, computed directly from the panorama, gives ``ll = -n_eff MSD / (2 sigma^2)``."""
    c = maps["room"]
    image = render_view(room_pano, Camera(yaw_deg=200.0))
    j = strip_offsets(Camera(), image.shape[1], c.grid)
    strip, valid, _ = angular_strip(image, Camera(), c.grid, j)
    q = strip.astype(np.float64) / (strip.sum() / (3 * valid.sum()))  # normalize="mean"
    colors, pvalid = c.panorama
    level = colors.sum() / (3 * pvalid.sum())
    msd = np.empty(360)
    for h in range(360):
        cols = (h + j) % 360
        m = valid & pvalid[:, cols]
        msd[h] = ((q - colors[:, cols]) ** 2 * m[..., None]).sum() / (3 * m.sum())
    n_eff = int(valid.any(axis=0).sum())
    expected = -n_eff * msd / (2 * (c.noise_std * level) ** 2)
    np.testing.assert_allclose(c.log_likelihood(image, Camera()), expected, rtol=1e-9, atol=1e-6)
    assert c.estimate(image, Camera()).score == pytest.approx(-math.sqrt(msd.min()), rel=1e-6)


def test_wrap_around_zero(maps, room_pano):
    yaws = np.array([0.0, 0.4, 359.6, 358.7, 1.3])
    errors = _errors(maps["room"], _views(room_pano, yaws), yaws)
    assert np.all(errors < 1.0), errors
    ll = maps["room"].log_likelihood(render_view(room_pano, Camera(yaw_deg=359.6)), Camera())
    assert int(np.argmax(ll)) == 0  # 359.6 rounds to bin 0, across the seam


def test_learning_yaw_is_taken_modulo_360(learn_views):
    views = learn_views["room"][:6]
    plain = _learned(views, LEARN_YAWS[:6])
    shifted = _learned(views, [y + 720.0 for y in LEARN_YAWS[:6]])
    negative = _learned(views, [y - 360.0 for y in LEARN_YAWS[:6]])
    for other in (shifted, negative):
        assert np.allclose(other.panorama[0], plain.panorama[0])
        assert np.array_equal(other.panorama[1], plain.panorama[1])


@pytest.mark.parametrize("pitch", [-12.0, 10.0])
def test_pitched_camera(maps, room_pano, pitch):
    yaws = RANDOM_YAWS[:8]
    images = _views(room_pano, yaws, pitch_deg=pitch)
    errors = _errors(maps["room"], images, yaws, Camera(pitch_deg=pitch))
    assert np.all(errors < 2.0), errors


def test_crop_with_principal_point(maps, room_pano):
    """A crop keeps the focal length and the optical axis (its principal point moves
    to the left edge): its true heading is the full view's yaw."""
    wide = Camera(hfov_deg=90.0, yaw_deg=140.0)
    image = render_view(room_pano, wide, width=320, height=160)
    f = wide.focal_px(320)
    crop = np.ascontiguousarray(image[:, 160:])
    cam = Camera.from_focal(f, 160, principal_point=(159.5 - 160, 79.5))
    est = maps["room"].estimate(crop, cam)
    assert abs(wrap180(est.heading_deg - 140.0)) < 1.0
    # the crop's centre looks about 26 deg right of the axis: ignoring the principal
    # point must give that answer instead (the test can tell the two apart)
    naive = maps["room"].estimate(crop, Camera.from_focal(f, 160))
    assert abs(wrap180(naive.heading_deg - (140.0 - math.degrees(math.atan(80 / f))))) < 2.0


def test_half_illumination_needs_the_mean_normalisation(maps, learn_views, outdoor_pano):
    images = _views(outdoor_pano, RANDOM_YAWS, illumination=0.5)
    with_mean = _errors(maps["outdoor"], images, RANDOM_YAWS)
    # measured on 100 views: "mean" all within 0.6 deg, "none" 62 % within 5 deg
    assert np.mean(with_mean < 5.0) >= 0.9, with_mean
    raw = _learned(learn_views["outdoor"], LEARN_YAWS, normalize="none")
    without = _errors(raw, images, RANDOM_YAWS)
    assert np.mean(without < 5.0) < np.mean(with_mean < 5.0), without
    local = _learned(learn_views["outdoor"], LEARN_YAWS, normalize="local")
    assert np.mean(_errors(local, images, RANDOM_YAWS) < 5.0) >= 0.9


def test_posterior_is_neither_absurdly_sharp_nor_flat(maps, room_pano):
    images = _views(room_pano, RANDOM_YAWS[:12])
    spreads = np.array([maps["room"].estimate(im, Camera()).spread_deg for im in images])
    # measured on 100 views: median 1.7 deg, 0.2 - 17 deg
    assert 0.5 < np.median(spreads) < 8.0, spreads


def test_goodness_is_best_at_the_place_it_learned(maps, room_pano, outdoor_pano):
    at_home = maps["room"].estimate(render_view(room_pano, Camera(yaw_deg=30.0)), Camera())
    elsewhere = maps["room"].estimate(render_view(outdoor_pano, Camera(yaw_deg=30.0)), Camera())
    assert -0.15 < at_home.score <= 0.0  # measured: RMS difference ~0.06 of the mean
    assert elsewhere.score < 2.0 * at_home.score


def test_unlearned_half_is_never_picked(room_pano):
    """Learn only 0-180 deg: headings whose view lies mostly in the other half get the
    worst value of the learned ones (not -inf, not NaN) and never win."""
    yaws = [30.0, 60.0, 90.0, 120.0, 150.0]
    c = _learned(_views(room_pano, yaws), yaws)
    assert 0.45 < c.learned_fraction < 0.55
    for true in (70.0, 135.0):
        est = c.estimate(render_view(room_pano, Camera(yaw_deg=true)), Camera())
        assert abs(wrap180(est.heading_deg - true)) < 1.0
    for true in (230.0, 270.0, 315.0):
        ll = c.log_likelihood(render_view(room_pano, Camera(yaw_deg=true)), Camera())
        assert np.all(np.isfinite(ll))
        # learned azimuths ~[1.5, 178.5]: from 180 deg on, less than half of a view is learned
        assert np.all(ll[182:358] == ll.min())
        assert 0 <= int(np.argmax(ll)) < 180


def test_no_view_of_the_band_gives_a_flat_answer(maps, room_pano):
    up = Camera(pitch_deg=70.0)
    est = maps["room"].estimate(render_view(room_pano, up), up)
    assert est.n_sectors == 0 and est.score == -math.inf
    assert np.all(est.log_likelihood == 0.0)


def test_learning_again_updates_the_cached_spectra(learn_views):
    views, yaws = learn_views["room"][:4], LEARN_YAWS[:4]
    c = _learned(views[:2], yaws[:2])
    c.log_likelihood(views[3], Camera())  # fills the cache
    c.learn(views[2], Camera(yaw_deg=yaws[2]))
    c.learn(views[3], Camera(yaw_deg=yaws[3]))
    fresh = _learned(views, yaws)
    np.testing.assert_array_equal(
        c.log_likelihood(views[3], Camera()), fresh.log_likelihood(views[3], Camera())
    )


def test_coarser_heading_grid(learn_views, room_pano):
    c = _learned(learn_views["room"], LEARN_YAWS, heading_step_deg=2.0)
    assert c.headings_deg.size == 180 and c.grid.n_azimuths == 180
    errors = _errors(c, _views(room_pano, RANDOM_YAWS[:6]), RANDOM_YAWS[:6])
    assert np.all(errors < 2.0), errors


@pytest.mark.parametrize(
    ("set_name", "min_within_5"),
    # measured with the defaults: median 0.12 / 0.15 deg, within 5 deg 26/27 / 19/27
    # (on the lawn, the middle crops look into the gaps between the learned photos)
    [("rotation_grail", 0.85), ("rotation_parrington", 0.6)],
)
def test_real_rotation_sets(real_data_dir, set_name, min_within_5):
    photos = load_rotation_set(real_data_dir / set_name)
    errors = np.array(rotation_set_errors(photos, ImageDifferenceCompass())["errors_deg"])
    assert np.median(errors) < 1.0, errors
    assert np.mean(errors < 5.0) >= min_within_5, errors


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "kwargs",
    [
        {"heading_step_deg": 7.0},
        {"heading_step_deg": 90.0},
        {"heading_step_deg": float("nan")},
        {"el_min_deg": 10.0, "el_max_deg": -10.0},
        {"el_min_deg": float("nan")},
        {"el_max_deg": 95.0},
        {"el_step_deg": 0.0},
        {"el_step_deg": 1e-9},
        {"normalize": "median"},
        {"normalize": None},
        {"noise_std": 0.0},
        {"noise_std": float("nan")},
        {"noise_std": "0.4"},
        {"min_overlap": 0.0},
        {"min_overlap": 1.5},
        {"min_overlap": float("inf")},
    ],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ValueError):
        ImageDifferenceCompass(**kwargs)


def test_bad_images_and_cameras(maps):
    c = maps["room"]
    good = np.zeros((160, 208, 3), dtype=np.uint8)
    for image in (good.astype(np.float32), good[..., 0], good[..., :2], np.zeros((0, 5, 3))):
        with pytest.raises(ValueError):
            c.log_likelihood(image, Camera())
        with pytest.raises(ValueError):
            ImageDifferenceCompass().learn(image, Camera())
    for camera in (None, {"yaw_deg": 0.0}, 30.0):
        with pytest.raises(ValueError, match="Camera"):
            c.estimate(good, camera)
        with pytest.raises(ValueError, match="Camera"):
            ImageDifferenceCompass().learn(good, camera)


def test_not_learned():
    c = ImageDifferenceCompass()
    image = np.zeros((160, 208, 3), dtype=np.uint8)
    for call in (c.log_likelihood, c.estimate):
        with pytest.raises(NotLearnedError):
            call(image, Camera())
    with pytest.raises(NotLearnedError):
        c.save("unused.npz")


# ---------------------------------------------------------------- persistence
@pytest.mark.parametrize("normalize", ["mean", "local"])
def test_save_load_round_trip(tmp_path, learn_views, room_pano, normalize):
    c = _learned(learn_views["room"][:9], LEARN_YAWS[:9], normalize=normalize, noise_std=0.3)
    path = c.save(tmp_path / "map")
    assert path.name == "map.npz"
    back = ImageDifferenceCompass.load(path)
    assert back._config() == c._config() and back.frames_learned == 9
    for yaw in (10.0, 250.0):
        image = render_view(room_pano, Camera(yaw_deg=yaw))
        np.testing.assert_array_equal(
            back.log_likelihood(image, Camera()), c.log_likelihood(image, Camera())
        )


@pytest.fixture
def saved(tmp_path, learn_views):
    c = _learned(learn_views["room"][:3], LEARN_YAWS[:3])
    path = c.save(tmp_path / "map.npz")
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files if k not in ("schema", "schema_version")}
    return path, arrays


def _rewrite(path, arrays, schema=ImageDifferenceCompass.schema):
    save_npz_atomic(path, schema, ImageDifferenceCompass.schema_version, arrays)
    return path


def test_corrupt_file(tmp_path, saved):
    path, _ = saved
    path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(MapFileError, match="map.npz"):
        ImageDifferenceCompass.load(path)
    with pytest.raises(MapFileError, match="missing"):
        ImageDifferenceCompass.load(tmp_path / "missing.npz")


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda a: a.pop("count"), "count"),
        (lambda a: a.update(count=a["count"][:, :100]), "count"),
        (lambda a: a.update(count=-a["count"]), "count"),
        (lambda a: a.update(count=a["count"].astype(np.float64)), "count"),
        (lambda a: a["color_sum"].__setitem__((0, 0, 0), np.nan), "color_sum"),
        (lambda a: a.update(color_sum=a["color_sum"][..., :2]), "color_sum"),
        (lambda a: a.update(color_sum=a["color_sum"] + 1.0), "color_sum"),
        (lambda a: a.update(frames_learned=np.array(0)), "frames_learned"),
        (lambda a: a.update(frames_learned=np.array(2)), "frames_learned"),
    ],
)
def test_inconsistent_file(saved, change, message):
    path, arrays = saved
    change(arrays)
    with pytest.raises(MapFileError, match=message) as info:
        ImageDifferenceCompass.load(_rewrite(path, arrays))
    assert path.name in str(info.value)


def test_bad_config_and_other_schema(saved):
    path, arrays = saved
    with pytest.raises(MapFileError, match="vc_gym.FeatureCompass"):
        ImageDifferenceCompass.load(_rewrite(path, dict(arrays), schema="vc_gym.FeatureCompass"))
    from vc_gym.persistence import json_array

    bad = dict(arrays, config=json_array({"normalize": "median"}))
    with pytest.raises(MapFileError, match="normalize"):
        ImageDifferenceCompass.load(_rewrite(path, bad))
    wider = dict(arrays, config=json_array({"el_max_deg": 30.0}))  # more rows than saved
    with pytest.raises(MapFileError, match="shape"):
        ImageDifferenceCompass.load(_rewrite(path, wider))
