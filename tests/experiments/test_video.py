"""Episode videos: a real short episode written as MP4, read back with OpenCV."""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import pytest

from vc_gym.experiments.episode import EpisodeStep, make_homing_run, run_episode
from vc_gym.experiments.video import (
    ESTIMATE_RGB,
    PARTICLE_RGB,
    TRUE_RGB,
    EpisodeVideo,
    write_episode_video,
)

SHORT = {"learn_time_s": 0.2, "max_homing_s": 3.0}
POSE = {"pose": (1.5, -0.8, 30.0)}  # kidnapped well away from home


@pytest.fixture(scope="module")
def run():
    """The scripted run with camera frames in its observations, place learned once."""
    r = make_homing_run(keep_image=True, **SHORT)
    r.env.reset(seed=0)  # the (short) learning phase
    yield r
    r.close()


def read_frames(path) -> tuple[list[np.ndarray], float]:
    cap = cv2.VideoCapture(str(path))
    assert cap.isOpened()
    fps = cap.get(cv2.CAP_PROP_FPS)
    frames = []
    while True:
        ok, bgr = cap.read()
        if not ok:
            break
        frames.append(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
    cap.release()
    return frames, fps


def near(rgb, target, tol=60) -> bool:
    return bool(np.all(np.abs(np.asarray(rgb, int) - np.asarray(target, int)) <= tol))


@pytest.mark.slow  # an episode on a learned place
def test_video_has_a_frame_per_step_and_shows_true_and_estimated_pose(run, tmp_path):
    path = tmp_path / "out" / "episode.mp4"  # the folder is created
    video = EpisodeVideo(path, run.env)
    with video:
        record = run_episode(run, seed=5, options=POSE, on_step=video)
    assert sorted(p.name for p in path.parent.iterdir()) == ["episode.mp4"]  # no temp left
    frames, fps = read_frames(path)
    assert len(frames) == video.frames == record.decisions > 0
    w, h = video.frame_size
    cam = run.env.unwrapped.camera
    assert w - 360 - round(cam.width * 360 / cam.height) in (0, 1) and h > 360  # + caption
    assert all(f.shape == (h, w, 3) for f in frames)
    assert fps == pytest.approx(1.0 / run.env.unwrapped.control_dt)

    # the frame where the belief is farthest from the truth: both markers apart
    true, est = np.array(record.true), np.array(record.estimated)
    i = int(np.nanargmax(np.hypot(*(est[:, :2] - true[:, :2]).T)))
    assert math.dist(true[i, :2], est[i, :2]) > 0.5
    frame, top = frames[i], video.top_view
    x, y, yaw = true[i]
    # the robot's body behind its centre (the white heading arrow starts at the centre)
    c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    u, v = top.to_px(x - 0.12 * c, y - 0.12 * s)
    assert near(frame[v - 1 : v + 2, u - 1 : u + 2].reshape(-1, 3).mean(0), TRUE_RGB)
    # the estimate's ring around its position: cyan on most rays from its centre
    u, v = top.to_px(*est[i, :2])
    hits = 0
    for a in np.linspace(0.0, 2 * math.pi, 16, endpoint=False):
        ray = [frame[round(v - r * math.sin(a)), round(u + r * math.cos(a))] for r in range(8, 15)]
        hits += any(near(p, ESTIMATE_RGB) for p in ray)
    assert hits >= 12
    assert not near(frame[v, u], TRUE_RGB)  # the estimate is not where the body is drawn


@pytest.mark.slow  # an episode on a learned place
def test_the_video_does_not_change_the_episode(run, tmp_path):
    plain = run_episode(run, seed=7)
    steps: list[EpisodeStep] = []
    watched = run_episode(run, seed=7, on_step=steps.append)
    filmed = write_episode_video(run, 7, tmp_path / "ep.mp4")
    assert plain.summary() == watched.summary() == filmed.summary()
    assert plain.true == filmed.true and plain.estimated == filmed.estimated
    assert [s.index for s in steps] == list(range(plain.decisions))
    assert [s.true_pose for s in steps] == plain.true
    assert steps[-1].sim_time_s == pytest.approx(plain.sim_time_s)
    assert all(s.estimate is not None and s.image is not None for s in steps)
    assert steps[-1].info["stopped"] == plain.stopped


@pytest.mark.slow  # an episode on a learned place
def test_frames_rendered_from_the_env_equal_the_observed_ones(run, tmp_path):
    """Without the frame in the observation (a learned agent's env), the video
    renders the head camera again: the same pixels."""
    observed = EpisodeVideo(tmp_path / "a.mp4", run.env)
    rendered = EpisodeVideo(tmp_path / "b.mp4", run.env)
    checked = []

    def both(step: EpisodeStep) -> None:
        obs = {k: v for k, v in step.observation.items() if k != "image"}
        a = observed.render(step)
        b = rendered.render(dataclasses.replace(step, observation=obs))
        checked.append(np.array_equal(a, b))

    run_episode(run, seed=3, options=POSE, on_step=both)
    observed.abort()
    rendered.abort()
    assert checked and all(checked)
    assert list(tmp_path.iterdir()) == []  # aborted videos leave nothing


@pytest.mark.slow  # an episode on a learned place
def test_a_failed_episode_writes_no_file(run, tmp_path):
    path = tmp_path / "ep.mp4"
    path.write_bytes(b"old")

    def boom(step: EpisodeStep) -> None:
        if step.index == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt), EpisodeVideo(path, run.env) as video:
        run_episode(run, seed=4, on_step=lambda s: (video(s), boom(s)))
    assert path.read_bytes() == b"old"  # the old file is untouched
    assert [p.name for p in tmp_path.iterdir()] == ["ep.mp4"]
    empty = EpisodeVideo(tmp_path / "empty.mp4", run.env)
    with pytest.raises(RuntimeError, match="no frame"):
        empty.close()
    assert [p.name for p in tmp_path.iterdir()] == ["ep.mp4"]


@pytest.mark.slow  # an episode on a learned place
def test_an_unavailable_codec_is_a_clear_error(run, tmp_path, monkeypatch):
    class ClosedWriter:
        def __init__(self, *args):
            pass

        def isOpened(self):
            return False

        def release(self):
            pass

    monkeypatch.setattr(cv2, "VideoWriter", ClosedWriter)
    with pytest.raises(RuntimeError, match="mp4v"):
        EpisodeVideo(tmp_path / "ep.mp4", run.env)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # an episode on a learned place
def test_bad_arguments(run, tmp_path):
    with pytest.raises(ValueError, match="fps"):
        EpisodeVideo(tmp_path / "ep.mp4", run.env, fps=0.0)
    with pytest.raises(ValueError, match="LearnThenHome"):
        EpisodeVideo(tmp_path / "ep.mp4", _NotAnEnv())
    assert list(tmp_path.iterdir()) == []


class _Cloud:
    """A tracker double that only has particles."""

    particles = np.array([[1.5, 1.0, 0.0]] * 20 + [[-1.5, -1.0, 90.0]] * 20)


def test_a_room_video_draws_the_trackers_particles_and_a_new_trail_after_a_jump(tmp_path):
    from vc_gym.sim import AiboRoomEnv

    room = AiboRoomEnv()
    try:
        obs, info = room.reset(seed=0, options={"pose": (0.0, 0.0, 0.0)})
        video = EpisodeVideo(tmp_path / "room.mp4", room, tracker=_Cloud(), spots={"a": (2, 0)})
        est = {"heading_deg": 10.0, "position": [0.5, 0.0], "position_std_m": [0.1, 0.1]}
        frame = video.render(EpisodeStep(0, 0.0, obs, info, tuple(info["pose"]), est))
        for x, y in ((1.5, 1.0), (-1.5, -1.0)):
            u, v = video.top_view.to_px(x, y)
            assert near(frame[v, u], PARTICLE_RGB)
        obs, info = room.reset(seed=1, options={"pose": (2.0, 1.0, 0.0)})  # teleported
        video.render(EpisodeStep(1, 0.1, obs, info, tuple(info["pose"]), est))
        assert len(video._true_trail) == 1  # the trail starts anew where it was put
        video.abort()
    finally:
        room.close()
    assert list(tmp_path.iterdir()) == []


class _NotAnEnv:
    unwrapped = property(lambda self: self)
    control_dt = 0.1
