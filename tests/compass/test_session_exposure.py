"""exposure="session": one gain for every frame of a session, read from the frames."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.compass import Camera, CompassAtlas, CompassConfig, MapFileError, VisualCompass, wrap180
from vc_gym.errors import NotLearnedError
from vc_gym.exposure import SessionLight
from vc_gym.worlds.panorama import render_view

SESSION = CompassConfig(exposure="session")


@pytest.fixture(scope="module")
def session_compass(room_pano, make_learned_compass) -> VisualCompass:
    return make_learned_compass(room_pano, SESSION)


@pytest.fixture(scope="module")
def paper_compass(room_pano, make_learned_compass) -> VisualCompass:
    return make_learned_compass(room_pano, CompassConfig())


def test_at_gain_one_it_is_the_papers_compass(room_pano, session_compass, paper_compass):
    # colours are fitted on the frames as they are, so the maps are the paper's
    np.testing.assert_array_equal(session_compass._counts, paper_compass._counts)
    img = render_view(room_pano, Camera(yaw_deg=222.0))
    np.testing.assert_array_equal(
        session_compass.log_likelihood(img, Camera(), gain=1.0),
        paper_compass.log_likelihood(img, Camera()),
    )


def test_frame_gain_reads_a_change_of_light(room_pano, session_compass):
    for yaw in (10.0, 130.0, 250.0):
        full = session_compass.frame_gain(render_view(room_pano, Camera(yaw_deg=yaw)), Camera())
        half = session_compass.frame_gain(
            render_view(room_pano, Camera(yaw_deg=yaw), illumination=0.5), Camera()
        )
        assert half / full == pytest.approx(2.0, rel=0.05)
    black = np.zeros((160, 208, 3), np.uint8)
    assert session_compass.frame_gain(black, Camera()) == np.inf


@pytest.mark.parametrize("illumination, gain", [(1.0, 1.0), (0.5, 2.0), (0.25, 4.0)])
def test_the_session_light_finds_the_heading_in_changed_light(
    room_pano, session_compass, illumination, gain
):
    yaws = np.random.default_rng(17).uniform(0.0, 360.0, 20)
    views = [render_view(room_pano, Camera(yaw_deg=y), illumination=illumination) for y in yaws]
    light = SessionLight()
    for img in views:
        light.update(session_compass.frame_gain(img, Camera()))
    assert light.gain == gain
    errs = [
        abs(wrap180(session_compass.estimate(img, Camera(), gain=light.gain).heading_deg - y))
        for img, y in zip(views, yaws, strict=True)
    ]
    assert np.mean(np.array(errs) < 5.0) >= 0.9, np.round(errs, 1)


def test_paper_compass_loses_the_heading_at_half_light(room_pano, paper_compass):
    # the case the session light is for (README: 74.5 deg median on this scene kind)
    yaws = np.random.default_rng(17).uniform(0.0, 360.0, 20)
    errs = [
        abs(
            wrap180(
                paper_compass.estimate(
                    render_view(room_pano, Camera(yaw_deg=y), illumination=0.5), Camera()
                ).heading_deg
                - y
            )
        )
        for y in yaws
    ]
    assert np.mean(np.array(errs) < 5.0) < 0.5


def test_a_frame_on_its_own_is_its_own_session(room_pano, session_compass):
    img = render_view(room_pano, Camera(yaw_deg=75.0), illumination=0.5)
    g = session_compass.frame_gain(img, Camera())
    steps = round(np.log2(g) * 3)
    np.testing.assert_array_equal(
        session_compass.log_likelihood(img, Camera()),
        session_compass.log_likelihood(img, Camera(), gain=2.0 ** (steps / 3)),
    )


def test_frame_gain_needs_a_reference_level(room_pano):
    img = render_view(room_pano, Camera(yaw_deg=10.0))
    with pytest.raises(ValueError, match="frame_gain needs exposure"):
        VisualCompass(CompassConfig()).frame_gain(img, Camera())
    with pytest.raises(NotLearnedError, match="fit_colors"):
        VisualCompass(SESSION).frame_gain(img, Camera())
    with pytest.raises(ValueError, match="not black"):
        VisualCompass(SESSION).fit_colors([np.zeros((160, 208, 3), np.uint8)])


def test_session_maps_keep_their_reference_level_on_disk(tmp_path, room_pano, session_compass):
    path = session_compass.save(tmp_path / "s.npz")
    loaded = VisualCompass.load(path)
    img = render_view(room_pano, Camera(yaw_deg=300.0), illumination=0.5)
    assert loaded.frame_gain(img, Camera()) == session_compass.frame_gain(img, Camera())
    arrays = dict(np.load(path, allow_pickle=False))
    arrays["exposure_reference"] = np.array(0.0)
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(MapFileError, match="no reference level"):
        VisualCompass.load(tmp_path / "bad.npz")


def test_the_atlas_scores_every_spot_at_the_session_light(room_pano, session_compass):
    other = VisualCompass(SESSION, session_compass.colors)
    for yaw in (0.0, 90.0, 180.0, 270.0):
        other.learn(render_view(room_pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    atlas = CompassAtlas({"a": ((0.0, 0.0), session_compass), "b": ((1.0, 0.0), other)}, home="a")
    img = render_view(room_pano, Camera(yaw_deg=40.0), illumination=0.5)
    assert atlas.frame_gain(img, Camera()) == session_compass.frame_gain(img, Camera())
    est = atlas.estimate_position(img, Camera(), gain=2.0)
    for name, vc in (("a", session_compass), ("b", other)):
        alone = vc.estimate(img, Camera(), gain=2.0)
        assert est.estimates[name].heading_deg == alone.heading_deg
        assert est.estimates[name].score == pytest.approx(alone.score, rel=1e-12)
