"""Write the footage the docs' compass examples read: ``turn.mp4`` (a camera turning once
to the left in place, at a constant rate, 66° wide) and ``walk.mp4`` with its true yaws in
``walk_yaws.csv``, both cut from one seeded synthetic panorama, into the current folder."""

from __future__ import annotations

import csv

import cv2
import numpy as np

from vc_gym.compass import Camera
from vc_gym.worlds import make_panorama, render_view

HFOV_DEG = 66.0


def write_video(path: str, yaws: np.ndarray, pano) -> None:
    writer = cv2.VideoWriter(path, cv2.VideoWriter_fourcc(*"mp4v"), 10.0, (208, 160))
    for yaw in yaws:
        frame = render_view(pano, Camera(hfov_deg=HFOV_DEG, yaw_deg=float(yaw)))
        writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
    writer.release()


def main() -> None:
    pano = make_panorama(np.random.default_rng(7))
    write_video("turn.mp4", np.arange(72) * 5.0, pano)  # one full turn, 5° a frame
    walk = np.random.default_rng(8).uniform(0.0, 360.0, 30)
    write_video("walk.mp4", walk, pano)
    with open("walk_yaws.csv", "w", newline="") as fh:
        rows = csv.writer(fh)
        rows.writerow(["frame", "yaw_deg"])
        rows.writerows((i, f"{yaw:.3f}") for i, yaw in enumerate(walk))


if __name__ == "__main__":
    main()
