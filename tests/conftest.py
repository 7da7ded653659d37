"""Shared fixtures: seeded synthetic scenes, the optional real photo folder, and a place
cache of the test session's own; hypothesis' profiles.

Hypothesis runs the ``default`` profile: a small, derandomised search without deadlines
(the same examples every run, on any machine's speed). ``VC_GYM_HYPOTHESIS=thorough``
searches ten times as many random examples.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

from vc_gym.compass import Camera, CompassAtlas, CompassConfig, VisualCompass, wrap180
from vc_gym.experiments.real_data import default_real_data_dir
from vc_gym.worlds.panorama import Panorama, render_view
from vc_gym.worlds.panorama_painters import make_panorama
from vc_gym.worlds.room import Room, make_room, render_room_view

settings.register_profile("default", max_examples=50, derandomize=True, deadline=None)
settings.register_profile("thorough", max_examples=500, derandomize=False, deadline=None)
settings.load_profile(os.environ.get("VC_GYM_HYPOTHESIS", "default"))

#: Yaws of the learning frames: 8 body directions x 3 head pans (paper 4.3).
LEARN_YAWS = [body + pan for body in range(0, 360, 45) for pan in (-22.5, 0.0, 22.5)]


@pytest.fixture(scope="session", autouse=True)
def place_cache_dir(tmp_path_factory):
    """Learned places of this test session go to a temporary folder (``VC_GYM_CACHE``,
    inherited by subprocesses), never to the user's cache. The xdist workers of one run
    share it (the cache locks its files), so a place is learned once per run."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        folder = tmp_path_factory.getbasetemp().parent / "vc_gym_cache"
        folder.mkdir(exist_ok=True)
    else:
        folder = tmp_path_factory.mktemp("vc_gym_cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("VC_GYM_CACHE", str(folder))
        yield folder


@pytest.fixture(scope="session")
def room_pano() -> Panorama:
    return make_panorama(np.random.default_rng(7), width=2400, height=600, kind="room")


@pytest.fixture(scope="session")
def outdoor_pano() -> Panorama:
    return make_panorama(np.random.default_rng(8), width=2400, height=600, kind="outdoor")


def learned_compass(pano: Panorama, config: CompassConfig | None = None) -> VisualCompass:
    """A compass that learned ``pano`` from LEARN_YAWS (colours fitted on the 0-pan views)."""
    vc = VisualCompass(config)
    vc.fit_colors([render_view(pano, Camera(yaw_deg=a)) for a in range(0, 360, 45)])
    for yaw in LEARN_YAWS:
        vc.learn(render_view(pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    return vc


@pytest.fixture(scope="session")
def make_learned_compass():
    """The :func:`learned_compass` factory, for tests that need their own config."""
    return learned_compass


def heading_errors(
    vc: VisualCompass, pano: Panorama, yaws, illumination: float = 1.0, **cam_kwargs
) -> np.ndarray:
    """|heading error| (deg) of ``vc`` on views of ``pano`` at ``yaws`` (lit ×
    ``illumination``; ``cam_kwargs`` such as ``pitch_deg`` for the camera)."""
    errs = []
    for yaw in yaws:
        img = render_view(pano, Camera(yaw_deg=yaw, **cam_kwargs), illumination=illumination)
        est = vc.estimate(img, Camera(**cam_kwargs))
        errs.append(abs(wrap180(est.heading_deg - yaw)))
    return np.array(errs)


@pytest.fixture(scope="session")
def view_heading_errors():
    """The :func:`heading_errors` helper, for tests that measure a compass on views."""
    return heading_errors


@pytest.fixture(scope="session")
def room_compass(room_pano: Panorama) -> VisualCompass:
    return learned_compass(room_pano)


#: Four training spots 1 m around home, as in the paper's homing experiment (5.2).
ROOM_SPOTS = {"east": (1.0, 0.0), "north": (0.0, 1.0), "west": (-1.0, 0.0), "south": (0.0, -1.0)}


@pytest.fixture(scope="session")
def synthetic_room() -> Room:
    """A ray-cast room with real parallax (seeded)."""
    return make_room(np.random.default_rng(3))


def learned_room_atlas(room: Room, config: CompassConfig | None = None) -> CompassAtlas:
    """Compasses learned at ROOM_SPOTS in ``room``, normalised at (0, 0)."""
    colors = None
    spots = {}
    for name, (x, y) in ROOM_SPOTS.items():
        vc = VisualCompass(config or CompassConfig(), colors)
        if colors is None:
            vc.fit_colors(
                [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in range(0, 360, 45)]
            )
            colors = vc.colors
        for a in LEARN_YAWS:
            vc.learn(render_room_view(room, x, y, Camera(yaw_deg=a)), Camera(yaw_deg=a))
        spots[name] = ((x, y), vc)
    atlas = CompassAtlas(spots, home="centre")
    home = [render_room_view(room, 0.0, 0.0, Camera(yaw_deg=a)) for a in range(0, 360, 10)]
    atlas.normalize(home, [Camera()] * len(home))
    return atlas


def learned_room_turn(
    room: Room, x: float, y: float, colors=None, yaws=LEARN_YAWS, config=None
) -> VisualCompass:
    """A full turn learned at ``(x, y)`` in ``room`` from ``yaws`` (colour classes fitted
    on that spot's 0-pan views unless ``colors`` are given), with ``config`` (default
    the paper's)."""
    vc = VisualCompass(config or CompassConfig(), colors)
    if colors is None:
        vc.fit_colors([render_room_view(room, x, y, Camera(yaw_deg=a)) for a in range(0, 360, 45)])
    for a in yaws:
        vc.learn(render_room_view(room, x, y, Camera(yaw_deg=a)), Camera(yaw_deg=a))
    return vc


@pytest.fixture(scope="session")
def learn_room_turn():
    """The :func:`learned_room_turn` factory."""
    return learned_room_turn


@pytest.fixture(scope="session")
def room_atlas(synthetic_room: Room) -> CompassAtlas:
    """The paper's compasses learned at ROOM_SPOTS in :func:`synthetic_room`."""
    return learned_room_atlas(synthetic_room)


@pytest.fixture(scope="session")
def make_room_atlas():
    """The :func:`learned_room_atlas` factory, for tests that need their own config."""
    return learned_room_atlas


@pytest.fixture(scope="session")
def real_data_dir():
    d = default_real_data_dir()
    if d is None:
        pytest.skip("real photos not found (set VC_GYM_REAL_DATA or place ../shared/data/real)")
    return d
