"""Tests of vc_gym.worlds.paint: colours and noise shared by every painter."""

from __future__ import annotations

import numpy as np
import pytest

from vc_gym.worlds.paint import (
    hsv,
    random_color,
    smooth_noise,
    smoothstep,
    to_uint8,
    value_noise,
)


@pytest.mark.parametrize(
    ("h", "s", "v", "rgb"),
    [
        (0.0, 1.0, 1.0, (255, 0, 0)),
        (1.0 / 3.0, 1.0, 1.0, (0, 255, 0)),
        (2.0 / 3.0, 1.0, 1.0, (0, 0, 255)),
        (1.0 / 6.0, 1.0, 1.0, (255, 255, 0)),
        (0.5, 1.0, 0.5, (0, 127.5, 127.5)),
        (0.3, 0.0, 0.2, (51, 51, 51)),  # no saturation: grey at the value
        (1.0, 1.0, 1.0, (255, 0, 0)),  # hue wraps
        (-1.0 / 3.0, 1.0, 1.0, (0, 0, 255)),
        (0.0, 2.0, 1.5, (255, 0, 0)),  # saturation and value are clipped to 0..1
        (0.0, -1.0, -0.5, (0, 0, 0)),
    ],
)
def test_hsv_known_values(h: float, s: float, v: float, rgb: tuple[float, float, float]) -> None:
    out = hsv(h, s, v)
    assert out.dtype == np.float32
    assert out.shape == (3,)
    np.testing.assert_allclose(out, rgb, atol=1e-3)


def test_random_color_draws_hue_saturation_value_in_order_from_the_ranges() -> None:
    rng = np.random.default_rng(5)
    out = random_color(rng, s=(0.2, 0.3), v=(0.6, 0.7), h=(0.1, 0.2))
    draws = np.random.default_rng(5).uniform(size=3)
    np.testing.assert_array_equal(
        out, hsv(0.1 + 0.1 * draws[0], 0.2 + 0.1 * draws[1], 0.6 + 0.1 * draws[2])
    )
    for seed in range(20):
        c = random_color(np.random.default_rng(seed), s=(0.0, 0.0), v=(0.4, 0.4))
        np.testing.assert_allclose(c, [102.0, 102.0, 102.0], atol=1e-3)  # grey at v


def test_random_colour_is_a_deprecated_alias_of_random_color() -> None:
    from vc_gym.worlds import paint

    with pytest.warns(DeprecationWarning, match="random_color"):
        assert paint.random_colour is random_color


def test_smoothstep() -> None:
    t = np.linspace(0.0, 1.0, 11)
    out = smoothstep(t)
    assert out[0] == 0.0 and out[-1] == 1.0 and out[5] == 0.5
    assert np.all(np.diff(out) > 0)
    np.testing.assert_allclose(out, 3 * t**2 - 2 * t**3, atol=1e-15)


def test_value_noise_deterministic_bounded_and_periodic_in_x() -> None:
    a = value_noise(np.random.default_rng(1), 90, 360, 24, 8)
    b = value_noise(np.random.default_rng(1), 90, 360, 24, 8)
    c = value_noise(np.random.default_rng(2), 90, 360, 24, 8)
    assert a.shape == (90, 360) and a.dtype == np.float32
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.min() >= -1.0 and a.max() <= 1.0
    assert a.max() - a.min() > 0.5
    # smooth: neighbours differ little, and the last column continues into the first
    step = np.abs(np.diff(a, axis=1)).max()
    assert step < 0.2
    assert np.abs(a[:, -1] - a[:, 0]).max() <= step + 1e-6


def test_value_noise_leaves_global_state_alone() -> None:
    state = np.random.get_state()[1].copy()  # noqa: NPY002 (the global state itself)
    value_noise(np.random.default_rng(0), 10, 20, 4, 2)
    smooth_noise(np.random.default_rng(0), 10, 20, 3.0)
    np.testing.assert_array_equal(np.random.get_state()[1], state)  # noqa: NPY002


def test_smooth_noise_deterministic_per_seed_and_about_unit_spread() -> None:
    a = smooth_noise(np.random.default_rng(3), 120, 200, 6.0)
    np.testing.assert_array_equal(a, smooth_noise(np.random.default_rng(3), 120, 200, 6.0))
    assert not np.array_equal(a, smooth_noise(np.random.default_rng(4), 120, 200, 6.0))
    assert a.shape == (120, 200) and a.dtype == np.float32
    assert 0.3 < float(a.std()) < 2.0
    assert np.abs(np.diff(a, axis=1)).max() < 0.5  # no pixel-scale detail


def test_to_uint8_rounds_to_nearest_and_clips() -> None:
    img = np.array([[-5.0, 0.4, 0.6, 127.5, 254.4, 255.5, 1e6]], np.float32)
    out = to_uint8(img)
    assert out.dtype == np.uint8 and out.shape == img.shape
    assert out.tolist() == [[0, 0, 1, 128, 254, 255, 255]]
    assert img[0, -1] == 1e6  # the input is not changed
