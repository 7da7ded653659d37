"""Pictures of the scenes: a top view and a 360° strip of head-camera views."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from vc_gym.jobs.output import check_out_dir
from vc_gym.persistence import write_atomic
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.sim.scenes import check_scene_name, scene_names

__all__ = ["render_scene_pictures"]


def _write_png(path: Path, rgb: np.ndarray) -> None:
    def write(tmp: str) -> None:
        # the temporary name ends in .png, so OpenCV picks the PNG encoder
        if not cv2.imwrite(tmp, cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)):
            raise OSError(f"could not write {path}")

    write_atomic(path, write)


def render_scene_pictures(
    out_dir: str | os.PathLike,
    scenes: str | Sequence[str] | None = None,
    seed: int = 0,
    randomize: bool = False,
    n_views: int = 8,
) -> list[Path]:
    """Write ``{scene}_top.png`` and ``{scene}_strip.png`` for each scene.

    The robot stands at the centre of the field; the strip holds ``n_views`` head
    frames at headings ``0, 360/n, ...`` degrees, left to right, labelled.

    Parameters
    ----------
    out_dir : str or os.PathLike
        Output folder (created if missing).
    scenes : str or sequence of str, optional
        Registered scene name(s); default: every registered scene
        (:func:`vc_gym.sim.scenes.scene_names`). All are checked before anything is
        rendered.
    seed : int
        Reset seed (and scene seed when ``randomize``).
    randomize : bool
        Domain-randomised scenes.
    n_views : int
        Head frames in each strip.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    ValueError
        On an unknown scene name or ``n_views < 1``.
    """
    if n_views < 1:
        raise ValueError(f"n_views must be >= 1, got {n_views}")
    if isinstance(scenes, str):
        scenes = (scenes,)
    scenes = scene_names() if scenes is None else tuple(scenes)
    for scene in scenes:
        check_scene_name(scene)
    out = check_out_dir(out_dir)
    written = []
    for scene in scenes:
        env = AiboRoomEnv(render_mode="rgb_array", scene=scene, randomize=randomize)
        try:
            env.reset(seed=seed)
            fx0, fx1, fy0, fy1 = env.scene.field_bounds
            cx, cy = (fx0 + fx1) / 2.0, (fy0 + fy1) / 2.0
            views = []
            for k in range(n_views):
                yaw = 360.0 * k / n_views
                obs, _ = env.reset(seed=seed, options={"pose": (cx, cy, yaw)})
                img = obs["image"].copy()
                cv2.putText(
                    img,
                    f"{yaw:.0f} deg",
                    (4, 14),
                    cv2.FONT_HERSHEY_SIMPLEX,
                    0.45,
                    (255, 255, 255),
                    1,
                    cv2.LINE_AA,
                )
                views.append(img)
            env.reset(seed=seed, options={"pose": (cx, cy, 30.0)})
            frame = env.render()
            top = frame[:, : frame.shape[0]]
            for name, rgb in ((f"{scene}_top.png", top), (f"{scene}_strip.png", np.hstack(views))):
                _write_png(out / name, rgb)
                written.append(out / name)
        finally:
            env.close()
    return written
