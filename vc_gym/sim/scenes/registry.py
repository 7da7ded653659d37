"""The scene registry: names to builder functions, and :func:`build_scene`.

Every part of vc_gym that takes a scene name (``AiboRoom-v0``'s ``scene=``, the
learn-then-home task, ``vc-gym render`` and ``vc-gym train``, the benchmarks) looks it up
here, so a scene registered with :func:`register_scene` works everywhere a built-in one
does — in the process that registered it (see the package docstring for worker
processes).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from vc_gym.sim.scenes.builder import Builder
from vc_gym.sim.scenes.scene import Scene, SceneLayout

__all__ = [
    "build_scene",
    "check_scene_name",
    "register_scene",
    "scene_names",
    "unregister_scene",
]

#: A scene builder: creates the bodies through the builder and returns the layout.
SceneBuilder = Callable[[Builder], Any]
_F = TypeVar("_F", bound=Callable[..., Any])

_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
#: Names that cannot be scenes: ``vc-gym render --scene all`` means every scene.
_RESERVED = frozenset({"all"})


@dataclass(frozen=True)
class _Entry:
    builder: SceneBuilder
    canonical_seed: int


_REGISTRY: dict[str, _Entry] = {}


def scene_names() -> tuple[str, ...]:
    """Names of the registered scenes, in the order they were registered.

    The built-in scenes (:data:`vc_gym.sim.scenes.SCENES`) come first.

    Returns
    -------
    tuple of str
        The names :func:`build_scene` accepts.
    """
    return tuple(_REGISTRY)


def _listing() -> str:
    return ", ".join(_REGISTRY) or "(none)"


def check_scene_name(name: object) -> str:
    """Return ``name`` if it is a registered scene, else raise a ``ValueError``.

    Parameters
    ----------
    name : object
        The name to check.

    Returns
    -------
    str
        ``name``.

    Raises
    ------
    ValueError
        If ``name`` is not a registered scene name; the message lists the registered
        ones and says how to add one.
    """
    if not isinstance(name, str) or name not in _REGISTRY:
        raise ValueError(
            f"unknown scene {name!r}; registered scenes: {_listing()} "
            "(add your own with vc_gym.sim.scenes.register_scene)"
        )
    return name


def _check_new_name(name: object) -> str:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ValueError(
            f"a scene name must be a non-empty str of letters, digits, '_', '.' and '-' "
            f"starting with a letter or digit, got {name!r}"
        )
    if name in _RESERVED:
        raise ValueError(f"{name!r} cannot be a scene name: it means every scene in vc-gym")
    return name


def register_scene(
    name: str, *, canonical_seed: int = 0, overwrite: bool = False
) -> Callable[[_F], _F]:
    """Decorator that registers a scene builder under ``name``.

    The builder is called as ``fn(builder)`` with a fresh
    :class:`~vc_gym.sim.scenes.builder.Builder` and creates every body of the scene
    through it (``builder.mesh``, ``builder.solid``, ``builder.fence``, or a
    :class:`~vc_gym.sim.scenes.rooms.Room`). It returns
    ``(room_bounds, field_bounds, light_direction)``, a
    :class:`~vc_gym.sim.scenes.scene.SceneLayout` or a plain tuple in that order.
    It must take every random draw from ``builder.rng`` or ``builder.choices`` so that the
    same generator state gives the same scene.

    Parameters
    ----------
    name : str
        The scene's name: letters, digits, ``_``, ``.`` and ``-``, starting with a letter
        or digit (it becomes part of file names, e.g. ``vc-gym render``'s
        ``<scene>_top.png``); not ``"all"``.
    canonical_seed : int
        Seed of the generator the canonical scene (``randomize=False``) is built with, so
        that its textures are varied but always the same.
    overwrite : bool
        Replace a scene registered under ``name`` instead of raising.

    Returns
    -------
    callable
        The decorator; it returns the builder function unchanged.

    Raises
    ------
    ValueError
        On a bad name, a name already registered (without ``overwrite=True``), a
        ``canonical_seed`` that is not an int >= 0, or (from the decorator) a builder that
        is not callable.

    Examples
    --------
    >>> from vc_gym.sim.scenes import register_scene
    >>> @register_scene("my_room", canonical_seed=7)  # doctest: +SKIP
    ... def my_room(b):
    ...     ...
    ...     return (-2.0, 2.0, -2.0, 2.0), (-1.0, 1.0, -1.0, 1.0), (0.3, -0.4, 0.85)
    """
    _check_new_name(name)
    if isinstance(canonical_seed, bool) or not isinstance(canonical_seed, int | np.integer):
        raise ValueError(f"canonical_seed must be an int >= 0, got {canonical_seed!r}")
    if canonical_seed < 0:
        raise ValueError(f"canonical_seed must be an int >= 0, got {canonical_seed!r}")
    if not isinstance(overwrite, bool):
        raise ValueError(f"overwrite must be a bool, got {overwrite!r}")
    if name in _REGISTRY and not overwrite:
        raise ValueError(
            f"scene {name!r} is already registered; pass overwrite=True to replace it "
            f"or choose another name (registered: {_listing()})"
        )

    def decorator(fn: _F) -> _F:
        if not callable(fn):
            raise ValueError(
                f"register_scene({name!r}) decorates a builder function fn(builder), "
                f"got {type(fn).__name__} {fn!r}"
            )
        if name in _REGISTRY and not overwrite:  # registered meanwhile
            raise ValueError(
                f"scene {name!r} is already registered; pass overwrite=True to replace it"
            )
        _REGISTRY[name] = _Entry(fn, int(canonical_seed))
        return fn

    return decorator


def unregister_scene(name: str) -> None:
    """Remove scene ``name`` from the registry (e.g. after a test).

    Parameters
    ----------
    name : str
        A registered scene (built-in ones can be removed too; ``SCENES`` still lists
        them, and re-registering restores them).

    Raises
    ------
    ValueError
        If ``name`` is not registered.
    """
    del _REGISTRY[check_scene_name(name)]


def _bounds(value: Any, what: str, name: str) -> tuple[float, float, float, float]:
    try:
        b = tuple(float(c) for c in value)
    except (TypeError, ValueError):
        b = ()
    if len(b) != 4 or not all(math.isfinite(c) for c in b) or not (b[0] < b[1] and b[2] < b[3]):
        raise ValueError(
            f"scene {name!r}: {what} must be (xmin, xmax, ymin, ymax) with xmin < xmax and "
            f"ymin < ymax, got {value!r}"
        )
    return b  # type: ignore[return-value]


def _layout(result: Any, name: str) -> SceneLayout:
    """Check and convert what a builder returned."""
    if not isinstance(result, tuple | list) or len(result) != 3:
        raise ValueError(
            f"the builder of scene {name!r} must return (room_bounds, field_bounds, "
            f"light_direction), got {result!r}"
        )
    room = _bounds(result[0], "room_bounds", name)
    field = _bounds(result[1], "field_bounds", name)
    if not (
        room[0] <= field[0] and field[1] <= room[1] and room[2] <= field[2] and field[3] <= room[3]
    ):
        raise ValueError(f"scene {name!r}: field_bounds {field} must lie inside room_bounds {room}")
    try:
        light = tuple(float(c) for c in result[2])
    except (TypeError, ValueError):
        light = ()
    norm = math.sqrt(sum(c * c for c in light)) if len(light) == 3 else 0.0
    if not (math.isfinite(norm) and norm > 0 and light[2] > 0):
        raise ValueError(
            f"scene {name!r}: light_direction must be 3 finite numbers pointing up "
            f"(z > 0), got {result[2]!r}"
        )
    if abs(norm - 1.0) > 1e-9:
        light = tuple(c / norm for c in light)
    return SceneLayout(room, field, light)  # type: ignore[arg-type]


def build_scene(
    bc: Any,
    name: str = "robolab",
    rng: np.random.Generator | None = None,
    randomize: bool = False,
) -> Scene:
    """Build the registered scene ``name`` into the client ``bc``.

    The caller owns the client and calls ``bc.resetSimulation()`` before building a new
    scene into it (textures are freed only then); this function never connects or resets.
    The arguments are checked before anything is built; if the builder itself fails, the
    bodies it made stay in the client until the caller resets it.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client (its ``physicsClientId`` goes into every call).
    name : str
        A registered scene (:func:`scene_names`).
    rng : numpy.random.Generator, optional
        Source of every random draw when ``randomize`` (required then); ignored
        otherwise. The same generator state gives the same scene.
    randomize : bool
        ``False``: the canonical scene for ``name``, the same for any ``rng`` (built
        with the scene's ``canonical_seed``). ``True``: domain randomisation as the
        scene's builder defines it (the built-in scenes vary wall, floor and furniture
        colours, posters (selection, pictures, size and placement), furniture placement,
        windows and doors, and the light direction).

    Returns
    -------
    Scene
        Bounds, obstacles, body ids and light of the built scene.

    Raises
    ------
    ValueError
        On an unknown name (the message lists the registered scenes), an ``rng`` that
        is not a ``numpy.random.Generator``, a non-bool ``randomize``, ``randomize=True``
        without an ``rng``, or a builder that returns a bad layout.
    """
    check_scene_name(name)
    if rng is not None and not isinstance(rng, np.random.Generator):
        raise ValueError(
            "rng must be a numpy.random.Generator (np.random.default_rng(seed)) or None, "
            f"got {type(rng).__name__}; scenes: {_listing()}"
        )
    if not isinstance(randomize, bool | np.bool_):
        raise ValueError(f"randomize must be a bool, got {randomize!r}")
    if randomize and rng is None:
        raise ValueError("randomize=True needs rng=np.random.default_rng(seed)")
    entry = _REGISTRY[name]
    gen = rng if randomize else np.random.default_rng(entry.canonical_seed)
    b = Builder(bc, gen, bool(randomize))
    with b.tex:  # removes the temporary texture folder, also if the build fails
        result = entry.builder(b)
    layout = _layout(result, name)
    if not b.bodies:
        raise ValueError(f"the builder of scene {name!r} made no bodies")
    return Scene(
        name=name,
        room_bounds=layout.room_bounds,
        field_bounds=layout.field_bounds,
        obstacles=tuple(tuple(float(c) for c in o) for o in b.obstacles),
        body_ids=tuple(b.bodies),
        light_direction=layout.light_direction,
        background_rgb=None,
        ceiling_ids=tuple(b.ceilings),
    )
