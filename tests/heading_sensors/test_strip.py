"""angular_strip: a pinhole image resampled onto world directions, checked on panoramas."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera
from vc_gym.heading_sensors.strip import StripGrid, angular_strip, strip_offsets
from vc_gym.worlds.panorama import render_view


def _panorama_at(pano, yaw, offsets, grid):
    """The panorama's pixels in the strip's directions (nearest neighbour)."""
    cols = np.round(pano.column_of_azimuth(yaw + offsets * grid.az_step_deg)).astype(int)
    rows = np.round(pano.row_of_elevation(grid.elevations_deg)).astype(int)
    return pano.image[rows][:, cols % pano.width].astype(np.float64)


@pytest.mark.parametrize("pitch", [0.0, 12.0, -8.0])
def test_strip_shows_the_directions_it_claims(room_pano, pitch):
    grid = StripGrid()
    cam = Camera(yaw_deg=30.0, pitch_deg=pitch)
    strip, valid, off = angular_strip(render_view(room_pano, cam), cam, grid)
    assert valid.mean() > 0.3
    ref = _panorama_at(room_pano, 30.0, off, grid)
    aligned = np.abs(ref - strip)[valid].mean()
    shifted = np.abs(_panorama_at(room_pano, 34.0, off, grid) - strip)[valid].mean()
    assert aligned < 0.6 * shifted, (aligned, shifted)


def test_left_offsets_look_at_larger_yaws(room_pano):
    # the view at yaw 30 seen j deg left of its centre is the view at yaw 40 seen j - 10
    grid = StripGrid()
    a, va, oa = angular_strip(render_view(room_pano, Camera(yaw_deg=30.0)), Camera(), grid)
    b, vb, ob = angular_strip(render_view(room_pano, Camera(yaw_deg=40.0)), Camera(), grid)

    def diff(shift):
        d = []
        for j in range(-5, 15):
            ia, ib = list(oa).index(j), list(ob).index(j + shift)
            both = va[:, ia] & vb[:, ib]
            d.append(np.abs(a[both, ia] - b[both, ib]).mean())
        return np.mean(d)

    assert diff(-10) < 0.5 * diff(10), (diff(-10), diff(10))


def test_a_crop_keeps_its_directions(room_pano):
    grid = StripGrid()
    cam = Camera(yaw_deg=0.0)
    full = render_view(room_pano, cam, width=208, height=160)
    crop = np.ascontiguousarray(full[:, :104])
    f = cam.focal_px(208)  # a crop keeps the focal length and moves the principal point
    crop_cam = Camera.from_focal(f, 104, principal_point=(103.5, 79.5))
    s_full, v_full, o_full = angular_strip(full, cam, grid)
    s_crop, v_crop, o_crop = angular_strip(crop, crop_cam, grid)
    assert o_crop.max() >= 20  # the crop is the left half: it sees up to ~28 deg left
    for j in (5, 15, 25):
        both = v_full[:, list(o_full).index(j)] & v_crop[:, list(o_crop).index(j)]
        diff = s_full[both, list(o_full).index(j)] - s_crop[both, list(o_crop).index(j)]
        assert np.abs(diff).mean() < 3.0


def test_offsets_cover_the_view():
    off = strip_offsets(Camera(hfov_deg=56.9), 208, StripGrid(az_step_deg=1.0))
    assert off.min() <= -28 and off.max() >= 28 and off.size < 180


@pytest.mark.parametrize(
    "kwargs",
    [
        {"az_step_deg": 7.0},
        {"az_step_deg": 0.0},
        {"el_min_deg": 10.0, "el_max_deg": 5.0},
        {"el_max_deg": 95.0},
        {"el_step_deg": -1.0},
        {"el_min_deg": float("nan")},
    ],
)
def test_bad_grids_are_refused(kwargs):
    with pytest.raises(ValueError):
        StripGrid(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"el_step_deg": 1e-9}, "elevation rows"),  # would be 4e10 rows
        ({"az_step_deg": 1e-6}, "az_step_deg must be >="),  # would be 3.6e8 azimuths
    ],
)
def test_a_grid_cannot_be_made_to_exhaust_memory(kwargs, match):
    with pytest.raises(ValueError, match=match):
        StripGrid(**kwargs)
