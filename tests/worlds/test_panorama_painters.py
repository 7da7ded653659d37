"""Tests of vc_gym.worlds.panorama_painters: procedural, seamless, seeded panoramas."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from vc_gym.worlds.panorama_painters import PANORAMA_KINDS, make_panorama


@functools.cache
def _pano(seed: int, kind: str = "room", width: int = 720, height: int = 180, noise: float = 4.0):
    return make_panorama(np.random.default_rng(seed), width, height, kind=kind, noise=noise)


@pytest.mark.parametrize("kind", PANORAMA_KINDS)
def test_same_seed_same_panorama_other_seed_differs(kind: str) -> None:
    a = make_panorama(np.random.default_rng(7), 720, 180, kind=kind)
    b = make_panorama(np.random.default_rng(7), 720, 180, kind=kind)
    c = make_panorama(np.random.default_rng(8), 720, 180, kind=kind)
    np.testing.assert_array_equal(a.image, b.image)
    assert np.abs(a.image.astype(int) - c.image.astype(int)).mean() > 5.0


@pytest.mark.parametrize("kind", PANORAMA_KINDS)
def test_default_panorama_shape_and_band(kind: str) -> None:
    pano = make_panorama(np.random.default_rng(0), kind=kind)
    assert pano.image.shape == (900, 3600, 3) and pano.image.dtype == np.uint8
    assert (pano.elev_top_deg, pano.elev_bottom_deg, pano.azimuth0_deg) == (45.0, -45.0, 0.0)
    # coarse structure: neighbouring pixels mostly agree up to the noise, yet the
    # scene has real contrast
    img = pano.image.astype(float)
    assert np.median(np.abs(np.diff(img, axis=1))) < 8.0
    assert img.std() > 20.0


def test_noise_is_drawn_last_and_global_state_untouched() -> None:
    state = np.random.get_state()[1].copy()  # noqa: NPY002 (the global state itself)
    clean = make_panorama(np.random.default_rng(3), 720, 180, noise=0.0)
    noisy = make_panorama(np.random.default_rng(3), 720, 180, noise=4.0)
    np.testing.assert_array_equal(np.random.get_state()[1], state)  # noqa: NPY002
    diff = noisy.image.astype(float) - clean.image.astype(float)
    assert 2.5 < np.abs(diff).mean() < 4.0  # E|N(0, 4)| = 3.19, minus clipping
    assert abs(diff.mean()) < 0.2


@pytest.mark.parametrize("kind", PANORAMA_KINDS)
@pytest.mark.parametrize("seed", range(4))
def test_panorama_is_seamless(kind: str, seed: int) -> None:
    img = _pano(seed, kind, noise=0.0).image.astype(float)
    steps = np.abs(np.diff(img, axis=1)).mean(axis=(0, 2))  # between neighbouring columns
    seam = np.abs(img[:, 0] - img[:, -1]).mean()
    assert seam <= np.quantile(steps, 0.99) + 0.5


def test_room_has_floor_below_and_ceiling_above() -> None:
    for seed in range(3):
        img = _pano(seed, "room", noise=0.0).image.astype(float)
        bottom, top = img[-20:], img[:10]
        middle = img[60:80]  # walls, 10°-20° above the horizon
        assert np.abs(bottom.mean((0, 1)) - middle.mean((0, 1))).max() > 10.0
        assert top.mean() > 150.0  # light ceiling (or the top of a light wall)


def test_outdoor_sky_above_grass_below() -> None:
    img = _pano(1, "outdoor", noise=0.0).image.astype(float)
    sky, grass = img[:20].mean((0, 1)), img[-30:].mean((0, 1))
    assert sky[2] > sky[0] and grass[1] > grass[2] and grass[1] > grass[0]


@pytest.mark.parametrize(
    "kwargs",
    [
        {"kind": "cave"},
        {"width": 359},
        {"height": 89},
        {"width": 3600.0},
        {"noise": -1.0},
        {"noise": float("nan")},
    ],
)
def test_make_panorama_rejects_bad_arguments(kwargs: dict) -> None:
    with pytest.raises(ValueError):
        make_panorama(np.random.default_rng(0), **kwargs)


def test_make_panorama_needs_a_generator() -> None:
    with pytest.raises(TypeError):
        make_panorama(0)  # type: ignore[arg-type]
