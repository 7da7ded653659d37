"""The views package's public face: every name the studies use, from one place.

The modules themselves are tested in tests/experiments/views/ (one test file a module).
"""

from __future__ import annotations

import importlib

import vc_gym.experiments.views as views

#: Where each public name of the package is defined.
HOMES = {
    "COMPASS": "evaluation",
    "PAPER_ERROR_DEG": "error_vs_distance",
    "PAPER_RANGE_M": "error_vs_distance",
    "Frame": "frames",
    "distance_table": "error_vs_distance",
    "evaluate_view": "evaluation",
    "field_grid": "poses",
    "learning_turn": "frames",
    "frames_at_pose": "frames",
    "plot_arrow_field": "arrow_field",
    "plot_error_vs_distance": "error_vs_distance",
    "plot_goodness_field": "goodness_field",
    "spot_goodness": "evaluation",
    "spots_array": "checks",
    "view_poses": "poses",
}


def test_the_package_exports_each_name_from_its_module():
    assert sorted(views.__all__) == sorted(HOMES)
    for name, module in HOMES.items():
        home = importlib.import_module(f"vc_gym.experiments.views.{module}")
        assert getattr(views, name) is getattr(home, name), name
        assert name in home.__all__, name
