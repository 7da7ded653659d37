"""The visual compass on its own: learn a spot of a ray-cast room, then estimate the
heading of views taken further and further away from it.

    python examples/compass_in_a_room.py --out compass_errors.png

Prints the median heading error at each distance and plots it (the paper's fig. 4 in
miniature: the compass is exact at the spot and degrades with parallax).
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from vc_gym import wrap180  # noqa: E402
from vc_gym.compass import Camera, VisualCompass  # noqa: E402
from vc_gym.worlds import make_room, render_room_view  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="seed of the room")
    parser.add_argument("--views", type=int, default=40, help="test views per distance")
    parser.add_argument("--out", default="compass_errors.png", help="the plot (PNG)")
    args = parser.parse_args()

    room = make_room(np.random.default_rng(args.seed))
    cam = Camera(hfov_deg=56.9)
    compass = VisualCompass()
    yaws = range(0, 360, 45)  # a turn on the spot: 8 views 45° apart
    turn = [(render_room_view(room, 0.0, 0.0, cam.replace(yaw_deg=y)), y) for y in yaws]
    compass.fit_colors([image for image, _ in turn])
    for image, yaw in turn:
        compass.learn(image, cam.replace(yaw_deg=yaw))

    rng = np.random.default_rng(args.seed + 1)
    distances = [0.0, 0.25, 0.5, 1.0, 1.5, 2.0]
    medians = []
    for d in distances:
        errors = []
        for _ in range(args.views):
            yaw, bearing = rng.uniform(0.0, 360.0, 2)
            x, y = d * np.cos(np.radians(bearing)), d * np.sin(np.radians(bearing))
            image = render_room_view(room, x, y, cam.replace(yaw_deg=yaw))
            errors.append(abs(wrap180(compass.estimate(image, cam).heading_deg - yaw)))
        medians.append(float(np.median(errors)))
        print(f"{d:4.2f} m from the spot: median heading error {medians[-1]:6.2f}°")

    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.plot(distances, medians, "o-")
    ax.set_xlabel("distance from the learned spot (m)")
    ax.set_ylabel("median heading error (°)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
