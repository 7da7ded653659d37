"""Frames from the robot standing at a pose: :func:`frames_at_pose` (scanning with its head, paper
5.1) and :func:`learning_turn` (a full turn with the true camera yaws, paper 4.3)."""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence

import numpy as np

from vc_gym.compass import Camera
from vc_gym.deprecation import moved_names
from vc_gym.envs.learning import HEAD_SCAN_DEG, RobotFell
from vc_gym.experiments.views.checks import int_at_least
from vc_gym.poses import check_pose
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.validation import finite_float

__all__ = ["Frame", "check_frames", "frames_at_pose", "learning_turn"]

#: One frame of :func:`frames_at_pose`: ``(image, measured head pan in degrees, odometry
#: (forward m, left m, turn deg) since the previous frame)``.
Frame = tuple[np.ndarray, float, tuple[float, float, float]]


def check_frames(frames: object) -> list[Frame]:
    """``frames`` as a non-empty list of ``(image, head_pan_deg, odometry)``, or a
    ValueError (the pans must be finite; images are checked where they are used)."""
    if isinstance(frames, np.ndarray) or not isinstance(frames, Sequence) or len(frames) == 0:
        raise ValueError("frames must be a non-empty sequence of (image, head_pan_deg, odometry)")
    out = []
    for i, frame in enumerate(frames):
        try:
            image, pan, odo = frame
        except (TypeError, ValueError):
            raise ValueError(
                f"frame {i} must be (image, head_pan_deg, odometry), got {type(frame).__name__}"
            ) from None
        out.append((image, finite_float(f"frame {i} head_pan_deg", pan), odo))
    return out


def frames_at_pose(
    room: AiboRoomEnv,
    pose: tuple[float, float, float] | np.ndarray,
    frames: int,
    seed: int,
    head_scan_deg: Sequence[float] = HEAD_SCAN_DEG,
) -> list[Frame]:
    """Put the robot at ``pose`` and let it stand there scanning with its head (5.1).

    The room is reset with ``seed`` at ``pose`` (``options={"pose": pose}``); the
    reset's frame is the first one. For every further frame ``k = 1, 2, ...`` the
    robot stands still (zero velocities) and commands the head pan
    ``head_scan_deg[k % len(head_scan_deg)]``; the head moves at its bounded speed, so
    the *measured* pan (``obs["head"][0]``) is what is returned. With the default scan
    the head moves 0° → -20° → 0° → 20° → 40° → 20° → ...

    The result depends only on the arguments: the reset re-seeds the room and puts the
    robot and its head in a fixed state, so a reused room gives the same frames as a
    fresh one.

    Parameters
    ----------
    room : AiboRoomEnv
        The room env; a wrapped env is unwrapped.
    pose : tuple of float
        ``(x, y, yaw_deg)`` of the robot, world frame.
    frames : int
        Number of frames, >= 1 (the reset frame included).
    seed : int
        Seed of the reset (odometry errors; the scene when randomised).
    head_scan_deg : sequence of float
        Head pans cycled while standing (within ±90°).

    Returns
    -------
    list of tuple
        ``(image, head_pan_deg, odometry)`` per frame: the ``(H, W, 3)`` uint8 RGB
        image, the measured head pan in degrees (float) and the odometry since the
        previous frame ``(forward m, left m, turn deg)`` as floats (zeros for the
        reset frame).

    Raises
    ------
    ValueError
        On a room that is not an ``AiboRoomEnv``, a bad pose, frame count, seed or scan.
    RobotFell
        If the robot falls (only with ``locomotion="dynamic"``).
    """
    env = getattr(room, "unwrapped", room)
    if not isinstance(env, AiboRoomEnv):
        raise ValueError(f"room must be an AiboRoomEnv, got {type(room).__name__}")
    x, y, yaw = check_pose(pose)
    n = int_at_least("frames", frames, 1)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    pans = tuple(float(p) for p in head_scan_deg)
    if not pans or not all(math.isfinite(p) and abs(p) <= 90.0 for p in pans):
        raise ValueError(f"head_scan_deg must be non-empty pans within ±90°, got {head_scan_deg!r}")

    def frame(obs: dict[str, np.ndarray]) -> Frame:
        odo = tuple(float(v) for v in obs["odometry"])
        return obs["image"], float(obs["head"][0]), odo  # type: ignore[return-value]

    obs, _ = env.reset(seed=int(seed), options={"pose": (x, y, yaw)})
    out = [frame(obs)]
    for k in range(1, n):
        action = env.velocity_action(pan_deg=pans[k % len(pans)])
        obs, _, terminated, _, _ = env.step(action)
        if terminated:
            raise RobotFell(f"the robot fell while standing at {(x, y, yaw)} (frame {k})")
        out.append(frame(obs))
    return out


def learning_turn(
    room: AiboRoomEnv, spot: Sequence[float], frames_per_direction: int, seed: int
) -> list[tuple[np.ndarray, Camera]]:
    """The frames of a learning turn at ``spot`` with their true camera yaws.

    The robot stands facing 0°, 45°, ..., 315° in turn (paper 4.3), scanning with its
    head for ``frames_per_direction`` frames each (:func:`frames_at_pose`, seeds ``seed + k``);
    every frame comes with the camera that took it (its yaw the body's plus the
    measured pan). The truth, not odometry: every sensor taught with it gets the
    same, exact headings.
    """
    env = getattr(room, "unwrapped", room)
    camera = Camera(hfov_deg=env.camera.hfov_deg)
    out = []
    for k in range(8):
        for image, pan, _ in frames_at_pose(
            room, (*spot, 45.0 * k), frames_per_direction, seed=seed + k
        ):
            out.append((image, camera.replace(yaw_deg=45.0 * k + pan)))
    return out

__getattr__ = moved_names(__name__, {"look": (sys.modules[__name__], "frames_at_pose")})
