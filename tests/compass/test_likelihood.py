"""The likelihood functions on arrays: tables, features, several maps at once."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassConfig, VisualCompass
from vc_gym.compass.likelihood import (
    heading_estimates,
    log_likelihoods,
    log_tables,
    remapped_log_likelihoods,
    sector_features,
)
from vc_gym.worlds.panorama import render_view

CONFIG = CompassConfig(n_colors=3)


@pytest.fixture(scope="module")
def two_maps(room_pano) -> list[VisualCompass]:
    """Two maps with one colour set: all of the room, and half of it."""
    first = VisualCompass(CONFIG)
    first.fit_colors([render_view(room_pano, Camera(yaw_deg=a)) for a in range(0, 360, 90)])
    second = VisualCompass(CONFIG, first.colors)
    for yaw in range(0, 360, 40):
        first.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
        if yaw < 180:
            second.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    return [first, second]


def test_log_tables_are_normalised_histograms(two_maps):
    vc = two_maps[1]
    delta_t, base, log_abs = log_tables(CONFIG, vc.map_counts, vc.sector_observations * 1.0)
    np.testing.assert_allclose(np.exp(log_abs).sum(axis=2), 1.0)
    n = CONFIG.n_bins
    empty_bin_rows = np.arange(CONFIG.n_colors**2) * n + n - 1
    assert not delta_t[empty_bin_rows].any()  # only non-zero frequencies need a read
    assert base.shape == (CONFIG.n_sectors,)
    np.testing.assert_array_equal(log_abs, vc.sector_log_probabilities())


def test_several_maps_score_each_as_it_would_alone(two_maps, room_pano):
    image = render_view(room_pano, Camera(yaw_deg=123.0))
    first = two_maps[0]
    geom, counts, total = first._sector_features(image, Camera())
    tables = [vc._log_tables() for vc in two_maps]
    delta_t = np.stack([t[0] for t in tables], axis=1)
    base = np.stack([t[1] for t in tables])
    lls = log_likelihoods(CONFIG, geom, counts, total, delta_t, base)
    for row, vc in zip(lls, two_maps, strict=True):
        np.testing.assert_array_equal(row, vc.log_likelihood(image, Camera()))
    only_second = log_likelihoods(CONFIG, geom, counts, total, delta_t, base, np.array([1]))
    np.testing.assert_array_equal(only_second[0], lls[1])
    heading, spread, scores, n_sectors = heading_estimates(
        CONFIG, first.headings_deg, [t[2] for t in tables], geom, counts, total, lls
    )
    for k, vc in enumerate(two_maps):
        est = vc.estimate(image, Camera())
        assert (heading[k], spread[k], scores[k], n_sectors[k]) == (
            est.heading_deg,
            est.spread_deg,
            est.score,
            est.n_sectors,
        )


def test_the_identity_remapping_is_the_plain_log_likelihood(two_maps, room_pano):
    vc = two_maps[0]
    image = render_view(room_pano, Camera(yaw_deg=250.0))
    geom, counts, total = vc._sector_features(image, Camera())
    delta_t, base, _ = vc._log_tables()
    n = CONFIG.n_sectors
    remaps = np.stack([np.arange(n), np.roll(np.arange(n), 5)])
    lls = remapped_log_likelihoods(CONFIG, geom, counts, total, delta_t, base, remaps)
    assert lls.shape == (2, CONFIG.n_headings)
    np.testing.assert_array_equal(lls[0], vc.log_likelihood(image, Camera()))
    assert not np.array_equal(lls[1], lls[0])


def test_a_frame_without_class_changes_has_no_features(two_maps):
    geom = two_maps[0]._geometry(Camera(), 208, 160)
    shape = (geom.grid.rows.size, geom.grid.cols.size)
    counts, total = sector_features(np.zeros(shape, np.uint8), geom, CONFIG)
    assert counts.shape == (geom.first_col.size, CONFIG.n_colors**2)
    assert not counts.any() and not total.any()
    # wide horizontal stripes: a class change in every column, far from noise
    striped = np.repeat((np.arange(shape[0]) // 8 % 2).astype(np.uint8)[:, None], shape[1], 1)
    counts, total = sector_features(striped, geom, CONFIG)
    np.testing.assert_array_equal(total, counts.sum(axis=1))
    assert total.any()
