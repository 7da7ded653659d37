"""make_sensor: every sensor by name, dict, import path, callable or instance."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from vc_gym.compass import Camera, ImageCompass, MapFileError, VisualCompass
from vc_gym.filters import HeadingGridFilter
from vc_gym.heading_sensors import (
    SENSORS,
    FeatureCompass,
    ImageDifferenceCompass,
    NoisyMagneticCompass,
    SectorColorCompass,
    make_sensor,
    register_sensor,
)
from vc_gym.localization.compass_sensors import CompassHeadingSensor
from vc_gym.worlds.panorama import render_view


@pytest.mark.parametrize(
    ("spec", "cls"),
    [
        ("visual_compass", VisualCompass),
        ("image_difference", ImageDifferenceCompass),
        ("sector_color", SectorColorCompass),
        ("feature", FeatureCompass),
        ("magnetic", NoisyMagneticCompass),
        ({"type": "magnetic", "noise_deg": 7.0}, NoisyMagneticCompass),
        (functools.partial(FeatureCompass, n_features=50), FeatureCompass),
        ("vc_gym.heading_sensors:ImageDifferenceCompass", ImageDifferenceCompass),
    ],
)
def test_specs(spec, cls):
    assert type(make_sensor(spec)) is cls


@pytest.mark.parametrize("spec", ["sector_colour", {"type": "sector_colour", "model": "histogram"}])
def test_the_british_sector_name_is_a_deprecated_alias(spec):
    message = "'sector_colour' is deprecated; use 'sector_color'"
    with pytest.warns(DeprecationWarning, match=message):
        sensor = make_sensor(spec)
    assert type(sensor) is SectorColorCompass
    assert "sector_colour" not in SENSORS and SectorColorCompass.name == "sector_color"


def test_a_saved_sector_sensor_loads_under_the_british_name(room_pano, tmp_path):
    from vc_gym.heading_sensors import SENSOR_GRID, load_sensor
    from vc_gym.localization import make_tracker

    sensor = make_sensor("sector_color")
    for yaw in range(0, 360, 30):
        sensor.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    path = sensor.save(tmp_path / "home.npz")
    with pytest.warns(DeprecationWarning, match="'sector_color'"):
        loaded = load_sensor("sector_colour", path)
    image = render_view(room_pano, Camera(yaw_deg=77.0))
    assert np.array_equal(
        loaded.log_likelihood(image, Camera()), sensor.log_likelihood(image, Camera())
    )
    spec = {"type": SENSOR_GRID, "sensor": "sector_colour", "sensor_file": str(path)}
    with pytest.warns(DeprecationWarning, match="'sector_color'"):
        assert isinstance(make_tracker(spec).heading_sensor, SectorColorCompass)


def test_dict_kwargs_reach_the_constructor():
    assert make_sensor({"type": "visual_compass", "exposure": "mean"}).config.exposure == "mean"
    assert make_sensor({"type": "magnetic", "noise_deg": 7.0}).noise_deg == 7.0
    sensor = NoisyMagneticCompass()
    assert make_sensor(sensor) is sensor


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("compass", "unknown sensor 'compass'; known: "),
        ({"noise_deg": 1.0}, "needs a 'type'"),
        ({"type": "magnetic", "noise": 1.0}, "bad arguments for sensor 'magnetic'"),
        (lambda: 42, "gave int"),
        (3.5, "a sensor spec is"),
        ("nowhere.module:thing", "cannot import sensor factory"),
    ],
)
def test_bad_specs_say_what_is_wrong(spec, message):
    with pytest.raises(ValueError, match=message):
        make_sensor(spec)


def test_register_a_users_sensor():
    register_sensor("my_magnetometer", functools.partial(NoisyMagneticCompass, noise_deg=1.0))
    try:
        assert make_sensor("my_magnetometer").noise_deg == 1.0
        with pytest.raises(ValueError, match="registered already"):
            register_sensor("my_magnetometer", NoisyMagneticCompass)
    finally:
        del SENSORS["my_magnetometer"]


@pytest.mark.parametrize("name", ["image_difference", "sector_color", "feature"])
def test_every_image_baseline_is_a_filters_heading_sensor(room_pano, name):
    # the image compass surface: a tracker's heading sensor takes it like the visual compass
    sensor = make_sensor(name)
    assert isinstance(sensor, ImageCompass)
    for yaw in range(0, 360, 15):
        sensor.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    heading = CompassHeadingSensor(sensor, Camera())
    f = HeadingGridFilter(rule="bayes")
    f.reset(0.0, 180.0)
    for _ in range(3):
        f.update(heading, render_view(room_pano, Camera(yaw_deg=137.0)))
    assert abs((f.estimate().heading_deg - 137.0 + 180.0) % 360.0 - 180.0) < 5.0
    assert np.isfinite(f.estimate().spread_deg)


def test_a_saved_sensor_is_a_grid_trackers_heading_sensor(room_pano, tmp_path):
    from vc_gym.heading_sensors import SENSOR_GRID, load_sensor
    from vc_gym.localization import GridTracker, make_tracker

    sensor = make_sensor("image_difference")
    for yaw in range(0, 360, 30):
        sensor.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    path = sensor.save(tmp_path / "home.npz")
    loaded = load_sensor("image_difference", path)
    image = render_view(room_pano, Camera(yaw_deg=77.0))
    assert np.array_equal(
        loaded.log_likelihood(image, Camera()), sensor.log_likelihood(image, Camera())
    )
    spec = {"type": SENSOR_GRID, "sensor": "image_difference", "sensor_file": str(path)}
    tracker = make_tracker({**spec, "half_life_s": 0.5})
    assert isinstance(tracker, GridTracker) and tracker.half_life_s == 0.5
    assert isinstance(tracker.heading_sensor, ImageDifferenceCompass)
    with pytest.raises(ValueError, match="not an image sensor that can be saved"):
        load_sensor("magnetic", path)
    with pytest.raises(MapFileError, match="home.npz"):
        load_sensor("feature", path)  # another sensor's file


@pytest.mark.parametrize(
    "spec",
    [
        {"type": "magnetic", "heading_step_deg": 1e-6},  # would be 3.6e8 headings
        {"type": "image_difference", "heading_step_deg": 0.001},
        {"type": "sector_color", "el_step_deg": 1e-9},
    ],
)
def test_a_config_cannot_make_a_sensor_exhaust_memory(spec):
    with pytest.raises(ValueError, match="heading_step_deg must be >=|elevation rows"):
        make_sensor(spec)
