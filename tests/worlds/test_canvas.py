"""Tests of vc_gym.worlds.canvas: the one painting surface of panoramas and textures."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.angles import wrap360
from vc_gym.worlds.canvas import Canvas


def test_canvas_is_measured_in_metres_with_y_up():
    c = Canvas(2.0, 1.0, 10.0, (0, 0, 0))
    c.rect(0.0, 0.5, 0.0, 0.2, (255, 0, 0))  # bottom-left corner
    img = c.image()
    assert img.shape == (10, 20, 3)
    assert tuple(img[-1, 0]) == (255, 0, 0) and tuple(img[0, 0]) == (0, 0, 0)
    assert tuple(img[-2, 4]) == (255, 0, 0) and tuple(img[-3, 4]) == (0, 0, 0)


def test_background_and_coordinates_of_a_metric_canvas():
    c = Canvas(2.0, 1.0, 10.0, (10, 20, 30))
    assert c.img.dtype == np.float32 and c.img.shape == (10, 20, 3)
    assert np.all(c.img == np.float32([10, 20, 30]))
    np.testing.assert_allclose(c.column_coords, (np.arange(20) + 0.5) / 10.0)
    np.testing.assert_allclose(c.row_coords, 1.0 - (np.arange(10) + 0.5) / 10.0)
    assert not c.wraps
    with pytest.raises(ValueError, match="> 0"):
        Canvas(0.0, 1.0, 10.0, (0, 0, 0))


def test_panorama_canvas_looks_where_the_panorama_convention_says():
    c = Canvas.panorama(720, 180, 45.0, -45.0, 10.0)
    assert c.img.shape == (180, 720, 3) and not c.img.any()  # black background
    assert c.wraps and (c.width_m, c.height_m) == (360.0, 90.0)
    np.testing.assert_array_equal(
        c.column_coords, wrap360(10.0 - 360.0 * (np.arange(720) + 0.5) / 720)
    )
    assert c.row_coords.dtype == np.float32
    np.testing.assert_allclose(c.row_coords, 45.0 - 90.0 * (np.arange(180) + 0.5) / 180)


def test_columns_wrap_around_the_seam_of_a_panorama():
    c = Canvas.panorama(360, 90)  # column k looks at azimuth -(k + 0.5) mod 360
    cols, rel = c.columns(0.0, 2.0)
    assert cols.tolist() == [0, 1, 358, 359]
    np.testing.assert_allclose(rel, [-0.5, -1.5, 1.5, 0.5])  # positive: left (CCW)
    metric = Canvas(2.0, 1.0, 10.0, (0, 0, 0))
    cols, rel = metric.columns(0.0, 0.2)  # no wrap on a flat surface
    assert cols.tolist() == [0, 1]
    np.testing.assert_allclose(rel, [0.05, 0.15])


@pytest.mark.parametrize("centre", [0.0, 180.0])  # across the seam, and inside
def test_paint_sets_only_the_masked_pixels_of_the_columns(centre):
    c = Canvas.panorama(360, 90)
    cols, rel = c.columns(centre, 3.0)
    mask = (c.row_coords[:, None] > 0.0) & (rel[None, :] > 0.0)
    c.paint(cols, mask, np.float32([200, 100, 50]))
    painted = np.zeros((90, 360), bool)
    painted[:, cols] = mask
    np.testing.assert_array_equal(c.img[painted], np.tile([200, 100, 50], (painted.sum(), 1)))
    assert not c.img[~painted].any()
    c.paint(cols[:0], mask[:, :0], np.float32([1, 1, 1]))  # nothing to paint
    assert c.img[painted].sum() == painted.sum() * 350


def test_image_rounds_and_clips_without_changing_the_canvas():
    c = Canvas(0.2, 0.2, 10.0, (0, 0, 0))
    c.img[0, 0] = (-3.0, 127.5, 300.0)
    c.img[0, 1] = (0.49, 254.5, 255.6)
    out = c.image()
    assert out.dtype == np.uint8
    assert out[0, 0].tolist() == [0, 128, 255] and out[0, 1].tolist() == [0, 254, 255]
    assert c.img[0, 0, 2] == 300.0
