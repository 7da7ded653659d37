"""Where the robot is put: the field grid (paper 5.1: ~33 cm) and random headings."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.experiments.views.poses import field_grid, view_poses

#: robolab's field
FIELD = (-3.0, 3.0, -2.0, 2.0)


def test_field_grid_known_answers():
    g = field_grid(FIELD, 0.5)  # 0.25 margin: 5.5 x 3.5 m at 0.5 m
    assert g.shape == (12 * 8, 2) and g.dtype == np.float64
    assert g[0].tolist() == [-2.75, -1.75] and g[-1].tolist() == [2.75, 1.75]
    assert g[1].tolist() == [-2.75, -1.25]  # ordered by x, then y
    # spare length split evenly: 1 m at 0.4 m -> 0.1, 0.5, 0.9
    np.testing.assert_allclose(np.unique(field_grid((0, 1, 0, 1), 0.4, 0.0)[:, 0]), [0.1, 0.5, 0.9])
    one = field_grid((0.0, 1.0, 0.0, 2.0), 0.3, margin_m=0.5)  # x extent exactly used up
    np.testing.assert_allclose(np.unique(one[:, 0]), [0.5])
    paper = field_grid((-3.0, 0.0, -1.5, 1.5), 0.33, 0.0)  # 3 x 3 m at ~33 cm (5.1)
    assert paper.shape == (10 * 10, 2)


@pytest.mark.parametrize(
    "args, match",
    [
        (((0, 1, 0), 0.5), "bounds"),
        (((1, 0, 0, 1), 0.5), "xmin < xmax"),
        (((0, 1, 0, float("nan")), 0.5), "finite"),
        (("abcd", 0.5), "bounds"),
        (((0, 1, 0, 1), 0.0), "spacing_m"),
        (((0, 1, 0, 1), float("inf")), "spacing_m"),
        (((0, 1, 0, 1), 0.5, -0.1), "margin_m"),
        (((0, 1, 0, 1), 0.5, 0.6), "margin_m"),
        (((0, 6, 0, 4), 1e-5), "too many"),
    ],
)
def test_field_grid_rejects_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        field_grid(*args)


def test_view_poses():
    positions = field_grid(FIELD, 1.0)
    poses = view_poses(positions, 3, np.random.default_rng(0))
    assert poses.shape == (3 * len(positions), 3)
    np.testing.assert_array_equal(poses[:, :2], np.repeat(positions, 3, axis=0))
    assert poses[:, 2].min() >= 0.0 and poses[:, 2].max() < 360.0
    assert len(np.unique(poses[:, 2])) == len(poses)
    np.testing.assert_array_equal(poses, view_poses(positions, 3, np.random.default_rng(0)))
    for bad, match in [
        (([[0.0, 0.0, 0.0]], 1, np.random.default_rng(0)), "shape"),
        (([[0.0, float("nan")]], 1, np.random.default_rng(0)), "finite"),
        (([[0.0, 0.0]], 0, np.random.default_rng(0)), "headings_per_position"),
        (([[0.0, 0.0]], 1.5, np.random.default_rng(0)), "headings_per_position"),
        (([[0.0, 0.0]], 1, 0), "Generator"),
    ]:
        with pytest.raises(ValueError, match=match):
            view_poses(*bad)
