"""The scene registry: names, duplicates, overwriting, bad builders and bad layouts."""

from __future__ import annotations

import numpy as np
import pytest

import vc_gym.sim
from vc_gym.sim.scenes import (
    SCENES,
    Builder,
    SceneLayout,
    build_scene,
    check_scene_name,
    register_scene,
    scene_names,
    unregister_scene,
)


@pytest.fixture
def names():
    """Names a test registers; whatever is still registered is removed afterwards."""
    registered: list[str] = []
    yield registered
    for name in registered:
        if name in scene_names():
            unregister_scene(name)


def slab(b: Builder) -> SceneLayout:
    """The smallest valid scene: one floor slab."""
    body = b.mesh(
        [((-2.0, -2.0, 0.0), (4.0, 0.0, 0.0), (0.0, 4.0, 0.0), (0.0, 0.0, 1.0, 1.0))],
        rgb=(90, 140, 90),
        collision=((0.0, 0.0, -0.25), (2.0, 2.0, 0.25)),
        obstacle=False,
    )
    b.floor(body)
    return SceneLayout((-2.0, 2.0, -2.0, 2.0), (-1.0, 1.0, -1.0, 1.0), (0.0, 0.0, 2.0))


def test_builtins_are_registered_and_exported():
    assert scene_names()[: len(SCENES)] == SCENES
    for name in SCENES:
        assert check_scene_name(name) == name
    assert vc_gym.sim.register_scene is register_scene
    assert vc_gym.sim.scene_names is scene_names
    assert vc_gym.sim.unregister_scene is unregister_scene


def test_register_build_and_unregister(bc, names):
    names.append("test_slab")
    assert register_scene("test_slab", canonical_seed=3)(slab) is slab  # returned unchanged
    assert scene_names()[-1] == "test_slab" and scene_names()[: len(SCENES)] == SCENES
    scene = build_scene(bc, "test_slab")
    assert scene.name == "test_slab"
    assert scene.room_bounds == (-2.0, 2.0, -2.0, 2.0)
    assert scene.field_bounds == (-1.0, 1.0, -1.0, 1.0)
    assert scene.light_direction == (0.0, 0.0, 1.0)  # normalised
    assert len(scene.body_ids) == 1 and scene.obstacles == () and scene.ceiling_ids == ()
    assert bc.getDynamicsInfo(scene.body_ids[0], -1)[1] == pytest.approx(1.0)
    unregister_scene("test_slab")
    assert "test_slab" not in scene_names()
    with pytest.raises(ValueError, match="unknown scene 'test_slab'"):
        build_scene(bc, "test_slab")
    with pytest.raises(ValueError, match="unknown scene"):
        unregister_scene("test_slab")


def test_unknown_name_lists_the_registered_ones(bc, names):
    names.append("test_slab")
    register_scene("test_slab")(slab)
    with pytest.raises(ValueError) as e:
        build_scene(bc, "moon")
    msg = str(e.value)
    assert "'moon'" in msg and "robolab, office, home, outdoor_field, plain_house, test_slab" in msg
    assert "register_scene" in msg
    with pytest.raises(ValueError, match="test_slab"):
        check_scene_name(3)
    assert bc.getNumBodies() == 0


def test_duplicate_needs_overwrite(bc, names):
    names.append("test_slab")
    register_scene("test_slab")(slab)
    with pytest.raises(ValueError, match="already registered.*overwrite=True"):
        register_scene("test_slab")(slab)
    with pytest.raises(ValueError, match="already registered"):
        register_scene("robolab")(slab)

    def other(b: Builder) -> SceneLayout:
        layout = slab(b)
        return layout._replace(field_bounds=(-0.5, 0.5, -0.5, 0.5))

    register_scene("test_slab", overwrite=True)(other)
    assert scene_names().count("test_slab") == 1
    assert build_scene(bc, "test_slab").field_bounds == (-0.5, 0.5, -0.5, 0.5)


def test_overwriting_a_builtin_and_restoring_it(bc):
    from vc_gym.sim.scenes.home import build_home

    register_scene("home", overwrite=True, canonical_seed=2007)(slab)
    try:
        assert len(build_scene(bc, "home").body_ids) == 1
    finally:
        register_scene("home", overwrite=True, canonical_seed=2007)(build_home)
    assert scene_names()[: len(SCENES)] == SCENES  # replacing keeps the place in the order
    bc.resetSimulation()
    assert len(build_scene(bc, "home").body_ids) > 5


@pytest.mark.parametrize("bad", [42, None, "not callable"])
def test_builder_must_be_callable(bad, names):
    names.append("test_bad")
    with pytest.raises(ValueError, match="builder function"):
        register_scene("test_bad")(bad)
    assert "test_bad" not in scene_names()


@pytest.mark.parametrize("bad", ["", "all", "my room", "-x", "a/b", None, 3, ("robolab",)])
def test_bad_names(bad):
    with pytest.raises(ValueError, match="scene name"):
        register_scene(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"canonical_seed": -1}, "canonical_seed"),
        ({"canonical_seed": 1.5}, "canonical_seed"),
        ({"canonical_seed": True}, "canonical_seed"),
        ({"overwrite": "yes"}, "overwrite"),
    ],
)
def test_bad_options(kwargs, match):
    with pytest.raises(ValueError, match=match):
        register_scene("test_opts", **kwargs)
    assert "test_opts" not in scene_names()


@pytest.mark.parametrize(
    ("layout", "match"),
    [
        (None, "must return"),
        (((-2, 2, -2, 2), (-1, 1, -1, 1)), "must return"),
        (((2, -2, -2, 2), (-1, 1, -1, 1), (0, 0, 1)), "room_bounds"),
        (((-2, 2, -2, 2), (-1, 1, -1, float("nan")), (0, 0, 1)), "field_bounds"),
        (((-2, 2, -2, 2), (-1, 3, -1, 1), (0, 0, 1)), "inside room_bounds"),
        (((-2, 2, -2, 2), (-1, 1, -1, 1), (0, 0, -1)), "light_direction"),
        (((-2, 2, -2, 2), (-1, 1, -1, 1), (0, 0)), "light_direction"),
    ],
)
def test_bad_layouts_are_refused(bc, names, layout, match):
    def builder(b: Builder):
        slab(b)
        return layout

    names.append("test_layout")
    register_scene("test_layout")(builder)
    with pytest.raises(ValueError, match=match):
        build_scene(bc, "test_layout")


def test_builder_draws_from_the_canonical_seed_or_the_rng(bc, names):
    draws: list[float] = []

    def record(b: Builder) -> SceneLayout:
        draws.append(float(b.rng.uniform()))
        draws.append(b.choices.uniform(0.5, 0.0, 1.0))
        return slab(b)

    names.append("test_seeded")
    register_scene("test_seeded", canonical_seed=21)(record)
    for rng in (None, np.random.default_rng(5)):
        build_scene(bc, "test_seeded", rng=rng)
    assert draws[0] == draws[2] == np.random.default_rng(21).uniform()
    assert draws[1] == draws[3] == 0.5  # canonical layout choice, whatever the rng
    draws.clear()
    for _ in range(2):
        build_scene(bc, "test_seeded", rng=np.random.default_rng(5), randomize=True)
    assert draws[:2] == draws[2:] and draws[1] != 0.5
