"""Which scanned columns fall into which sector: the geometry behind eq. 13-14."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassConfig
from vc_gym.compass.scan_geometry import (
    GEOMETRY_CACHE_SIZE,
    ScanGeometryCache,
    column_sectors,
    scan_geometry,
)

CONFIG = CompassConfig(n_colors=3)
HEADINGS = np.arange(CONFIG.n_headings, dtype=np.float64) * CONFIG.heading_step_deg


@pytest.mark.parametrize(
    "camera", [Camera(), Camera(pitch_deg=8.0), Camera(hfov_deg=90.0, principal_point=(70.0, 60.0))]
)
def test_every_scanned_column_falls_into_one_relative_sector_per_phase(camera):
    geom = scan_geometry(camera, 208, 160, CONFIG, HEADINGS)
    delta = CONFIG.sector_deg
    s0 = np.floor(HEADINGS / delta + 1e-9)
    phases = np.unique(np.round(HEADINGS - s0 * delta, 9))
    cols = np.arange(geom.grid.cols.size)
    for p, phase in enumerate(phases):
        k = np.floor((phase + geom.grid.offsets_deg) / delta).astype(int) - geom.kmin
        for rel in range(geom.n_rel):
            r = p * geom.n_rel + rel
            # the columns of a relative sector are one contiguous run [first, stop)
            np.testing.assert_array_equal(
                cols[geom.first_col[r] : geom.stop_col[r]], np.flatnonzero(k == rel)
            )
    assert geom.heading_phase.shape == geom.heading_sector.shape == HEADINGS.shape
    assert geom.roll_index.shape == (geom.n_rel, CONFIG.n_sectors)


def test_headings_on_a_sector_boundary_share_one_phase():
    geom = scan_geometry(Camera(), 208, 160, CONFIG, HEADINGS)
    on_boundary = np.isclose(HEADINGS % CONFIG.sector_deg, 0.0)
    assert np.unique(geom.heading_phase[on_boundary]).size == 1
    np.testing.assert_array_equal(
        geom.heading_sector[on_boundary], HEADINGS[on_boundary] / CONFIG.sector_deg
    )


def test_the_cache_keeps_the_recent_cameras_and_sizes():
    cache = ScanGeometryCache(CONFIG, HEADINGS)
    first = cache.get(Camera(), 208, 160)
    assert cache.get(Camera(yaw_deg=33.0), 208, 160) is first  # the yaw does not matter
    for width in range(100, 100 + GEOMETRY_CACHE_SIZE):
        cache.get(Camera(), width, 80)
    assert len(cache) == GEOMETRY_CACHE_SIZE
    assert cache.get(Camera(), 208, 160) is not first  # the oldest entry was dropped


def test_column_sectors_wrap_around_zero():
    # -9 deg is exactly on a boundary: it opens sector -2 (78), not the one before
    sectors = column_sectors(1.0, np.array([10.0, 0.0, -2.0, -10.0]), 4.5, 80)
    np.testing.assert_array_equal(sectors, [2, 0, 79, 78])
    assert sectors.dtype == np.int64
