"""Cost of the bearing sensor per frame, in a simulated room.

The learning turns of the ``pose-home`` mode are rendered at their true poses (home and
the four spots 1 m around it, each with the turns 0.5 m around it, every 30°); their
colour changes are triangulated into landmarks
(:func:`~vc_gym.compass.landmarks.learn_landmarks`). Frames from seeded random
poses of the field are rendered once; each round then reads every frame's changes
(:func:`~vc_gym.compass.bearings.bands_bearings`, the default bands) and scores
``poses`` candidate poses around the truth
(:class:`~vc_gym.localization.bearing_sensor.BearingSensor`). The medians over the
rounds are reported per frame, with the landmarks' count and the changes a frame shows.
"""

from __future__ import annotations

import time

import numpy as np
from tqdm import tqdm

from vc_gym.compass import Camera
from vc_gym.compass.bearings import bands_bearings
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.landmarks import LearnedView, learn_landmarks
from vc_gym.localization.bearing_sensor import BearingSensor
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.robot import EYE_OFFSET_M
from vc_gym.sim.scenes import check_scene_name
from vc_gym.validation import check_seed, int_in_range

__all__ = ["MAX_FRAMES", "MAX_POSES", "bench_bearings", "frame_at_pose"]

#: Most test frames (each is rendered and kept in memory).
MAX_FRAMES = 10_000
#: Most candidate poses scored per frame.
MAX_POSES = 100_000
#: Most rounds.
MAX_REPEATS = 1_000
#: Where the learning turns are: home, the spots, and 0.5 m around each.
_SPOTS = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))
_AROUND = ((0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (-0.5, 0.0), (0.0, -0.5))


def frame_at_pose(room: AiboRoomEnv, camera: Camera, x: float, y: float, yaw: float):
    """The robot put at the body pose ``(x, y, yaw)`` (head straight): the head camera's
    image, ``camera`` with the head's pitch, the eye's ``(x, y, yaw)`` and the body's
    true pose."""
    obs, info = room.reset(seed=0, options={"pose": (x, y, yaw)})
    eye, eye_yaw, pitch = room.robot.eye()
    return obs["image"], camera.replace(pitch_deg=pitch), (eye[0], eye[1], eye_yaw), info["pose"]


def bench_bearings(
    frames: int = 40,
    repeats: int = 15,
    poses: int = 500,
    scene: str = "robolab",
    seed: int = 0,
    progress: bool = True,
) -> dict:
    """Median cost per frame of reading a frame's bearings and scoring ``poses`` poses.

    Parameters
    ----------
    frames : int
        Test frames, from seeded random poses of the scene's field (1 to
        :data:`MAX_FRAMES`).
    repeats : int
        Timed rounds over all frames (1 to :data:`MAX_REPEATS`).
    poses : int
        Candidate poses per frame, uniform within 0.5 m and 10° of the truth (1 to
        :data:`MAX_POSES`).
    scene : str
        A registered scene.
    seed : int
        Seed of the colour classes, the test poses and the candidates.

    Returns
    -------
    dict
        ``landmarks``, ``learning_frames``, ``changes_per_frame`` (median),
        ``bearings_ms`` and ``likelihood_ms`` (median per frame), ``poses``, ``frames``,
        ``repeats``, ``scene``, ``seed``.
    """
    int_in_range("frames", frames, 1, MAX_FRAMES)
    int_in_range("repeats", repeats, 1, MAX_REPEATS)
    int_in_range("poses", poses, 1, MAX_POSES)
    check_scene_name(scene)
    check_seed("seed", seed)
    rng = np.random.default_rng(seed)
    room = AiboRoomEnv(scene=scene)
    try:
        camera = Camera(hfov_deg=room.camera.hfov_deg)
        turns = [
            frame_at_pose(room, camera, sx + ax, sy + ay, float(yaw))
            for sx, sy in _SPOTS
            for ax, ay in _AROUND
            for yaw in range(0, 360, 30)
        ]
        colors = ColorClasses.fit([t[0] for t in turns[::4]], rng=np.random.default_rng(seed))
        views = [
            LearnedView(bands_bearings(image, cam, colors), eye[2], eye[0], eye[1])
            for image, cam, eye, _ in turns
        ]
        sensor = BearingSensor(
            learn_landmarks(views), colors, camera, eye_forward_m=EYE_OFFSET_M[0]
        )
        x0, x1, y0, y1 = (float(v) for v in room.scene.field_bounds)
        tests = []
        for _ in range(frames):
            x, y = rng.uniform([x0 + 0.3, y0 + 0.3], [x1 - 0.3, y1 - 0.3])
            yaw = float(rng.uniform(0, 360))
            image, cam, _, truth = frame_at_pose(room, camera, float(x), float(y), yaw)
            near = np.asarray(truth, np.float64) + rng.uniform(
                [-0.5, -0.5, -10.0], [0.5, 0.5, 10.0], (poses, 3)
            )
            tests.append((image, cam, near))
    finally:
        room.close()
    read, score, changes = [], [], []
    for _ in tqdm(range(repeats), desc="bench bearings", disable=not progress):
        t_read = t_score = 0.0
        for image, cam, near in tests:
            t0 = time.perf_counter()
            found = bands_bearings(image, cam, colors)
            t1 = time.perf_counter()
            sensor.pose_log_likelihood(found, near)
            t_score += time.perf_counter() - t1
            t_read += t1 - t0
            changes.append(len(found))
        read.append(1000.0 * t_read / frames)
        score.append(1000.0 * t_score / frames)
    return {
        "scene": scene,
        "seed": seed,
        "frames": frames,
        "repeats": repeats,
        "poses": poses,
        "learning_frames": len(views),
        "landmarks": len(sensor.landmarks),
        "changes_per_frame": float(np.median(changes)),
        "bearings_ms": float(np.median(read)),
        "likelihood_ms": float(np.median(score)),
    }
