"""Tests of vc_gym.compass.color_mixture: the EM fit of a Gaussian mixture over RGB."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vc_gym.compass.color_mixture import (
    COV_REG,
    GaussianMixture,
    WeightedGaussians,
    cholesky3,
    fit_gaussian_mixture,
)
from vc_gym.compass.colors import ColorClasses

BLOCK_COLORS = np.array([[200.0, 30.0, 30.0], [30.0, 200.0, 30.0], [30.0, 30.0, 200.0]])


def _block_pixels(seed: int = 1, n: int = 600, noise: float = 8.0) -> np.ndarray:
    """``(3 n, 3)`` uint8 pixels: three colours plus Gaussian noise."""
    rng = np.random.default_rng(seed)
    pix = np.repeat(BLOCK_COLORS, n, axis=0) + rng.normal(0.0, noise, (3 * n, 3))
    return np.clip(pix, 0, 255).round().astype(np.uint8)


def _random_spd(rng: np.random.Generator, c: int) -> np.ndarray:
    a = rng.normal(0.0, 20.0, (c, 3, 3))
    return a @ a.transpose(0, 2, 1) + 5.0 * np.eye(3)


def test_cholesky3_matches_numpy():
    cov = _random_spd(np.random.default_rng(0), 6)
    np.testing.assert_allclose(cholesky3(cov), np.linalg.cholesky(cov), rtol=1e-12)


def test_cholesky3_refuses_matrices_that_are_not_positive_definite():
    cov = _random_spd(np.random.default_rng(1), 3)
    bad = cov.copy()
    bad[1] = np.diag([1.0, -1.0, 1.0])
    assert cholesky3(bad) is None
    bad[1] = np.nan
    assert cholesky3(bad) is None
    assert cholesky3(np.zeros((1, 3, 3))) is None


def test_weighted_log_density():
    rng = np.random.default_rng(2)
    cov = _random_spd(rng, 4)
    means = rng.uniform(0, 255, (4, 3))
    weights = np.array([0.1, 0.2, 0.3, 0.4])
    x = rng.uniform(0, 255, (3, 50))
    got = WeightedGaussians(means, cholesky3(cov), weights).weighted_log_density(x)
    assert got.shape == (4, 50)
    for k in range(4):
        d = x.T - means[k]
        maha = np.einsum("ni,ij,nj->n", d, np.linalg.inv(cov[k]), d)
        want = math.log(weights[k]) - 0.5 * math.log(np.linalg.det(cov[k])) - 0.5 * maha
        np.testing.assert_allclose(got[k], want, rtol=1e-9, atol=1e-9)


def test_fit_recovers_three_colours():
    mix = fit_gaussian_mixture(_block_pixels(), 3, rng=np.random.default_rng(0))
    assert isinstance(mix, GaussianMixture)
    assert mix.weights.shape == (3,) and mix.means.shape == (3, 3)
    assert mix.covariances.shape == (3, 3, 3)
    np.testing.assert_allclose(mix.weights.sum(), 1.0)
    np.testing.assert_allclose(mix.weights, 1 / 3, atol=0.01)
    for colour in BLOCK_COLORS:
        assert np.min(np.linalg.norm(mix.means - colour, axis=1)) < 2.0
    diag = np.diagonal(mix.covariances, axis1=1, axis2=2)
    assert np.all((diag > 40) & (diag < 90)), diag  # noise variance 64 plus COV_REG
    np.testing.assert_array_equal(mix.covariances, mix.covariances.transpose(0, 2, 1))


def test_fit_is_deterministic_for_a_seed():
    pix = _block_pixels(seed=3, noise=30.0)
    a = fit_gaussian_mixture(pix, 5, rng=np.random.default_rng(7))
    b = fit_gaussian_mixture(pix.astype(np.float64), 5, rng=np.random.default_rng(7))
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


def test_more_components_than_colours_stay_valid():
    pix = np.array([[10, 20, 30]] * 5 + [[200, 100, 0]] * 5, np.uint8)
    for k in (2, 4, 12):  # 12 > number of samples
        mix = fit_gaussian_mixture(pix, k, rng=np.random.default_rng(k))
        assert mix.means.shape == (k, 3)
        assert np.all(np.isfinite(mix.means)) and np.all(mix.weights > 0)
        np.testing.assert_allclose(mix.weights.sum(), 1.0)
        assert cholesky3(mix.covariances) is not None
        assert np.all(np.diagonal(mix.covariances, axis1=1, axis2=2) >= COV_REG)


def test_color_classes_are_the_sorted_mixture():
    image = _block_pixels(seed=4, n=200, noise=15.0).reshape(20, 30, 3)
    classes = ColorClasses.fit([image], n_colors=4, rng=np.random.default_rng(5))
    mix = fit_gaussian_mixture(image.reshape(-1, 3), 4, rng=np.random.default_rng(5))
    order = [int(np.flatnonzero((mix.means == m).all(axis=1))[0]) for m in classes.means]
    assert sorted(order) == [0, 1, 2, 3]
    np.testing.assert_array_equal(classes.covariances, mix.covariances[order])
    np.testing.assert_array_equal(classes.weights, mix.weights[order] / mix.weights[order].sum())


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"samples": np.zeros((4, 2))}, "shape"),
        ({"samples": np.zeros((0, 3))}, "shape"),
        ({"samples": np.array([[0.0, np.nan, 1.0]])}, "finite"),
        ({"samples": np.array([["a", "b", "c"]])}, "real"),
        ({"n_components": 0}, "n_components"),
        ({"n_components": 2.0}, "n_components"),
        ({"max_iter": 0}, "max_iter"),
        ({"tol": -1.0}, "tol"),
        ({"tol": float("nan")}, "tol"),
        ({"rng": 0}, "Generator"),
    ],
)
def test_bad_arguments_raise(kwargs, match):
    args = {
        "samples": np.zeros((4, 3), np.uint8),
        "n_components": 2,
        "rng": np.random.default_rng(0),
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        fit_gaussian_mixture(args.pop("samples"), args.pop("n_components"), **args)
