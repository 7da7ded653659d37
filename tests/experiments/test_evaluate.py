"""`vc-gym evaluate` end to end with a tiny budget (learned agents: tests/agents)."""

from __future__ import annotations

import json

import pytest

from vc_gym.cli import main
from vc_gym.experiments.evaluate import evaluate_agent


def test_evaluate_scripted_summarises_stops(tmp_path):
    r = evaluate_agent(
        episodes=2,
        seed=3,
        learn_time_s=0.2,
        max_homing_s=20.0,
        workers=2,
        out_dir=tmp_path,
        progress=False,
    )
    assert [e["seed"] for e in r["per_episode"]] == [4, 5]
    assert len(r["mean_stop_offset_cm"]) == 2 and len(r["std_stop_offset_cm"]) == 2
    assert 0.0 <= r["success_rate"] <= 1.0
    for ep in r["per_episode"]:
        assert ep["stopped"] or ep["timed_out"]
        assert ep["sim_time_s"] <= 20.0 + 1e-6
        assert ep["home_error_m"] == pytest.approx(
            (ep["stop_offset_m"][0] ** 2 + ep["stop_offset_m"][1] ** 2) ** 0.5
        )
    saved = json.loads((tmp_path / "evaluation.json").read_text())
    assert saved["episodes"] == 2 and saved["protocol"].startswith("learn once")
    assert (tmp_path / "stop_positions.png").read_bytes()[:4] == b"\x89PNG"


def test_evaluate_rejects_a_missing_model(capsys):
    assert main(["evaluate", "--agent", "ppo_model.zip", "--episodes", "1"]) == 2
    assert "model" in capsys.readouterr().err


def test_evaluate_rejects_bad_numbers():

    with pytest.raises(ValueError):
        evaluate_agent(episodes=0)
    with pytest.raises(ValueError):
        evaluate_agent(relearn="sometimes")
    with pytest.raises(ValueError):
        evaluate_agent(max_homing_s=float("nan"))


class DyingTracker:
    """A tracker whose worker process dies at the first frame (as if OOM-killed)."""

    def reset(self, atlas, camera, dt_s):
        pass

    def update(self, image, head_pan_deg, odometry):
        import os

        os._exit(9)


def test_a_dead_worker_is_a_clear_error_not_a_hang(capsys):
    # the learning phase is short; the first homing frame kills each worker
    args = ["evaluate", "--episodes", "2", "--workers", "2", "--learn-time", "0.2"]
    code = main([*args, "--tracker", f"{__name__}:DyingTracker"])
    assert code == 1
    assert "worker process died" in capsys.readouterr().err
