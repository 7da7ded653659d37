"""Scene types: a built :class:`Scene`, and the :class:`SceneLayout` its builder returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

__all__ = ["Scene", "SceneLayout"]


@dataclass(frozen=True)
class Scene:
    """A built scene: where things are, for the env, the robot and the top view.

    Attributes
    ----------
    name : str
        Registered name of the scene (see :func:`vc_gym.sim.scenes.scene_names`).
    room_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces (outdoor: the area the
        robot may ever reach, fenced by invisible walls).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` where the robot may be placed or kidnapped to
        (robolab: the 6 x 4 m carpet). It is free of obstacles and inside
        ``room_bounds``.
    obstacles : tuple of tuple of float
        Floor-plane footprints ``(xmin, xmax, ymin, ymax)`` of walls, fences and
        furniture that reach below 0.35 m, for kinematic collision checks.
    body_ids : tuple of int
        Every body of the scene; ``body_ids[0]`` is the floor (lateral friction 1.0).
    light_direction : tuple of float
        Unit vector towards the light, for ``getCameraImage(lightDirection=...)``.
    background_rgb : tuple of int or None
        Colour where camera rays hit nothing; ``None`` because every scene is closed.
    ceiling_ids : tuple of int
        Bodies to hide when the scene is viewed from above (ceiling, sky lid). They are
        single-sided, so a camera above them does not see them anyway.
    """

    name: str
    room_bounds: tuple[float, float, float, float]
    field_bounds: tuple[float, float, float, float]
    obstacles: tuple[tuple[float, float, float, float], ...]
    body_ids: tuple[int, ...]
    light_direction: tuple[float, float, float]
    background_rgb: tuple[int, int, int] | None = None
    ceiling_ids: tuple[int, ...] = field(default=())


class SceneLayout(NamedTuple):
    """What a scene builder returns (a plain 3-tuple in the same order works too).

    Attributes
    ----------
    room_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the walls' inner faces, or of the area the robot
        may reach outdoors (see :attr:`Scene.room_bounds`).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` where the robot may be placed: free of obstacles
        (keep furniture at least 0.2 m away) and inside ``room_bounds``.
    light_direction : tuple of float
        Vector towards the light, pointing up (``z > 0``); :func:`~vc_gym.sim.scenes.
        furniture.sun` gives a canonical or randomised one. Normalised by
        :func:`~vc_gym.sim.scenes.build_scene`.
    """

    room_bounds: tuple[float, float, float, float]
    field_bounds: tuple[float, float, float, float]
    light_direction: tuple[float, float, float]
