import math

import numpy as np
import pytest

from vc_gym.compass import Camera


def test_direction_convention():
    cam = Camera(hfov_deg=90.0, yaw_deg=30.0)
    w, h = 201, 101
    d = cam.column_directions_deg(np.array([0.0, 100.0, 200.0]), w, h)
    # left edge looks 45 deg to the left (larger yaw), right edge 45 deg to the right
    assert d == pytest.approx([75.0, 30.0, -15.0], abs=0.5)


def test_focal_and_from_focal_round_trip():
    cam = Camera.from_focal(628.0, 384, yaw_deg=10.0)
    assert cam.focal_px(384) == pytest.approx(628.0)
    assert cam.hfov_deg == pytest.approx(2 * math.degrees(math.atan(192 / 628)))


def test_pitch_moves_horizon_down():
    w, h = 208, 160
    assert Camera().horizon_row(w, h) == pytest.approx((h - 1) / 2)
    assert Camera(pitch_deg=10.0).horizon_row(w, h) > Camera().horizon_row(w, h)
    assert Camera(pitch_deg=-10.0).horizon_row(w, h) < Camera().horizon_row(w, h)


def test_principal_point_crop():
    full = Camera.from_focal(600.0, 400)
    crop = Camera.from_focal(600.0, 100, principal_point=(199.5 - 150, 49.5))
    # column 150 of the full image is column 0 of the crop
    a = full.column_offsets_deg(np.array([150.0, 249.0]), 400, 100)
    b = crop.column_offsets_deg(np.array([0.0, 99.0]), 100, 100)
    assert a == pytest.approx(b)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"hfov_deg": 0.0},
        {"hfov_deg": 180.0},
        {"hfov_deg": float("nan")},
        {"yaw_deg": float("inf")},
        {"pitch_deg": 90.0},
        {"principal_point": (1.0,)},
        {"principal_point": (1.0, float("nan"))},
        {"hfov_deg": True},  # a bool, not a 1-degree lens
        {"hfov_deg": "56.9"},  # refused here, not failing later
        {"yaw_deg": 1e17},  # beyond float precision: would learn 4 of 14 sectors
        {"yaw_deg": -1e300},
        {"pitch_deg": False},
    ],
)
def test_bad_camera(kwargs):
    with pytest.raises(ValueError, match="hfov_deg|yaw_deg|pitch_deg|principal_point|cx|cy"):
        Camera(**kwargs)


def test_a_large_but_exact_yaw_is_the_same_direction():
    far = Camera(yaw_deg=360.0 * 10**6 + 30.0)
    assert far.column_directions_deg(np.array([103.5]), 208, 160)[0] % 360 == pytest.approx(30.0)
