"""`vc-gym bench trackers`: every tracker timed on the same walk, errors reported."""

from __future__ import annotations

import json

from vc_gym.cli import main
from vc_gym.localization import TRACKERS


def test_bench_trackers_json(capsys, tmp_path):
    out = tmp_path / "trackers.json"
    assert main(["bench", "trackers", "--json", "--repeats", "3", "--out", str(out)]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert json.loads(out.read_text()) == result
    assert set(result["trackers"]) == set(TRACKERS)
    assert result["atlas_ms"] > 0
    for name, v in result["trackers"].items():
        assert v["update_ms"] > 0
        assert v["final_heading_error_deg"] < 15.0  # a walk towards home in a known room
        # the bench's atlas has no turns around its spots, so the pose tracker's maps
        # cannot be re-drawn: it knows a position only to the nearest spot's area, and
        # pose-grid answers with it until it places the robot near home
        assert v["final_position_error_m"] < (1.5 if name in ("pose", "pose-grid") else 0.8)
