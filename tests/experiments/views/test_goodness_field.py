"""The goodness of one spot's map over the field (paper fig. 5 right)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.goodness_field import plot_goodness_field
from vc_gym.experiments.views.poses import field_grid, view_poses

FIELD = (-3.0, 3.0, -2.0, 2.0)
SPOT = (-1.5, 0.0)


def _is_png(path) -> bool:
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_plot_writes_pngs(tmp_path):
    rng = np.random.default_rng(1)
    poses = view_poses(field_grid(FIELD, 0.66), 1, rng)
    dist = np.hypot(poses[:, 0] - SPOT[0], poses[:, 1] - SPOT[1])
    grid = field_grid(FIELD, 0.5)
    goodness = np.exp(-0.05 * np.hypot(grid[:, 0] - SPOT[0], grid[:, 1] - SPOT[1]))
    plot_goodness_field(tmp_path / "good.png", grid, goodness, SPOT, FIELD)
    plot_goodness_field(
        tmp_path / "scatter.png",
        poses[:, :2] + 0.01 * rng.normal(size=(len(poses), 2)),
        dist,
        SPOT,
        FIELD,
    )
    for name in ("good", "scatter"):
        assert _is_png(tmp_path / f"{name}.png"), name
    with pytest.raises(ValueError, match="goodness"):
        plot_goodness_field(tmp_path / "x.png", grid, goodness[:-1], SPOT, FIELD)
    with pytest.raises(ValueError, match="spot must be"):
        plot_goodness_field(tmp_path / "x.png", grid, goodness, [SPOT, SPOT], FIELD)
    assert not (tmp_path / "x.png").exists()
