"""The agents experiment's summary: every agent's figures, homing time included, and the
paired comparison with the scripted agent on the same kidnappings (known answers)."""

from __future__ import annotations

import pytest

from vc_gym.experiments.studies.agents import _summarise, summary_lines


def episode(seed, distance_m, time_s):
    return {"learning_seed": 0, "seed": seed, "home_error_m": distance_m, "sim_time_s": time_s}


def homing_results(episodes, homing_time_s):
    overall = {
        "episodes": len(episodes),
        "success_rate": 1.0,
        "mean_stop_distance_cm": 10.0,
        "median_stop_distance_cm": 9.0,
        "mean_stop_offset_cm": [1.0, -1.0],
        "std_stop_offset_cm": [5.0, 5.0],
        "far_stops": 0,
        "timed_out": 1,
        "mean_homing_time_s": homing_time_s,
    }
    per_seed = [{"seed": 0, "success_rate": 1.0, "mean_stop_distance_cm": 10.0,
                 "mean_homing_time_s": homing_time_s}]  # fmt: skip
    return {"overall": overall, "per_seed": per_seed, "per_episode": episodes}


def test_the_paired_comparison_counts_distance_and_homing_time():
    scripted = [episode(1, 0.10, 20.0), episode(2, 0.05, 30.0), episode(3, 0.20, 10.0)]
    learned = [episode(1, 0.08, 10.0), episode(2, 0.07, 15.0), episode(3, 0.20, 12.0)]
    out = _summarise(
        {"scripted": homing_results(scripted, 20.0), "ppo": homing_results(learned, 12.3)},
        "scripted",
        ["ppo"],
    )
    p = out["paired_with_scripted"]["ppo"]
    assert p["episodes"] == 3
    assert p["at_least_as_close"] == 2  # 8 <= 10 cm and 20 <= 20 cm, not 7 > 5 cm
    assert p["mean_distance_difference_cm"] == pytest.approx(0.0)
    assert p["at_least_as_fast"] == 2  # 10 <= 20 s and 15 <= 30 s, not 12 > 10 s
    assert p["mean_homing_time_difference_s"] == pytest.approx((-10 - 15 + 2) / 3, abs=0.05)
    assert p["homing_time_ratio"] == pytest.approx(37 / 60, abs=1e-3)
    row = out["agents"]["ppo"]
    assert row["mean_homing_time_s"] == 12.3 and row["timed_out"] == 1
    assert row["median_stop_distance_cm"] == 9.0
    assert row["per_seed"][0]["mean_homing_time_s"] == 12.3
    assert out["learned_over_agents"]["mean_homing_time_s"][0] == pytest.approx(12.3)
    lines = "\n".join(summary_lines(out))
    assert "mean homing time 12.3 s" in lines and "1 timed out" in lines
    assert "at least as fast in 2/3" in lines and "0.62 × the scripted agent's" in lines


def test_learned_agents_of_different_modes_need_a_mode(monkeypatch, tmp_path):
    from vc_gym.experiments.studies import agents as study

    modes = {"pretrained": "paper", str(tmp_path / "b" / "model.zip"): "pose-home"}
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "model.zip").write_bytes(b"")
    monkeypatch.setattr(study, "LearnedHomingAgent", lambda path, allow: path)
    monkeypatch.setattr(
        study,
        "default_homing_mode",
        lambda path: modes["pretrained" if path == str(study.PRETRAINED_MODEL) else path],
    )
    assert study._learned_mode(["scripted", "pretrained"], False) == "paper"
    with pytest.raises(ValueError, match="different homing modes"):
        study._learned_mode(["scripted", "pretrained", str(tmp_path / "b" / "model.zip")], False)
    with pytest.raises(ValueError, match="different homing modes"):
        study.run_agents(
            tmp_path / "out",
            agent=["scripted", "pretrained", str(tmp_path / "b" / "model.zip")],
        )
    assert not (tmp_path / "out").exists()  # refused before any work
