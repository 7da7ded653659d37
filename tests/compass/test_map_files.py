"""A map as plain arrays and back: every entry written is read and checked."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import (
    Camera,
    CompassConfig,
    MapFileError,
    VisualCompass,
    map_files,
    visual_compass,
)
from vc_gym.compass.light_map import LightMap
from vc_gym.compass.map_files import (
    MAX_LEARNED_SIZES,
    MapContents,
    check_learned_sizes,
    map_arrays,
    read_config_and_colors,
    read_light_map,
    read_map_contents,
    read_map_file,
    write_map_file,
)
from vc_gym.worlds.panorama import render_view

MAP = CompassConfig(n_colors=3, exposure="map")


@pytest.fixture(scope="module")
def map_compass(room_pano) -> VisualCompass:
    vc = VisualCompass(MAP)
    vc.fit_colors([render_view(room_pano, Camera(yaw_deg=a)) for a in range(0, 360, 90)])
    for yaw in range(0, 360, 60):
        vc.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    return vc


def test_contents_survive_the_arrays_and_the_file(map_compass, tmp_path):
    arrays = map_compass.to_arrays()
    path = write_map_file(tmp_path / "m", arrays)
    assert path.name == "m.npz"
    read = read_map_file(path)
    config, colors = read_config_and_colors(read, path)
    assert config == MAP and colors.n_colors == 3
    contents = read_map_contents(read, path, config)
    np.testing.assert_array_equal(contents.counts, map_compass.map_counts)
    np.testing.assert_array_equal(contents.sector_observations, map_compass.sector_observations)
    assert contents.frames_learned == map_compass.frames_learned == 6
    assert contents.learned_sizes == {(160, 208)}
    assert contents.exposure_reference == 0.0
    np.testing.assert_array_equal(contents.light.level_sum, map_compass._light.level_sum)
    again = map_arrays(config, contents, colors)
    assert list(again) == list(arrays)  # the same entries, in the order they are written
    for key in arrays:
        np.testing.assert_array_equal(again[key], arrays[key])


def test_without_colours_only_the_map_is_written(map_compass):
    contents = MapContents(
        counts=map_compass.map_counts,
        sector_observations=map_compass.sector_observations,
        frames_learned=map_compass.frames_learned,
        exposure_reference=0.0,
        learned_sizes={(160, 208)},
        light=LightMap(MAP.n_sectors),
    )
    arrays = map_arrays(MAP, contents)
    assert not any(k.startswith("colors") for k in arrays)
    assert arrays["counts"].dtype == np.uint32 and "light_sum" in arrays
    plain = map_arrays(CompassConfig(n_colors=3), contents)
    assert "light_sum" not in plain  # the light is kept only with exposure="map"


def test_a_light_map_above_white_is_refused(map_compass):
    arrays = dict(map_compass.to_arrays())
    arrays["light_sum"] = arrays["light_columns"] * 2 + 1
    with pytest.raises(MapFileError, match="f.npz: light_sum exceeds light_columns"):
        read_light_map(arrays, "f.npz", MAP.n_sectors)
    with pytest.raises(MapFileError, match="needs entry 'light_columns'"):
        read_light_map({"light_sum": arrays["light_columns"]}, "f.npz", MAP.n_sectors)


def test_too_many_frame_sizes_are_refused():
    check_learned_sizes({(h, 1) for h in range(1, MAX_LEARNED_SIZES + 1)})
    with pytest.raises(ValueError, match=f"at most {MAX_LEARNED_SIZES} different sizes"):
        check_learned_sizes({(h, 1) for h in range(1, MAX_LEARNED_SIZES + 2)})


def test_the_file_constants_are_importable_from_the_compass_module():
    for name in ("MAP_SCHEMA", "MAP_SCHEMA_VERSION", "MAX_LEARNED_SIZES"):
        assert getattr(visual_compass, name) is getattr(map_files, name)
