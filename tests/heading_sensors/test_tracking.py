"""load_sensor on damaged and foreign files: a MapFileError naming the file, nothing else."""

from __future__ import annotations

from pathlib import Path

import pytest

from vc_gym.compass import Camera
from vc_gym.errors import MapFileError
from vc_gym.heading_sensors import load_sensor, make_sensor
from vc_gym.worlds.panorama import Panorama, render_view

#: The image baselines that save and load a learned map, by their registry name.
IMAGE_BASELINES = ("image_difference", "sector_color", "feature")

#: Places of a saved file at which one byte is flipped in turn.
FLIPS = 30


def _learned_file(name: str, pano: Panorama, folder: Path) -> Path:
    """``name`` learned on ``pano`` every 30 degrees and saved in ``folder``."""
    sensor = make_sensor(name)
    for yaw in range(0, 360, 30):
        sensor.learn(render_view(pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    return sensor.save(folder / f"{name}.npz")


@pytest.fixture(scope="module")
def saved(room_pano: Panorama, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each image baseline's saved file, by its registry name."""
    folder = tmp_path_factory.mktemp("sensors")
    return {name: _learned_file(name, room_pano, folder) for name in IMAGE_BASELINES}


@pytest.mark.parametrize("name", IMAGE_BASELINES)
def test_a_file_with_a_flipped_byte_loads_or_is_a_map_file_error(
    name: str, saved: dict[str, Path], tmp_path: Path
) -> None:
    data = saved[name].read_bytes()
    path = tmp_path / "flipped.npz"
    for i in range(0, len(data), max(1, len(data) // FLIPS)):
        flipped = bytearray(data)
        flipped[i] ^= 0xFF
        path.write_bytes(bytes(flipped))
        try:
            load_sensor(name, path)
        except MapFileError:
            pass


# the feature compass given the image difference's file: test_sensor_registry.py
@pytest.mark.parametrize("name", ["image_difference", "sector_color"])
def test_another_sensors_file_is_refused_naming_the_file(name: str, saved: dict[str, Path]) -> None:
    with pytest.raises(MapFileError, match="feature.npz"):
        load_sensor(name, saved["feature"])
