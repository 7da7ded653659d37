"""A baseline sensor file whose config cannot even be allocated is a MapFileError."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.compass import Camera
from vc_gym.errors import MapFileError
from vc_gym.heading_sensors.sector_color import SectorColorCompass
from vc_gym.worlds.panorama import render_view


def test_a_config_too_large_to_allocate_is_a_map_file_error(room_pano, tmp_path):
    sc = SectorColorCompass(model="histogram")
    sc.learn(render_view(room_pano, Camera(yaw_deg=10.0)), Camera(yaw_deg=10.0))
    path = sc.save(tmp_path / "sensor.npz")
    with np.load(path, allow_pickle=False) as d:
        arrays = {k: d[k] for k in d.files}
    config = json.loads(str(arrays["config"]))
    config["n_bins"] = 10**12  # 1.7 PiB of histograms
    arrays["config"] = np.array(json.dumps(config))
    np.savez(tmp_path / "huge.npz", **arrays)
    with pytest.raises(MapFileError, match="huge.npz: bad config.*n_bins"):
        SectorColorCompass.load(tmp_path / "huge.npz")
