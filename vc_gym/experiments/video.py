"""Episode videos: what the robot saw and what it believed, step by step, as an MP4.

:class:`EpisodeVideo` is an ``on_step`` hook of :func:`~vc_gym.experiments.episode.run_episode`.
Each frame shows the robot's head-camera image beside a top view of the scene
(:class:`~vc_gym.sim.top_view.TopView`, north up) with the true pose (red body, white
heading arrow, the camera's field of view, orange trail), the tracker's estimated pose
(cyan ring with a heading arrow, its 1σ position uncertainty as an ellipse, cyan trail),
home and the training spots, above a caption with the time, the heading error and the
distance from home (in a room without a home, the position error). Given the tracker,
it also draws the tracker's ``particles`` when it has them (magenta dots). A true pose
that jumps (a kidnapping in the middle of a recording) starts the true trail anew.
:func:`write_episode_video` runs one episode with it.

The file is written through a temporary file in the same folder and renamed into place
when the video is closed, so ``path`` holds a whole video or none.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import cv2
import gymnasium as gym
import numpy as np

from vc_gym.angles import wrap180
from vc_gym.experiments.episode import EpisodeRecord, EpisodeStep, HomingRun, run_episode
from vc_gym.persistence import write_atomic
from vc_gym.sim.top_view import TopView

__all__ = ["ESTIMATE_RGB", "PARTICLE_RGB", "TRUE_RGB", "EpisodeVideo", "write_episode_video"]

#: Colour of the true robot body (the body :meth:`TopView.draw` fills), RGB.
TRUE_RGB = (220, 40, 40)
#: Colour of the estimated pose, its uncertainty and trail, RGB.
ESTIMATE_RGB = (0, 230, 255)
#: Colour of a particle tracker's particles, RGB.
PARTICLE_RGB = (255, 0, 255)
_TRUE_TRAIL_RGB = (255, 128, 0)  # TopView.draw's trail colour
_HOME_RGB = (255, 255, 255)
_SPOT_RGB = (255, 230, 0)
_TEXT_RGB = (235, 235, 235)
_CAPTION_BG = (30, 30, 30)

_TOP_PX = 360  # top view height and width
_CAPTION_PX = 52  # two lines of text
_FONT = cv2.FONT_HERSHEY_SIMPLEX
_ARROW_M = 0.5
_RING_PX = 11  # the estimate's ring: a little larger than the 0.45 x 0.3 m body
_JUMP_M = 0.5  # a true pose that moves farther in one step was teleported
_MAX_PARTICLES = 1000  # most particles drawn (every k-th)
_MAX_SPOT_LABELS = 8  # more spots are marked without their names


def _even(n: int) -> int:
    return n + (n % 2)  # MPEG-4 part 2 wants even frame sizes


class EpisodeVideo:
    """Writes one episode to an MP4 file, one frame per step; use it as ``on_step``.

    ``run_episode(run, seed, on_step=video)`` calls it after every step; :meth:`close`
    then renames the finished video to ``path`` (or use it as a context manager: the
    video is closed on success and discarded on an exception). Frames are
    ``(top view + scaled camera image) over a caption``, encoded with OpenCV's
    ``mp4v`` codec.

    The camera image comes from the observation when it carries one
    (``make_homing_run(..., keep_image=True)``); otherwise (a learned agent's feature
    vector, or ``keep_image=False``) the head camera is rendered again from the env's
    room, :meth:`~vc_gym.sim.AiboRoomEnv.head_image`: the same pixels (the renderer
    is deterministic and draws no random numbers) for one more render per frame.

    Parameters
    ----------
    path : path-like
        The MP4 file to write (its folder is created).
    env : gymnasium.Env
        The episode's env (``run.env``): its ``unwrapped`` is a
        ``vc_gym/LearnThenHome-v0`` (with ``room``, ``home``, ``control_dt`` and, once
        learned, ``learning_result`` or ``atlas``) or a ``vc_gym/AiboRoom-v0``.
    fps : float, optional
        Frames per second of the video. Default ``1 / control_dt``: real time.
    tracker : object, optional
        The tracker whose belief is shown: its ``particles`` (an ``(N, 3)`` array of
        ``x, y, θ``, world frame), if it has them, are drawn in every frame.
    spots : mapping, optional
        ``{name: (x, y)}`` of the training spots to mark (default: the task's learned
        spots; none for a room).

    Raises
    ------
    RuntimeError
        If OpenCV cannot write ``mp4v`` MP4 files (a build without video I/O).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        env: gym.Env,
        fps: float | None = None,
        *,
        tracker: object | None = None,
        spots: Mapping[str, Sequence[float]] | None = None,
    ):
        u = env.unwrapped
        room = getattr(u, "room", u)
        if not all(hasattr(room, a) for a in ("client", "scene", "camera", "head_image")):
            raise ValueError(
                "EpisodeVideo needs a vc_gym/LearnThenHome-v0 or vc_gym/AiboRoom-v0 env, "
                f"got {type(u).__name__}"
            )
        if fps is None:
            fps = 1.0 / float(u.control_dt)
        fps = float(fps)
        if not (math.isfinite(fps) and fps > 0):
            raise ValueError(f"fps must be a positive number, got {fps!r}")
        self.path = Path(path)
        self.fps = fps
        self._task = u
        self._room = room
        self._tracker = tracker
        self._given_spots = (
            None if spots is None else {str(n): (float(x), float(y)) for n, (x, y) in spots.items()}
        )
        cam_w = round(room.camera.width * _TOP_PX / room.camera.height)
        self._cam_size = (cam_w, _TOP_PX)
        #: ``(width, height)`` of every frame, pixels
        self.frame_size = (_even(_TOP_PX + cam_w), _even(_TOP_PX + _CAPTION_PX))
        #: number of frames written so far
        self.frames = 0
        self.top_view: TopView | None = None
        self._true_trail: list[tuple[float, float]] = []
        self._est_trail: list[tuple[int, int]] = []  # pixels
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, self._tmp = tempfile.mkstemp(
            prefix=f".{self.path.name}.", suffix=".part.mp4", dir=self.path.parent
        )
        os.close(fd)
        self._writer: cv2.VideoWriter | None = cv2.VideoWriter(
            self._tmp, cv2.VideoWriter_fourcc(*"mp4v"), fps, self.frame_size
        )
        if not self._writer.isOpened():
            self.abort()
            raise RuntimeError(
                f"OpenCV cannot write an MP4 video (codec 'mp4v') to {self.path}: this "
                "OpenCV build has no usable video writer (opencv-python-headless from PyPI "
                "has one; check cv2.getBuildInformation() under 'Video I/O')"
            )

    # ------------------------------------------------------------------ frames
    def __call__(self, step: EpisodeStep) -> None:
        """Render ``step`` and append it to the video."""
        if self._writer is None:
            raise RuntimeError(f"the video {self.path} is already closed")
        frame = self.render(step)
        self._writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
        self.frames += 1

    def render(self, step: EpisodeStep) -> np.ndarray:
        """The frame of ``step`` as an RGB ``uint8`` array of ``frame_size`` (it also
        extends the trails: call it once per step, in order)."""
        width, height = self.frame_size
        frame = np.zeros((height, width, 3), np.uint8)
        frame[_TOP_PX:] = _CAPTION_BG
        frame[:_TOP_PX, :_TOP_PX] = self._top(step)
        frame[:_TOP_PX, _TOP_PX : _TOP_PX + self._cam_size[0]] = self._camera(step)
        self._caption(frame, step)
        return frame

    def _camera(self, step: EpisodeStep) -> np.ndarray:
        image = step.image
        if image is None:
            image = self._room.head_image()
        image = np.asarray(image)
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 3:
            raise ValueError(
                f"the camera image must be uint8 (H, W, 3), got {image.dtype} {image.shape}"
            )
        out = cv2.resize(image, self._cam_size, interpolation=cv2.INTER_NEAREST)
        pan = float(step.info.get("head", (0.0,))[0])
        _text(out, f"head camera, pan {pan:+.0f} deg", (8, 20), box=True)
        return out

    def _top(self, step: EpisodeStep) -> np.ndarray:
        if self.top_view is None:
            room = self._room
            light = getattr(room, "light_direction_override", None)
            if light is None:
                light = getattr(room.scene, "light_direction", None)
            # the background is rendered once: without the robot, which would stay
            # painted at its first pose (hiding it changes no physics)
            robot = getattr(room, "robot", None)
            if robot is not None:
                robot.set_visible(False)
            try:
                self.top_view = TopView(room.client, room.scene, light, size_px=_TOP_PX)
            finally:
                if robot is not None:
                    robot.set_visible(True)
        top = self.top_view
        x, y, yaw = step.true_pose
        if self._true_trail and math.dist(self._true_trail[-1], (x, y)) > _JUMP_M:
            self._true_trail = []  # teleported: a new trail
        self._true_trail.append((x, y))
        pan = float(step.info.get("head", (0.0,))[0])
        img = top.draw(
            x, y, yaw, yaw + pan, self._room.camera.hfov_deg, trail=np.array(self._true_trail)
        )
        px_per_m = (top.to_px(top.center[0] + 10.0, 0.0)[0] - top.to_px(top.center[0], 0.0)[0]) / 10
        spots = self._spots()
        for name, (sx, sy) in spots.items():
            p = top.to_px(sx, sy)
            cv2.drawMarker(img, p, _SPOT_RGB, cv2.MARKER_TILTED_CROSS, 10, 2, cv2.LINE_AA)
            if len(spots) <= _MAX_SPOT_LABELS:
                _text(img, name, (p[0] + 6, p[1] - 6), _SPOT_RGB, 0.35)
        particles = self._particles()
        if particles is not None:
            every = max(1, math.ceil(len(particles) / _MAX_PARTICLES))
            for px, py in particles[::every, :2]:
                cv2.circle(img, top.to_px(px, py), 1, PARTICLE_RGB, -1)
        home = getattr(self._task, "home", None)
        if home is not None:
            cv2.drawMarker(img, top.to_px(*home), _HOME_RGB, cv2.MARKER_CROSS, 16, 2, cv2.LINE_AA)
        est = step.estimate
        if est is not None and all(math.isfinite(float(v)) for v in est["position"]):
            ex, ey = (float(v) for v in est["position"])
            c = top.to_px(ex, ey)
            self._est_trail.append(c)
            if len(self._est_trail) > 1:
                pts = np.array(self._est_trail, np.int32)
                cv2.polylines(img, [pts], False, ESTIMATE_RGB, 1, cv2.LINE_AA)
            std = est.get("position_std_m")
            if std is not None and all(math.isfinite(float(s)) for s in std):
                axes = tuple(int(round(min(float(s) * px_per_m, 2 * _TOP_PX))) for s in std)
                if max(axes) > 0:
                    cv2.ellipse(img, c, axes, 0.0, 0.0, 360.0, ESTIMATE_RGB, 1, cv2.LINE_AA)
            cv2.circle(img, c, _RING_PX, ESTIMATE_RGB, 2, cv2.LINE_AA)
            h = math.radians(float(est["heading_deg"]))
            tip = top.to_px(ex + _ARROW_M * math.cos(h), ey + _ARROW_M * math.sin(h))
            cv2.arrowedLine(img, c, tip, ESTIMATE_RGB, 2, cv2.LINE_AA, tipLength=0.3)
        _text(img, "top view (north up)", (8, 18), box=True)
        return img

    def _particles(self) -> np.ndarray | None:
        """The tracker's particles ``(N, >= 2)``, or ``None`` (no tracker, none, or not
        finite)."""
        p = getattr(self._tracker, "particles", None)
        if p is None:
            return None
        p = np.asarray(p, np.float64)
        if p.ndim != 2 or p.shape[1] < 2 or not np.all(np.isfinite(p[:, :2])):
            return None
        return p

    def _spots(self) -> dict[str, tuple[float, float]]:
        if self._given_spots is not None:
            return dict(self._given_spots)
        learned = getattr(self._task, "learning_result", None)
        if learned is not None:
            return dict(learned.spots)
        atlas = getattr(self._task, "atlas", None)
        if atlas is not None:
            return dict(zip(atlas.names, map(tuple, atlas.positions), strict=True))
        return {}

    def _caption(self, frame: np.ndarray, step: EpisodeStep) -> None:
        info: dict[str, Any] = step.info
        x, y, yaw = step.true_pose
        home = getattr(self._task, "home", None)
        est = step.estimate
        if est is None:
            belief = "no estimate"
        else:
            err = float(wrap180(float(est["heading_deg"]) - yaw))
            ex, ey = (float(v) for v in est["position"])
            belief = f"heading error {err:+6.1f} deg"
            if home is None:
                belief += f" | position error {math.hypot(ex - x, ey - y):4.2f} m"
            else:
                believed = math.hypot(ex - home[0], ey - home[1])
                belief += f" | believed {believed:4.2f} m from home"
        if home is None:  # a room: no home to be far from
            line = f"t {step.sim_time_s:5.1f} s | {belief}"
        else:
            dist = math.hypot(x - home[0], y - home[1])
            line = f"t {step.sim_time_s:5.1f} s | {dist:4.2f} m from home | {belief}"
        if "kidnapped_at_s" in info:
            line += f" | kidnapped at {float(info['kidnapped_at_s']):.1f} s"
        if "stop_error_m" in info:
            if info.get("fallen"):
                end = "FELL"
            elif info.get("stopped"):
                end = "STOPPED: " + ("success" if info.get("success") else "missed home")
            else:
                end = "TIME OUT"
            line += f" | {end}"
        _text(frame, line, (8, _TOP_PX + 20))
        # legend
        yl = _TOP_PX + 42
        xl = 8
        cv2.rectangle(frame, (xl, yl - 9), (xl + 14, yl), TRUE_RGB, -1)
        xl = _text(frame, "true pose", (xl + 20, yl)) + 16
        cv2.circle(frame, (xl + 7, yl - 5), 6, ESTIMATE_RGB, 2, cv2.LINE_AA)
        xl = _text(frame, "estimate (ellipse: 1 sigma)", (xl + 20, yl)) + 16
        if home is not None:
            cv2.drawMarker(frame, (xl + 7, yl - 5), _HOME_RGB, cv2.MARKER_CROSS, 12, 2)
            xl = _text(frame, "home", (xl + 18, yl)) + 16
        if self._particles() is not None:
            cv2.circle(frame, (xl + 7, yl - 5), 2, PARTICLE_RGB, -1)
            xl = _text(frame, "particles", (xl + 16, yl)) + 16
        cv2.drawMarker(frame, (xl + 7, yl - 5), _SPOT_RGB, cv2.MARKER_TILTED_CROSS, 10, 2)
        xl = _text(frame, "training spots", (xl + 18, yl)) + 16
        cv2.line(frame, (xl, yl - 5), (xl + 14, yl - 5), _TRUE_TRAIL_RGB, 2)
        _text(frame, "true path", (xl + 20, yl))

    # ------------------------------------------------------------------ file
    def close(self) -> Path:
        """Finish the video and move it to ``path`` (atomically); returns ``path``.

        Raises ``RuntimeError`` (and writes nothing) if no frame was recorded.
        Closing again does nothing.
        """
        if self._writer is None:
            return self.path
        self._writer.release()
        self._writer = None
        if self.frames == 0:
            self.abort()
            raise RuntimeError(f"no frame was recorded; {self.path} was not written")
        tmp = self._tmp
        try:
            # write_atomic gives the file the usual permissions (mkstemp's are 0600)
            write_atomic(self.path, lambda dest: os.replace(tmp, dest))
        finally:
            self.abort()  # removes the stream file if the move failed
        return self.path

    def abort(self) -> None:
        """Stop without writing ``path`` (the partial video is deleted)."""
        if self._writer is not None:
            self._writer.release()
            self._writer = None
        try:
            os.unlink(self._tmp)
        except FileNotFoundError:
            pass

    def __enter__(self) -> EpisodeVideo:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def _text(
    img: np.ndarray,
    text: str,
    org: tuple[int, int],
    color: tuple[int, int, int] = _TEXT_RGB,
    scale: float = 0.45,
    box: bool = False,
) -> int:
    """Draw ``text`` at ``org`` (baseline left), on a dark box if ``box``; returns its
    right end. (No outline: OpenCV 5 draws a thicker line with wider glyphs.)"""
    (w, h), base = cv2.getTextSize(text, _FONT, scale, 1)
    if box:
        x, y = org
        cv2.rectangle(img, (x - 3, y - h - 3), (x + w + 3, y + base), _CAPTION_BG, -1)
    cv2.putText(img, text, org, _FONT, scale, color, 1, cv2.LINE_AA)
    return org[0] + w


def write_episode_video(
    run: HomingRun,
    seed: int | None,
    path: str | os.PathLike,
    *,
    options: dict[str, Any] | None = None,
    progress: bool = False,
    fps: float | None = None,
) -> EpisodeRecord:
    """Run one episode (:func:`~vc_gym.experiments.episode.run_episode`) and write its
    video to ``path``; returns the episode's record, the same as without the video.

    Make the run with ``make_homing_run(..., keep_image=True)`` to take the camera
    frames from the observations; otherwise each frame is rendered once more. On an
    error nothing is written to ``path``.
    """
    with EpisodeVideo(path, run.env, fps=fps) as video:
        return run_episode(run, seed=seed, options=options, progress=progress, on_step=video)
