"""Heading error against distance from the spot (paper fig. 4 right): the table on a known
answer and its plot."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.error_vs_distance import distance_table, plot_error_vs_distance
from vc_gym.experiments.views.poses import field_grid, view_poses

FIELD = (-3.0, 3.0, -2.0, 2.0)
SPOT = (-1.5, 0.0)


def test_distance_table_known_answer():
    rows = distance_table(
        [0.1, 0.3, 0.6, 2.2, 2.4],
        [1.0, -3.0, 350.0, 20.0, -40.0],  # 350° is a -10° error
        [2.0, 4.0, 6.0, 8.0, 10.0],
        bin_m=0.5,
    )
    assert [(r["bin_start_m"], r["bin_end_m"], r["n"]) for r in rows] == [
        (0.0, 0.5, 2),
        (0.5, 1.0, 1),
        (2.0, 2.5, 2),
    ]
    assert [r["mean_abs_error_deg"] for r in rows] == pytest.approx([2.0, 10.0, 30.0])
    assert [r["median_abs_error_deg"] for r in rows] == pytest.approx([2.0, 10.0, 30.0])
    assert [r["mean_spread_deg"] for r in rows] == pytest.approx([3.0, 6.0, 9.0])
    assert [r["distance_m"] for r in rows] == pytest.approx([0.2, 0.6, 2.3])
    assert distance_table([], [], []) == []
    for bad, match in [
        (([0.1, 0.2], [1.0], [1.0, 1.0]), "one length"),
        (([-0.1], [1.0], [1.0]), ">= 0"),
        (([0.1], [float("nan")], [1.0]), "errors"),
        (([0.1], [1.0], [1.0], 0.0), "bin_m"),
    ]:
        with pytest.raises(ValueError, match=match):
            distance_table(*bad)


def _is_png(path) -> bool:
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_plot_writes_a_png(tmp_path):
    rng = np.random.default_rng(1)
    poses = view_poses(field_grid(FIELD, 0.66), 1, rng)
    dist = np.hypot(poses[:, 0] - SPOT[0], poses[:, 1] - SPOT[1])
    errors = rng.normal(0.0, 2.0 + 8.0 * dist)
    table = distance_table(dist, errors, 5.0 + 20.0 * dist)
    plot_error_vs_distance(tmp_path / "err.png", {"grid": table, "kalman": table[:-1]})
    assert _is_png(tmp_path / "err.png")
    with pytest.raises(ValueError, match="table_by_tracker"):
        plot_error_vs_distance(tmp_path / "x.png", {})
    assert not (tmp_path / "x.png").exists()
