"""One episode path: the demo is the first episode of the evaluation, record for record."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.experiments.demo import run_demo
from vc_gym.experiments.episode import EpisodeRecord, make_homing_run, run_episode
from vc_gym.experiments.studies import ExperimentOptions
from vc_gym.experiments.studies.homing import run_homing
from vc_gym.jobs.backends import LocalBackend

SHORT = {"learn_time_s": 0.2, "max_homing_s": 8.0}


@pytest.mark.slow
@pytest.mark.parametrize(("mode", "tracker"), [("check-home", "grid"), ("pose-home", "pose-grid")])
def test_demo_summary_equals_the_evaluations_record_of_that_episode(tmp_path, mode, tracker):
    demo = run_demo(tmp_path, seed=2, progress=False, mode=mode, **SHORT)
    # the experiment learns the place in a job, saves the atlas and homes with the
    # loaded atlas: the same episode, so the atlas file is an exact round trip
    opts = ExperimentOptions(seed=2, backend=LocalBackend(1), progress=False)
    evaluation = run_homing(tmp_path / "homing", opts, episodes=1, field=False, mode=mode, **SHORT)
    episode = evaluation["per_episode"][0]
    assert episode["seed"] == 3 and demo["learning_seed"] == 2
    assert {k: demo[k] for k in episode} == episode
    assert demo["mode"] == evaluation["settings"]["mode"] == mode
    assert demo["tracker"] == evaluation["settings"]["tracker"] == tracker  # the mode's
    assert (tmp_path / "demo.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
@pytest.mark.parametrize("tracker", ["grid", "particle"])
def test_record_holds_what_the_plots_need(tracker):
    run = make_homing_run(tracker=tracker, **SHORT)
    try:
        run.env.reset(seed=0)
        record = run_episode(run, seed=5, options={"pose": (1.2, -0.6, 45.0)})
    finally:
        run.close()
    assert isinstance(record, EpisodeRecord)
    n = record.decisions
    assert len(record.true) == len(record.estimated) == len(record.heading_error) == n > 0
    assert record.start_pose == pytest.approx((1.2, -0.6, 45.0), abs=1e-6)
    true, est = np.array(record.true), np.array(record.estimated)
    wrapped = (est[:, 2] - true[:, 2] + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(np.clip(wrapped, -180, 179.999), record.heading_error, atol=1e-6)
    assert record.stopped or record.timed_out
    assert record.stop_error_m == pytest.approx(math.hypot(*record.stop_position))
    assert record.tracker_updates == n and record.tracker_time_s > 0
    s = record.summary()
    assert s["decisions"] == n and s["home_error_m"] == record.stop_error_m
    assert "tracker_time_s" not in s  # figures only, no timings


def test_modes_choose_the_learning_and_the_policy():
    from vc_gym.experiments.episode import HOMING_MODES, homing_mode

    assert homing_mode("paper").policy == {} and homing_mode("paper").learning == {}
    assert homing_mode("check-home").policy == {"verify_home": True}
    assert homing_mode("check-home").learning == {"normalise_at": "start"}
    assert set(HOMING_MODES) == {"paper", "check-home", "pose-home", "bearings-home"}
    bearings = homing_mode("bearings-home")
    assert bearings.tracker == {"type": "bearings", "search_every": 1}
    assert bearings.learning["landmarks"] is True
    assert not bearings.policy.get("verify_home") and bearings.policy["home_tolerance_m"] <= 0.05
    assert max(bearings.policy["walk_scan_deg"]) > 0  # the head scans while walking
    assert bearings.policy["look_std_m"] > 0  # an unsure belief looks around
    pose = homing_mode("pose-home")
    assert pose.tracker == "pose-grid" and pose.learning["around_m"] > 0
    assert pose.policy["verify_home"]
    assert homing_mode("paper").tracker == "grid"
    with pytest.warns(DeprecationWarning, match="check-home"):
        assert homing_mode("improved") is HOMING_MODES["check-home"]
    with pytest.raises(ValueError, match="paper"):
        homing_mode("best")
    run = make_homing_run(mode="check-home", policy={"max_verifications": 2}, **SHORT)
    try:
        policy = run.act.__self__
        assert policy.verify_home and policy.max_verifications == 2
        assert run.env.unwrapped.learn_config.normalise_at == "start"
        assert type(run.env.get_wrapper_attr("tracker")).__name__ == "GridTracker"
    finally:
        run.close()


def test_the_pose_home_mode_reaches_the_run():
    """pose-home's policy settings, places and tracker reach the scripted run (built,
    not run); a policy setting given to the run wins over the mode's."""
    import inspect

    from vc_gym.agents import ScriptedHomingPolicy
    from vc_gym.experiments.episode import homing_mode
    from vc_gym.localization import HomeSwitchTracker

    mode = homing_mode("pose-home")
    # as HOMING_MODES documents them: check home with a full turn, walk the checked
    # offset itself, settle 1 s, turn the checks at the robot's own speed
    assert mode.policy == {
        "verify_home": True,
        "verify_gain": 1.0,
        "verify_turn_deg_s": 90.0,
        "settle_time_s": 1.0,
    }
    defaults = inspect.signature(ScriptedHomingPolicy).parameters
    # every setting of the mode differs from the policy's default: each is seen to arrive
    assert all(value != defaults[name].default for name, value in mode.policy.items())
    for given in ({"max_verifications": 2}, {"settle_time_s": 1.5}):
        run = make_homing_run(mode="pose-home", policy=given, **SHORT)
        try:
            policy = run.act.__self__
            for name, value in {**mode.policy, **given}.items():
                assert getattr(policy, name) == value, name
            learn = run.env.unwrapped.learn_config
            assert (learn.normalise_at, learn.around_m) == ("start", 0.5)
            assert isinstance(run.env.get_wrapper_attr("tracker"), HomeSwitchTracker)
        finally:
            run.close()


def test_a_learned_agent_runs_with_its_stops_checked():
    from vc_gym.agents.learned import PRETRAINED_MODEL
    from vc_gym.envs.homing import StopAction
    from vc_gym.experiments.episode import LEARNED_CONFIRM_STOP_M

    run = make_homing_run(agent=str(PRETRAINED_MODEL), learn_time_s=0.2, max_homing_s=3.0)
    wrapper = run.env.unwrapped.stop_action  # Homing-v0 applies it inside its env class
    assert isinstance(wrapper, StopAction)
    assert wrapper.confirm_stop_m == LEARNED_CONFIRM_STOP_M == 0.25
    run.env.close()


def test_a_learned_agent_homes_in_the_mode_of_its_training_places():
    from types import SimpleNamespace

    from vc_gym.agents.learned import PRETRAINED_MODEL
    from vc_gym.experiments.episode import default_homing_mode, homing_mode

    assert default_homing_mode("scripted") == "check-home"
    assert default_homing_mode(str(PRETRAINED_MODEL)) == "pose-home"  # its training places
    pose = SimpleNamespace(env_kwargs={**homing_mode("pose-home").learning}, path="m.zip")
    assert default_homing_mode(pose) == "pose-home"
    odd = SimpleNamespace(env_kwargs={"around_m": 0.3}, path="odd/model.zip")
    with pytest.raises(ValueError, match="odd/model.zip.*none of the homing modes"):
        default_homing_mode(odd)
