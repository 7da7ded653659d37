"""The tracking experiment: routes, the driver, re-localisation and coverage on hand-made
series, bad arguments, and the quick size end to end."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.cli import main
from vc_gym.experiments.studies.tracking import (
    MIN_LEG_M,
    ROUTE_MARGIN_M,
    Route,
    RouteDriver,
    make_route,
    relocalisation_time,
    route_figures,
    two_sigma_coverage,
)

ROBOLAB = (-3.0, 3.0, -2.0, 2.0)


# ---------------------------------------------------------------------- routes
def test_a_route_is_seeded_and_stays_on_the_field():
    a = make_route(ROBOLAB, seed=0, route=0)
    assert a == make_route(ROBOLAB, seed=0, route=0)
    assert a != make_route(ROBOLAB, seed=0, route=1)
    assert a != make_route(ROBOLAB, seed=1, route=0)
    assert Route.from_dict(json.loads(json.dumps(a.to_dict()))) == a
    x0, x1, y0, y1 = ROBOLAB
    m = ROUTE_MARGIN_M
    points = [a.start[:2], a.kidnap_pose[:2], *(w[:2] for w in a.waypoints)]
    for x, y in points:
        assert x0 + m <= x <= x1 - m and y0 + m <= y <= y1 - m
    legs = np.diff(np.array([a.start[:2], *(w[:2] for w in a.waypoints)]), axis=0)
    assert np.all(np.hypot(*legs.T) >= MIN_LEG_M - 1e-3)
    # enough waypoints for the whole route at the top speed
    assert np.hypot(*legs.T).sum() > 0.4 * a.duration_s
    assert 25.0 <= a.kidnap_s <= 35.0 and abs(a.kidnap_s * 10 - round(a.kidnap_s * 10)) < 1e-6
    turns = [w[2] for w in a.waypoints if w[2]]
    assert turns and all(90.0 <= abs(t) <= 360.0 for t in turns)
    assert any(t > 0 for t in turns) and any(t < 0 for t in turns)
    assert 0 < sum(1 for w in a.waypoints if w[2]) < len(a.waypoints)


def test_route_arguments_are_checked():
    with pytest.raises(ValueError, match="kidnapping window"):
        make_route(ROBOLAB, 0, 0, duration_s=8.0, kidnap_window_s=(4.0, 9.0))
    with pytest.raises(ValueError, match="too small"):
        make_route((0.0, 1.0, 0.0, 1.0), 0, 0)


def _drive(driver: RouteDriver, pose, steps: int, dt: float = 0.1):
    """A point robot that does exactly what it is told; the poses and commands."""
    x, y, yaw = pose
    out = []
    for _ in range(steps):
        forward, turn, pan = driver.command((x, y, yaw))
        out.append(((x, y, yaw), (forward, turn, pan)))
        yaw = (yaw + turn * dt) % 360.0
        x += forward * dt * math.cos(math.radians(yaw))
        y += forward * dt * math.sin(math.radians(yaw))
    return out


def test_the_driver_walks_to_each_waypoint_and_turns_on_the_spot():
    driver = RouteDriver([(1.0, 0.0, 0.0), (1.0, 1.0, -270.0), (0.0, 1.0, 0.0)], dt_s=0.1)
    trace = _drive(driver, (0.0, 0.0, 0.0), 300)
    assert driver.index == 3
    poses = np.array([p for p, _ in trace])
    commands = np.array([c for _, c in trace])
    assert commands[:, 0].max() <= 0.4 and np.abs(commands[:, 1]).max() <= 60.0
    # it stood still at (1, 1) while turning 270° clockwise
    at_corner = np.hypot(poses[:, 0] - 1.0, poses[:, 1] - 1.0) < 0.16
    spun = (commands[:, 0] == 0.0) & at_corner & (commands[:, 1] < 0)
    assert abs(commands[spun, 1].sum() * 0.1 + 270.0) < 8.0
    # the head scans when the robot does not walk, looks ahead when it does
    assert np.all(commands[commands[:, 0] > 0, 2] == 0.0)
    assert len(set(commands[commands[:, 0] == 0, 2])) > 2
    # it ends near the last waypoint, standing
    assert math.dist(poses[-1, :2], (0.0, 1.0)) < 0.16 and commands[-1, 0] == 0.0


def test_after_a_kidnapping_the_driver_heads_for_the_next_waypoint():
    driver = RouteDriver([(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)], dt_s=0.1)
    driver.command((0.0, 0.0, 0.0))
    driver.skip()
    assert driver.index == 1
    forward, turn, _ = driver.command((0.0, 0.0, 0.0))  # -1, 0 is behind: turn first
    assert forward == 0.0 and abs(turn) == 60.0


# ---------------------------------------------------------------------- figures
T = np.round(np.arange(0, 101) * 0.1, 6)  # 0 .. 10 s


def _reloc(pos, head, kidnap=3.0):
    return relocalisation_time(T, pos, head, kidnap)


def test_relocalisation_is_the_start_of_the_first_good_stretch_of_two_seconds():
    good_from = lambda t0: np.where(T >= t0 - 1e-9, 0.1, 2.0)  # noqa: E731
    zero = np.zeros_like(T)
    assert _reloc(good_from(5.0), zero) == pytest.approx(2.0)
    # a good stretch shorter than 2 s does not count
    pos = np.where(((T >= 4.0) & (T < 5.5)) | (T >= 6.0), 0.1, 2.0)
    assert _reloc(pos, zero) == pytest.approx(3.0)
    # good from 8 s: held exactly until the route's end at 10 s
    assert _reloc(good_from(8.0), zero) == pytest.approx(5.0)
    # good from 8.5 s: the route ends before 2 s could be seen
    assert _reloc(good_from(8.5), zero) is None
    # never good
    assert _reloc(np.full_like(T, 2.0), zero) is None
    # good all along: re-localised at the kidnapping itself
    assert _reloc(np.full_like(T, 0.1), zero) == 0.0
    # the criteria are inclusive
    assert _reloc(np.full_like(T, 0.3), np.full_like(T, -10.0)) == 0.0


def test_relocalisation_needs_the_heading_too_whatever_its_sign():
    pos = np.full_like(T, 0.05)
    head = np.where(T >= 6.0, -9.0, 15.0)
    assert _reloc(pos, head) == pytest.approx(3.0)
    assert _reloc(pos, np.full_like(T, -15.0)) is None
    with pytest.raises(ValueError, match="one length"):
        relocalisation_time(T, pos[:-1], head, 3.0)


def test_two_sigma_coverage_counts_entries_within_twice_sigma():
    assert two_sigma_coverage([1.0, -3.0, 5.0], [1.0, 1.0, 3.0]) == pytest.approx(2 / 3)
    # per (frame, axis) pair
    err = [[0.1, -0.5], [0.0, 0.0]]
    std = [[0.1, 0.1], [0.01, 0.01]]
    assert two_sigma_coverage(err, std) == pytest.approx(3 / 4)
    assert two_sigma_coverage([], []) is None
    with pytest.raises(ValueError, match="shape"):
        two_sigma_coverage([1.0, 2.0], [1.0])


def _frames(kidnap_s: float = 12.0, back_s: float = 15.0) -> dict:
    """20 s: heading off by 2°, position by 0.1 m; from the kidnapping until ``back_s``
    by 90° and 2 m; then by -4° and 0.2 m. Spreads 1.5°, stds 0.06 m."""
    t = np.round(np.arange(0, 201) * 0.1, 6)
    lost = (t >= kidnap_s) & (t < back_s)
    after = t >= back_s
    head_err = np.where(lost, 90.0, np.where(after, -4.0, 2.0))
    pos_err = np.where(lost, 2.0, np.where(after, 0.2, 0.1))
    true = np.stack([np.linspace(-2, 2, t.size), np.zeros_like(t), np.full_like(t, 350.0)], 1)
    est = true.copy()
    est[:, 0] += pos_err
    est[:, 2] = (true[:, 2] + head_err) % 360.0
    return {
        "t_s": t.tolist(),
        "true": true.tolist(),
        "estimate": est.tolist(),
        "heading_spread_deg": np.full_like(t, 1.5).tolist(),
        "position_std_m": np.full((t.size, 2), 0.06).tolist(),
    }


def test_route_figures_leave_out_the_first_seconds_and_the_relocalisation_window():
    f = route_figures(_frames(), kidnap_s=12.0, settle_s=10.0)
    assert f["relocalisation_s"] == pytest.approx(3.0)
    # evaluated: 10.0-11.9 s (20 frames of 2°, 0.1 m) and 15.0-20.0 s (51 of 4°, 0.2 m)
    assert f["mean_heading_error_deg"] == pytest.approx((20 * 2 + 51 * 4) / 71, abs=0.01)
    assert f["mean_position_error_m"] == pytest.approx((20 * 0.1 + 51 * 0.2) / 71, abs=1e-4)
    # with the window: 30 frames more of 90° and 2 m
    assert f["mean_heading_error_with_relocalisation_deg"] == pytest.approx(
        (20 * 2 + 30 * 90 + 51 * 4) / 101, abs=0.01
    )
    assert f["mean_position_error_with_relocalisation_m"] == pytest.approx(
        (20 * 0.1 + 30 * 2.0 + 51 * 0.2) / 101, abs=1e-4
    )
    assert f["relocalised_within_10s"] == 1.0
    # 2σ: 3° covers the 2° frames only; 0.12 m covers x 0.1 (20) and every y (71)
    assert f["heading_coverage_2sigma"] == pytest.approx(20 / 71, abs=1e-4)
    assert f["position_coverage_2sigma"] == pytest.approx((20 + 71) / 142, abs=1e-4)
    bins = f["error_over_time"]
    assert len(bins["heading_deg"]) == len(bins["position_m"]) == 20
    assert bins["heading_deg"][0] == 2.0 and bins["heading_deg"][13] == 90.0
    assert bins["heading_deg"][-1] == 4.0 and bins["position_m"][-1] == 0.2


def test_a_robot_never_found_again_is_left_out_from_the_kidnapping_on():
    f = route_figures(_frames(back_s=99.0), kidnap_s=12.0, settle_s=10.0)
    assert f["relocalisation_s"] is None and f["relocalised_within_10s"] == 0.0
    assert f["mean_heading_error_deg"] == pytest.approx(2.0)
    assert f["mean_heading_error_with_relocalisation_deg"] == pytest.approx(
        (20 * 2 + 81 * 90) / 101, abs=0.01
    )


def test_heading_errors_wrap():
    frames = _frames()
    frames["estimate"] = [[x, y, (h + 360.0) % 360.0] for x, y, h in frames["estimate"]]
    assert route_figures(frames, 12.0, 10.0) == route_figures(_frames(), 12.0, 10.0)
    assert float(wrap180(355.0 - 5.0)) == -10.0


# ---------------------------------------------------------------------- arguments
@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["--lights", "1,1.5"], "(0, 1]"),
        (["--lights", "1,1"], "distinct"),
        (["--episodes", "0"], "--episodes"),
        (["--seeds", "0,0"], "given twice"),
        (["--scenes", "nowhere"], "nowhere"),
        (["--tracker", "no_such_tracker"], "no_such_tracker"),
    ],
)
def test_bad_arguments_are_refused_before_any_work(tmp_path, capsys, argv, says):
    out = tmp_path / "out"
    code = main(["experiment", "tracking", "--quick", "--out", str(out), *argv])
    assert code == 2
    assert says in capsys.readouterr().err
    assert not out.exists()


# ---------------------------------------------------------------------- end to end
@pytest.mark.slow
def test_the_quick_size_end_to_end(tmp_path):
    import cv2

    first = tmp_path / "first"
    argv = ["experiment", "tracking", "--quick", "--seed", "0", "--json"]
    assert main([*argv, "--out", str(first), "--video", "1"]) == 0
    for name in ("results.json", "run.json", "errors_robolab.png", "belief_robolab.png"):
        assert (first / name).is_file(), name
    (video,) = (first / "videos").glob("*.mp4")
    cap = cv2.VideoCapture(str(video))
    assert cap.isOpened() and cap.get(cv2.CAP_PROP_FRAME_COUNT) == 81  # 8 s at 10 Hz
    cap.release()

    text = (first / "results.json").read_text()
    for word in ("seconds", "duration", "timing", "ms_per", str(tmp_path)):
        assert word not in text, word  # figures only: no timings, no paths
    r = json.loads(text)
    assert r["failed_jobs"] == [] and r["settings"]["lights"] == [1.0]
    grid = r["scenes"]["robolab"]["lights"]["1"]["trackers"]["grid"]
    assert grid["routes"] == 1 and set(grid["per_seed"]) == {"0"}
    (route,) = grid["per_route"]
    assert route["kidnap_s"] == 4.0 and route["kidnap_distance_m"] > 0.0
    assert len(route["error_over_time"]["heading_deg"]) == 8
    assert 0.0 <= grid["heading_coverage_2sigma"] <= 1.0
    run = json.loads((first / "run.json").read_text())
    assert run["ms_per_update_median"]["grid"] > 0.0
    frames = json.loads(next((first / "jobs" / "routes").glob("*.json")).read_text())
    assert len(frames["output"]["frames"]["t_s"]) == 81

    # the same seed again (the atlas reused, no video): the same bytes
    second = tmp_path / "second"
    assert main([*argv, "--out", str(second), "--atlas", str(first / "atlases")]) == 0
    assert (second / "results.json").read_bytes() == (first / "results.json").read_bytes()
