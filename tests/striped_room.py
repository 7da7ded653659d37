"""A ray-cast room whose colour edges are known exactly: vertical stripes of six colours
on its walls, and the learning turns seen in it (shared by the bearing, landmark and
turn-placement tests)."""

from __future__ import annotations

import numpy as np

from vc_gym.compass import Camera
from vc_gym.compass.bearings import frame_bearings
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.landmarks import LearnedView
from vc_gym.worlds.room import Room, render_room_view

HFOV = 56.9
PALETTE = np.array(
    [[200, 40, 40], [40, 160, 60], [40, 70, 200], [230, 210, 60], [150, 60, 170], [240, 240, 235]],
    np.uint8,
)
PX_PER_M = 200


def striped_room():
    """A 5 x 4 m room whose walls are vertical stripes of six colours, 0.3-0.9 m wide:
    its colour changes (the landmarks) lie at known points of the walls."""
    rng = np.random.default_rng(4)
    width, depth = 5.0, 4.0
    perimeter = 2 * (width + depth)
    edges, s, last = [], 0.0, -1
    colours = []
    while s < perimeter - 0.3:
        c = int(rng.choice([k for k in range(len(PALETTE)) if k != last]))
        colours.append((s, c))
        last = c
        s += rng.uniform(0.3, 0.9)
        if s < perimeter - 0.3:
            edges.append(s)
    tex = np.zeros((120, int(perimeter * PX_PER_M), 3), np.uint8)
    bounds = [c[0] for c in colours] + [perimeter]
    for (s0, c), s1 in zip(colours, bounds[1:], strict=True):
        tex[:, int(round(s0 * PX_PER_M)) : int(round(s1 * PX_PER_M))] = PALETTE[c]
    room = Room(width, depth, 1.0, tex, floor_rgb=(90, 90, 90), ceiling_rgb=(20, 20, 20))
    if colours[-1][1] != colours[0][1]:
        edges.append(0.0)  # where the unrolled walls close, at the corner (W/2, -D/2)
    # the texture's columns start at pixel edges: an edge at s sits at round(s * px) / px
    points = np.array([room.wall_point(round(e * PX_PER_M) / PX_PER_M) for e in edges])
    return room, points


def view(room, x, y, yaw):
    camera = Camera(hfov_deg=HFOV, yaw_deg=yaw)
    return render_room_view(room, x, y, camera), camera


def true_offsets(points, x, y, yaw):
    ang = np.degrees(np.arctan2(points[:, 1] - y, points[:, 0] - x)) - yaw
    ang = (ang + 180.0) % 360.0 - 180.0
    return ang[np.abs(ang) < HFOV / 2 - 1.0]


def learned_views(striped):
    """Colour classes and the learning turns: 8 directions at home, the four spots 1 m
    away and the turns 0.5 m around home."""
    room, _ = striped
    positions = [(0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (0.5, 0), (0, 0.5), (-0.5, 0), (0, -0.5)]
    yaws = range(0, 360, 45)
    frames = [(x, y, yaw, *view(room, x, y, yaw)) for x, y in positions for yaw in yaws]
    colors = ColorClasses.fit([f[3] for f in frames[::4]], n_colors=8, rng=np.random.default_rng(0))
    views = [
        LearnedView(frame_bearings(img, cam, colors), float(yaw), float(x), float(y))
        for x, y, yaw, img, cam in frames
    ]
    return colors, views
