"""Tests of vc_gym.compass.colors: EM colour classes and their lookup table."""

from __future__ import annotations

import functools
import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from vc_gym.compass.colors import ColorClasses

BLOCK_COLORS = np.array([[200.0, 30.0, 30.0], [30.0, 200.0, 30.0], [30.0, 30.0, 200.0]])


def _three_blocks(seed: int = 1, noise: float = 8.0) -> tuple[np.ndarray, np.ndarray]:
    """A 60x90 image of three vertical colour blocks plus Gaussian noise, and its labels."""
    rng = np.random.default_rng(seed)
    labels = np.repeat(np.arange(3), 30)[None, :].repeat(60, axis=0)
    img = BLOCK_COLORS[labels] + rng.normal(0.0, noise, labels.shape + (3,))
    return np.clip(img, 0, 255).round().astype(np.uint8), labels


@pytest.fixture(scope="module")
def blocks() -> tuple[np.ndarray, np.ndarray]:
    return _three_blocks()


@pytest.fixture(scope="module")
def model(blocks: tuple[np.ndarray, np.ndarray]) -> ColorClasses:
    return ColorClasses.fit([blocks[0]], n_colors=3, rng=np.random.default_rng(0))


@functools.cache
def _model_with_bits(bits: int) -> ColorClasses:
    means = np.array([[40.0, 60.0, 80.0], [180.0, 120.0, 90.0], [90.0, 200.0, 60.0]])
    covs = np.stack([np.diag([400.0, 300.0, 500.0]), np.eye(3) * 900.0, np.eye(3) * 250.0])
    covs[0, 0, 1] = covs[0, 1, 0] = 100.0
    return ColorClasses(means, covs, np.array([0.5, 0.3, 0.2]), bits=bits)


# ------------------------------------------------------------------ fitting


def test_fit_recovers_block_means(model: ColorClasses) -> None:
    assert model.n_colors == 3
    assert model.means.shape == (3, 3) and model.means.dtype == np.float64
    assert model.covariances.shape == (3, 3, 3)
    assert model.weights.shape == (3,)
    np.testing.assert_allclose(model.weights.sum(), 1.0)
    np.testing.assert_allclose(model.weights, 1 / 3, atol=0.01)
    for colour in BLOCK_COLORS:
        nearest = np.min(np.linalg.norm(model.means - colour, axis=1))
        assert nearest < 3.0, (colour, model.means)
    # noise std 8 -> variance ~64 (+1 regularisation) on the diagonal
    diag = np.diagonal(model.covariances, axis1=1, axis2=2)
    assert np.all((diag > 40) & (diag < 90)), diag


def test_classes_sorted_by_luminance(model: ColorClasses) -> None:
    luma = model.means @ np.array([0.299, 0.587, 0.114])
    assert np.all(np.diff(luma) >= 0)


def test_classify_matches_blocks(
    model: ColorClasses, blocks: tuple[np.ndarray, np.ndarray]
) -> None:
    img, truth = blocks
    labels = model.classify(img)
    assert labels.shape == img.shape[:2] and labels.dtype == np.uint8
    # best label permutation: majority class of every block, which must be a bijection
    mapping = {t: np.bincount(labels[truth == t], minlength=3).argmax() for t in range(3)}
    assert sorted(mapping.values()) == [0, 1, 2]
    predicted_truth = np.vectorize({v: k for k, v in mapping.items()}.get)(labels)
    assert np.mean(predicted_truth == truth) > 0.99


def test_fit_is_deterministic(blocks: tuple[np.ndarray, np.ndarray]) -> None:
    imgs = [blocks[0], _three_blocks(seed=2)[0]]
    a = ColorClasses.fit(imgs, 4, rng=np.random.default_rng(7), max_samples=3000)
    b = ColorClasses.fit(imgs, 4, rng=np.random.default_rng(7), max_samples=3000)
    for key, value in a.to_arrays().items():
        np.testing.assert_array_equal(value, b.to_arrays()[key])
    np.testing.assert_array_equal(a.lut, b.lut)


def test_default_rng_is_deterministic(blocks: tuple[np.ndarray, np.ndarray]) -> None:
    a = ColorClasses.fit([blocks[0]], 3, max_samples=1000)
    b = ColorClasses.fit([blocks[0]], 3, max_samples=1000)
    np.testing.assert_array_equal(a.means, b.means)
    np.testing.assert_array_equal(a.lut, b.lut)


def test_flat_image_many_colors_no_nan() -> None:
    flat = np.full((20, 30, 3), (100, 150, 200), dtype=np.uint8)
    cc = ColorClasses.fit([flat], n_colors=10)
    assert cc.n_colors == 10
    for arr in (cc.means, cc.covariances, cc.weights):
        assert np.all(np.isfinite(arr))
    assert np.all(cc.weights > 0)
    np.testing.assert_allclose(cc.weights.sum(), 1.0)
    labels = cc.classify(flat)
    assert len(np.unique(labels)) == 1
    np.testing.assert_allclose(cc.means[labels[0, 0]], [100, 150, 200])


def test_fewer_pixels_than_colors() -> None:
    tiny = np.array([[[0, 0, 0], [255, 255, 255]], [[255, 0, 0], [0, 0, 255]]], dtype=np.uint8)
    cc = ColorClasses.fit([tiny], n_colors=10)
    assert np.all(np.isfinite(cc.means)) and np.all(np.isfinite(cc.covariances))
    labels = cc.classify(tiny)
    assert len(np.unique(labels)) == 4  # every distinct colour gets its own class


def test_single_color_class() -> None:
    img, _ = _three_blocks()
    cc = ColorClasses.fit([img], n_colors=1)
    assert np.all(cc.lut == 0)
    np.testing.assert_allclose(cc.means[0], img.reshape(-1, 3).mean(axis=0), atol=1e-6)


# ------------------------------------------------------------------ lookup table


def test_lut_is_readonly_and_sized(model: ColorClasses) -> None:
    assert model.lut.shape == (2**15,) and model.lut.dtype == np.uint8
    assert model.bits == 5
    for arr in (model.lut, model.means, model.covariances, model.weights):
        with pytest.raises(ValueError):
            arr[0] = 0


@pytest.mark.parametrize("bits", [3, 4, 6])
def test_lut_matches_reference_density(bits: int) -> None:
    cc = _model_with_bits(bits)
    rng = np.random.default_rng(bits)
    n_side = 2**bits
    q = rng.integers(0, n_side, size=(200, 3))
    centres = (q + 0.5) * 2 ** (8 - bits)
    scores = []
    for w, mu, cov in zip(cc.weights, cc.means, cc.covariances, strict=True):
        d = centres - mu
        maha = np.einsum("ni,ni->n", d, np.linalg.solve(cov, d.T).T)
        scores.append(np.log(w) - 0.5 * np.linalg.slogdet(cov)[1] - 0.5 * maha)
    expected = np.argmax(np.stack(scores, axis=1), axis=1)
    index = (q[:, 0] << (2 * bits)) | (q[:, 1] << bits) | q[:, 2]
    np.testing.assert_array_equal(cc.lut[index], expected)


def test_rebuilding_lut_is_deterministic() -> None:
    a = _model_with_bits(5)
    b = ColorClasses(a.means, a.covariances, a.weights, bits=5)
    np.testing.assert_array_equal(a.lut, b.lut)


@settings(max_examples=60, deadline=None)
@given(
    bits=st.integers(3, 7),
    pixels=arrays(np.uint8, st.tuples(st.integers(0, 6), st.integers(1, 6), st.just(3))),
)
def test_lut_index_in_range(bits: int, pixels: np.ndarray) -> None:
    cc = _model_with_bits(bits)
    idx = cc.lut_index(pixels)
    assert idx.shape == pixels.shape[:-1]
    assert idx.dtype == np.intp
    assert np.all((idx >= 0) & (idx < 2 ** (3 * bits)))
    p = pixels.astype(np.int64) >> (8 - bits)
    np.testing.assert_array_equal(idx, (p[..., 0] << 2 * bits) | (p[..., 1] << bits) | p[..., 2])


@settings(max_examples=40, deadline=None)
@given(
    bits=st.integers(3, 6),
    image=arrays(np.uint8, st.tuples(st.integers(1, 8), st.integers(1, 8), st.just(3))),
)
def test_classify_pixels_matches_classify(bits: int, image: np.ndarray) -> None:
    cc = _model_with_bits(bits)
    labels = cc.classify(image)
    np.testing.assert_array_equal(cc.classify_pixels(image), labels)
    np.testing.assert_array_equal(cc.classify_pixels(image.reshape(-1, 3)), labels.ravel())
    np.testing.assert_array_equal(labels, cc.lut[cc.lut_index(image)])
    assert labels.dtype == np.uint8 and np.all(labels < cc.n_colors)


def test_classify_pixels_rejects_bad_pixels(model: ColorClasses) -> None:
    with pytest.raises(ValueError, match="uint8"):
        model.classify_pixels(np.zeros((4, 3), dtype=np.float32))
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        model.classify_pixels(np.zeros((4, 4), dtype=np.uint8))


# ------------------------------------------------------------------ persistence


def test_round_trip_through_npz(model: ColorClasses) -> None:
    arrays_ = model.to_arrays()
    assert all(k.startswith("colors_") for k in arrays_)
    assert arrays_["colors_bits"].shape == () and arrays_["colors_n_colors"].shape == ()
    assert "colors_lut" not in arrays_
    buf = io.BytesIO()
    np.savez(buf, **arrays_, other_module_key=np.zeros(2))
    buf.seek(0)
    with np.load(buf, allow_pickle=False) as npz:
        loaded = ColorClasses.from_arrays(npz)
    np.testing.assert_array_equal(loaded.lut, model.lut)
    np.testing.assert_array_equal(loaded.means, model.means)
    np.testing.assert_array_equal(loaded.covariances, model.covariances)
    np.testing.assert_array_equal(loaded.weights, model.weights)
    assert (loaded.bits, loaded.n_colors) == (model.bits, model.n_colors)


def _bad(model: ColorClasses, key: str, value: object) -> dict[str, object]:
    arrays_ = dict(model.to_arrays())
    if value is None:
        del arrays_[key]
    else:
        arrays_[key] = value
    return arrays_


def _nan_means(model: ColorClasses) -> np.ndarray:
    m = model.means.copy()
    m[1, 2] = np.nan
    return m


@pytest.mark.parametrize(
    ("key", "make"),
    [
        ("colors_means", lambda m: None),
        ("colors_bits", lambda m: None),
        ("colors_means", lambda m: m.means[:2]),
        ("colors_means", lambda m: m.means[:, :2]),
        ("colors_means", _nan_means),
        ("colors_means", lambda m: m.means.astype(str)),
        ("colors_covariances", lambda m: m.covariances[:, :2]),
        ("colors_covariances", lambda m: -m.covariances),
        ("colors_weights", lambda m: np.full(m.n_colors, np.inf)),
        ("colors_weights", lambda m: m.weights * 2),
        ("colors_bits", lambda m: np.array(9)),
        ("colors_bits", lambda m: np.array([5])),
        ("colors_bits", lambda m: np.array(5.0)),
        ("colors_n_colors", lambda m: np.array(0)),
    ],
)
def test_from_arrays_rejects_bad_arrays(model: ColorClasses, key: str, make) -> None:
    with pytest.raises(ValueError, match=key):
        ColorClasses.from_arrays(_bad(model, key, make(model)))


# ------------------------------------------------------------------ validation


@pytest.mark.parametrize(
    ("images", "kwargs", "match"),
    [
        ([], {}, "at least one"),
        ([np.zeros((8, 8, 3), dtype=np.float64)], {}, "uint8"),
        ([np.zeros((8, 8), dtype=np.uint8)], {}, r"\(H, W, 3\)"),
        ([np.zeros((8, 8, 4), dtype=np.uint8)], {}, r"\(H, W, 3\)"),
        ([np.zeros((8, 8, 3), dtype=np.uint8), np.zeros((8, 8), np.uint8)], {}, r"images\[1\]"),
        (np.zeros((8, 8, 3), dtype=np.uint8), {}, "single image"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"n_colors": 0}, "n_colors"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"n_colors": 256}, "n_colors"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"n_colors": 2.0}, "n_colors"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"bits": 9}, "bits"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"bits": 2}, "bits"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"max_samples": 5}, "max_samples"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"max_iter": 0}, "max_iter"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"tol": float("nan")}, "tol"),
        ([np.zeros((8, 8, 3), dtype=np.uint8)], {"rng": 3}, "rng"),
    ],
)
def test_fit_rejects_bad_input(images: object, kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        ColorClasses.fit(images, **kwargs)  # type: ignore[arg-type]


def test_classify_validates_image(model: ColorClasses) -> None:
    with pytest.raises(ValueError, match="uint8"):
        model.classify(np.zeros((4, 4, 3), dtype=np.float32))
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        model.classify(np.zeros((4, 4), dtype=np.uint8))


@pytest.mark.parametrize(
    ("means", "covs", "weights", "bits", "match"),
    [
        (np.zeros((2, 3)), np.stack([np.eye(3)] * 2), [0.5, 0.5], 8, "bits"),
        (np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros(0), 5, "means"),
        (np.zeros((2, 3)), np.stack([np.eye(3), np.zeros((3, 3))]), [0.5, 0.5], 5, "positive"),
        (np.zeros((2, 3)), np.stack([np.eye(3), np.triu(np.ones((3, 3)))]), [0.5, 0.5], 5, "sym"),
        (np.zeros((2, 3)), np.stack([np.eye(3)] * 2), [0.7, 0.7], 5, "sum to 1"),
        (np.zeros((2, 3)), np.stack([np.eye(3)] * 2), [1.5, -0.5], 5, "non-negative"),
    ],
)
def test_constructor_validates(means, covs, weights, bits, match) -> None:
    with pytest.raises(ValueError, match=match):
        ColorClasses(means, covs, np.asarray(weights), bits=bits)
