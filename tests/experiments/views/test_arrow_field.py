"""The arrow field of heading estimates (paper fig. 4 left)."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.arrow_field import plot_arrow_field
from vc_gym.experiments.views.poses import field_grid, view_poses

FIELD = (-3.0, 3.0, -2.0, 2.0)
SPOT = (-1.5, 0.0)


def _is_png(path) -> bool:
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_plot_writes_pngs(tmp_path):
    rng = np.random.default_rng(1)
    poses = view_poses(field_grid(FIELD, 0.66), 1, rng)
    dist = np.hypot(poses[:, 0] - SPOT[0], poses[:, 1] - SPOT[1])
    estimated = poses[:, 2] + rng.normal(0.0, 2.0 + 8.0 * dist)
    plot_arrow_field(tmp_path / "arrows.png", poses, estimated, SPOT, FIELD, "fig. 4 left")
    plot_arrow_field(tmp_path / "ref.png", poses, estimated, SPOT, FIELD, "ref", reference_deg=0)
    spots = [(-1.5, 0.0), (1.5, 1.0)]
    plot_arrow_field(tmp_path / "spots.png", poses, estimated, spots, FIELD, "several spots")
    for name in ("arrows", "ref", "spots"):
        assert _is_png(tmp_path / f"{name}.png"), name
    with pytest.raises(ValueError, match="estimated_headings"):
        plot_arrow_field(tmp_path / "x.png", poses, estimated[:-1], SPOT, FIELD, "x")
    with pytest.raises(ValueError, match="poses"):
        plot_arrow_field(tmp_path / "x.png", poses[:, :2], estimated, SPOT, FIELD, "x")
    with pytest.raises(ValueError, match="field_bounds"):
        plot_arrow_field(tmp_path / "x.png", poses, estimated, SPOT, (1, 0, 0, 1), "x")
    assert not (tmp_path / "x.png").exists()
