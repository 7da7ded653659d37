"""Tests of vc_gym.worlds.rays: the per-pixel camera rays both renderers cast."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.compass.camera import Camera
from vc_gym.worlds.rays import RayGrid, ray_grid


def test_centre_column_looks_at_the_yaw_and_the_centre_row_at_the_pitch() -> None:
    for pitch in (0.0, 12.5, -30.0):
        rays = ray_grid(Camera(hfov_deg=60.0, yaw_deg=123.0, pitch_deg=pitch), 201, 151)
        assert rays.azimuth_offset_deg[75, 100] == pytest.approx(0.0, abs=1e-12)
        assert rays.elevation_deg[75, 100] == pytest.approx(pitch, abs=1e-12)


def test_image_edges_look_half_the_field_of_view_aside() -> None:
    # with cx = W/2 - 1 the centre of the last column is W/2 pixels right of the
    # principal point: x = tan(hfov/2), so it looks exactly hfov/2 to the right
    hfov, w, h = 56.9, 208, 160
    cam = Camera(hfov_deg=hfov, principal_point=(w / 2 - 1.0, (h - 1) / 2))
    rays = ray_grid(cam, w, h)
    row = (h - 1) // 2
    assert rays.azimuth_offset_deg[row, w - 1] == pytest.approx(-hfov / 2, abs=1e-9)
    # and the column W/2 pixels left of it looks hfov/2 to the left
    cam = Camera(hfov_deg=hfov, principal_point=(w / 2, (h - 1) / 2))
    assert ray_grid(cam, w, h).azimuth_offset_deg[row, 0] == pytest.approx(hfov / 2, abs=1e-9)


def test_columns_follow_the_design_convention_at_zero_pitch() -> None:
    # docs/design.md: direction(u) = yaw - degrees(atan((u - cx) / f)), f = (W/2) / tan(hfov/2)
    hfov, w, h = 70.0, 160, 90
    cam = Camera(hfov_deg=hfov)
    f = (w / 2) / math.tan(math.radians(hfov / 2))
    cx = (w - 1) / 2
    expected = -np.degrees(np.arctan((np.arange(w) - cx) / f))
    rays = ray_grid(cam, w, h)
    for row in (0, h // 2, h - 1):  # without pitch every row looks the same way
        np.testing.assert_allclose(rays.azimuth_offset_deg[row], expected, atol=1e-12)
    assert np.all(np.diff(rays.azimuth_offset_deg[0]) < 0)  # rightwards = clockwise


def test_rows_look_down_the_image_and_match_the_camera_offsets_with_pitch() -> None:
    w, h = 120, 100
    cam = Camera(hfov_deg=80.0, pitch_deg=25.0)
    rays = ray_grid(cam, w, h)
    assert np.all(np.diff(rays.elevation_deg[:, w // 2]) < 0)  # rows further down look lower
    columns = np.arange(w, dtype=float)
    for row in (0, 37, h - 1):
        np.testing.assert_allclose(
            rays.azimuth_offset_deg[row], cam.column_offsets_deg(columns, w, h, row=row), atol=1e-9
        )


def test_vectors_and_angles_agree() -> None:
    rays = ray_grid(Camera(hfov_deg=90.0, pitch_deg=-15.0, principal_point=(20.0, 10.0)), 64, 48)
    np.testing.assert_allclose(
        rays.azimuth_offset_deg, np.degrees(np.arctan2(rays.left, rays.forward)), atol=1e-12
    )
    horizontal = np.hypot(rays.forward, rays.left)
    np.testing.assert_allclose(
        rays.elevation_deg, np.degrees(np.arctan2(rays.up, horizontal)), atol=1e-12
    )
    # pitching keeps the ray length of the camera-frame ray (x, y_up, 1)
    f = 32.0  # (W/2) / tan(45 deg)
    x = (np.arange(64) - 20.0) / f
    y_up = (10.0 - np.arange(48)) / f
    length = np.sqrt(1.0 + x[None, :] ** 2 + y_up[:, None] ** 2)
    np.testing.assert_allclose(np.sqrt(horizontal**2 + rays.up**2), length, rtol=1e-12)


def test_grid_is_read_only_shaped_and_shared_across_yaws() -> None:
    a = ray_grid(Camera(yaw_deg=0.0), 208, 160)
    b = ray_grid(Camera(yaw_deg=77.0), 208, 160)
    assert isinstance(a, RayGrid)
    assert a is b  # the yaw is not part of the grid: one cached grid for every heading
    for field in a:
        assert field.shape == (160, 208)
        assert field.dtype == np.float64
        assert not field.flags.writeable
    assert a.azimuth_offset_deg.flags.c_contiguous and a.elevation_deg.flags.c_contiguous
    assert ray_grid(Camera(pitch_deg=1.0), 208, 160) is not a


@pytest.mark.parametrize("args", [(0, 10), (10, 0), (10.0, 10), (10, "10"), (True, 10)], ids=str)
def test_bad_sizes_are_refused(args) -> None:
    with pytest.raises(ValueError, match="width|height"):
        ray_grid(Camera(), *args)


def test_needs_a_camera() -> None:
    with pytest.raises(TypeError, match="Camera"):
        ray_grid(56.9, 208, 160)  # type: ignore[arg-type]
