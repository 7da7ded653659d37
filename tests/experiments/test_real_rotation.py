"""The compass on real photos (skipped when the photo folder is absent)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import CompassConfig
from vc_gym.experiments.real_data import load_rotation_set
from vc_gym.experiments.real_rotation import crop_columns, evaluate_rotation_set


@pytest.mark.parametrize("set_name", ["rotation_grail", "rotation_parrington"])
def test_real_rotation_set_localises_crops(real_data_dir, set_name):
    photos = load_rotation_set(real_data_dir / set_name)
    assert len(photos) == 18
    r = evaluate_rotation_set(photos, CompassConfig(n_colors=10))
    assert r["n_crops"] == 27
    # measured: median below 1 deg on both sets; demand a clear, not a lucky, result
    assert r["median_error_deg"] < 3.0, r["errors_deg"]
    assert r["within_10deg"] >= 0.75, r["errors_deg"]


def test_rotation_loader_reads_ground_truth(real_data_dir):
    photos = load_rotation_set(real_data_dir / "rotation_grail")
    assert photos[0].name == "grail01.jpg" and photos[0].yaw_deg == 0.0
    assert photos[0].image.dtype == np.uint8 and photos[0].image.shape == (512, 384, 3)
    yaws = np.array([p.yaw_deg for p in photos])
    assert np.all(np.diff(yaws) > 15.0)  # camera turns left ~20 deg per photo


def test_crop_camera_keeps_optical_axis(real_data_dir):
    photo = load_rotation_set(real_data_dir / "rotation_grail")[3]
    crop, cam = crop_columns(photo, 100, 150)
    assert crop.shape == (512, 150, 3)
    assert cam.yaw_deg == photo.yaw_deg
    assert cam.focal_px(150) == pytest.approx(photo.focal_px)
    with pytest.raises(ValueError):
        crop_columns(photo, 300, 150)


def test_missing_folder_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="yaw_ground_truth.csv"):
        load_rotation_set(tmp_path)


@pytest.mark.parametrize("exposure", ["map", "session"])
@pytest.mark.parametrize("set_name", ["rotation_grail", "rotation_parrington"])
def test_session_exposures_find_the_session_light_of_real_photos(real_data_dir, set_name, exposure):
    """At the photos' own light the session gain is 1 and the paper's result is kept
    crop for crop; at half light it is 2 and the yaws are found (the paper's mode
    loses them: 36° and 68° median)."""
    photos = load_rotation_set(real_data_dir / set_name)
    paper = evaluate_rotation_set(photos, CompassConfig(n_colors=10))
    full = evaluate_rotation_set(photos, CompassConfig(n_colors=10, exposure=exposure))
    assert full["session_gain"] == 1.0
    assert full["errors_deg"] == paper["errors_deg"]
    half = evaluate_rotation_set(photos, CompassConfig(n_colors=10, exposure=exposure), light=0.5)
    assert half["session_gain"] == 2.0
    assert half["median_error_deg"] < 2.0 and half["within_10deg"] >= 0.75, half["errors_deg"]
