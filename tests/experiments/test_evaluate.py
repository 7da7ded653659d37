"""`vc-gym evaluate` end to end with a tiny budget."""

from __future__ import annotations

import json

from vc_gym.cli import main
from vc_gym.experiments.evaluate import evaluate_scripted


def test_evaluate_scripted_summarises_stops(tmp_path):
    r = evaluate_scripted(
        episodes=2, seed=3, learn_time_s=0.3, workers=1, out_dir=tmp_path, progress=False
    )
    assert len(r["per_episode"]) == 2
    assert len(r["mean_stop_offset_cm"]) == 2 and len(r["std_stop_offset_cm"]) == 2
    assert 0.0 <= r["success_rate"] <= 1.0
    saved = json.loads((tmp_path / "evaluation.json").read_text())
    assert saved["episodes"] == 2
    assert (tmp_path / "stop_positions.png").read_bytes()[:4] == b"\x89PNG"


def test_evaluate_rejects_unknown_agent(capsys):
    assert main(["evaluate", "--agent", "ppo_model.zip", "--episodes", "1"]) == 2
    assert "scripted" in capsys.readouterr().err
