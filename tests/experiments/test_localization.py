"""Full-field localisation: the paper's eq. 30 on known answers, and the experiment end to
end at --quick. The calibrated and turn-signature estimators are
:mod:`vc_gym.localization`'s (tests/localization/test_goodness_calibration.py and
test_turn_signature.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vc_gym.cli import main
from vc_gym.experiments.studies.localization import locate_eq30

SPOTS = np.array([[x, y] for x in (-2.25, -0.75, 0.75, 2.25) for y in (-1.5, 0.0, 1.5)])


def test_eq30_picks_the_best_spot_when_sharp():
    s = np.full(len(SPOTS), -0.3)
    s[4] = -0.1
    np.testing.assert_allclose(locate_eq30(s, SPOTS, 100.0), SPOTS[4], atol=1e-6)
    np.testing.assert_allclose(
        locate_eq30(np.zeros(len(SPOTS)), SPOTS, 30.0), (0.0, 0.0), atol=1e-9
    )


@pytest.mark.parametrize(
    "call",
    [
        lambda: locate_eq30(np.zeros(3), SPOTS, 30.0),  # one score per spot
        lambda: locate_eq30(np.full(len(SPOTS), np.nan), SPOTS, 30.0),
        lambda: locate_eq30(np.zeros(len(SPOTS)), SPOTS, 0.0),
        lambda: locate_eq30(np.zeros((0,)), SPOTS[:0], 30.0),
    ],
)
def test_bad_inputs_are_clear_errors(call):
    with pytest.raises(ValueError, match="shape|finite|sharpness"):
        call()


@pytest.mark.slow
def test_the_experiment_end_to_end(tmp_path, capsys):
    assert main(["experiment", "localization", "--quick", "--out", str(tmp_path)]) == 0
    r = json.loads((tmp_path / "results.json").read_text())
    assert set(r["methods"]) == {"paper", "calibrated", "turn_calibrated", "turn_nearest"}
    n = len(r["true_positions"])
    for name, m in r["methods"].items():
        assert len(m["estimates"]) == n > 0 and m["mean_error_m"] >= 0
        if name != "paper":
            assert 0.0 <= m["within_2_sigma"] <= 1.0
    assert (tmp_path / "localization.png").read_bytes()[:4] == b"\x89PNG"
    assert "calibrated" in capsys.readouterr().out


def test_more_than_one_scene_is_refused(tmp_path, capsys):
    argv = ["experiment", "localization", "--quick", "--scenes", "robolab,office"]
    assert main([*argv, "--out", str(tmp_path)]) == 2
    assert "one scene" in capsys.readouterr().err
