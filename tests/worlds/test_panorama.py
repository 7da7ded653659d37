"""Tests of vc_gym.worlds.panorama: the Panorama type and pinhole views of panoramas."""

from __future__ import annotations

import functools
import math

import cv2
import numpy as np
import pytest

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass.camera import Camera
from vc_gym.worlds.panorama import Panorama, equirectangular, render_view
from vc_gym.worlds.panorama_painters import make_panorama

W_VIEW, H_VIEW = 208, 160


@functools.cache
def _pano(seed: int, kind: str = "room", width: int = 720, height: int = 180, noise: float = 4.0):
    return make_panorama(np.random.default_rng(seed), width, height, kind=kind, noise=noise)


def _azimuths(width: int, azimuth0: float = 0.0) -> np.ndarray:
    """Azimuth of each panorama column, straight from the documented convention."""
    return np.asarray(wrap360(azimuth0 - 360.0 * (np.arange(width) + 0.5) / width))


def _elevations(height: int, top: float = 45.0, bottom: float = -45.0) -> np.ndarray:
    return top - (top - bottom) * (np.arange(height) + 0.5) / height


def _stripe_panorama(
    azimuth: float, width: int = 1440, height: int = 360
) -> tuple[Panorama, float]:
    """Flat grey with a ~1° wide bright vertical stripe near ``azimuth``, and the exact
    azimuth of the stripe's centre (the mean direction of its columns)."""
    img = np.full((height, width, 3), 60, np.uint8)
    az = _azimuths(width)
    cols = np.abs(wrap180(az - azimuth)) < 0.5
    img[:, cols] = 240
    centre = azimuth + float(np.mean(wrap180(az[cols] - azimuth)))
    return Panorama(img), centre


def _pinhole_column(camera: Camera, delta_deg: float, row: float) -> float:
    """Column where a ray of azimuth offset ``delta`` crosses image row ``row``.

    From the ray formulas: forward_w = cos θ - sin θ y_up, left_w = -x and
    tan(delta) = left_w / forward_w, so x = -tan(delta) (cos θ - sin θ y_up).
    """
    cx, cy = camera.center(W_VIEW, H_VIEW)
    f = camera.focal_px(W_VIEW)
    theta = math.radians(camera.pitch_deg)
    y_up = (cy - row) / f
    return cx - f * math.tan(math.radians(delta_deg)) * (math.cos(theta) - math.sin(theta) * y_up)


def _bright_centroid(profile: np.ndarray, background: float = 60.0) -> float:
    excess = np.clip(profile - background - 10.0, 0.0, None)
    assert excess.sum() > 0, "stripe not visible"
    return float((excess * np.arange(profile.size)).sum() / excess.sum())


# ---------------------------------------------------------------------- Panorama


def test_panorama_validation() -> None:
    ok = np.zeros((10, 40, 3), np.uint8)
    with pytest.raises(ValueError):
        Panorama(ok.astype(np.float32))
    with pytest.raises(ValueError):
        Panorama(ok[:, :, 0])
    with pytest.raises(ValueError):
        Panorama(ok, elev_top_deg=10.0, elev_bottom_deg=10.0)
    with pytest.raises(ValueError):
        Panorama(ok, elev_top_deg=-10.0, elev_bottom_deg=10.0)
    with pytest.raises(ValueError):
        Panorama(ok, elev_top_deg=95.0)
    with pytest.raises(ValueError):
        Panorama(ok, azimuth0_deg=float("nan"))


def test_panorama_pixel_directions() -> None:
    pano = Panorama(np.zeros((90, 360, 3), np.uint8), 30.0, -60.0, azimuth0_deg=100.0)
    assert pano.azimuth_of_column(0) == pytest.approx(99.5)
    assert pano.azimuth_of_column(359) == pytest.approx(100.5)
    assert pano.column_of_azimuth(99.5) == pytest.approx(0.0)
    assert pano.column_of_azimuth(100.0) == pytest.approx(359.5)  # the wrap
    x = np.array([0.0, 17.25, 200.0, 359.0])
    np.testing.assert_allclose(pano.column_of_azimuth(pano.azimuth_of_column(x)), x, atol=1e-9)
    assert pano.elevation_of_row(0) == pytest.approx(29.5)
    assert pano.row_of_elevation(-60.0) == pytest.approx(89.5)
    assert pano.row_of_elevation(pano.elevation_of_row(12.3)) == pytest.approx(12.3)


def test_equirectangular_spans_the_sphere() -> None:
    img = np.zeros((90, 180, 3), np.uint8)
    img[:45] = 200  # upper hemisphere bright
    pano = equirectangular(img, azimuth0_deg=30.0)
    assert (pano.elev_top_deg, pano.elev_bottom_deg, pano.azimuth0_deg) == (90.0, -90.0, 30.0)
    assert pano.image is img
    cam = Camera(yaw_deg=77.0, pitch_deg=20.0)
    view = render_view(pano, cam, interpolation=cv2.INTER_NEAREST)
    horizon = cam.horizon_row(W_VIEW, H_VIEW)
    assert (view[: int(horizon) - 1] == 200).all() and (view[int(horizon) + 2 :] == 0).all()
    with pytest.raises(ValueError):
        equirectangular(img.astype(np.int16))


# -------------------------------------------------------------------- render_view


def test_column_and_row_convention_exact() -> None:
    """A camera looking at the centre of panorama pixel (x, y) sees exactly that pixel."""
    width, height = 250, 100
    img = np.zeros((height, width, 3), np.uint8)
    img[:, :, 0] = np.arange(width)[None, :]
    img[:, :, 1] = np.arange(height)[:, None]
    pano = Panorama(img, 40.0, -50.0, azimuth0_deg=-123.0)
    for x, y in [(0, 50), (1, 0), (124, 99), (249, 45), (200, 3)]:
        az = -123.0 - 360.0 * (x + 0.5) / width
        el = 40.0 - 90.0 * (y + 0.5) / height
        cam = Camera(yaw_deg=az, pitch_deg=el)
        view = render_view(pano, cam, 3, 3, interpolation=cv2.INTER_NEAREST)
        assert tuple(view[1, 1, :2]) == (x, y)
        # turning right (clockwise, smaller yaw) moves to larger panorama columns
        right = render_view(pano, cam.replace(yaw_deg=az - 360.0 / width), 3, 3, interpolation=0)
        assert right[1, 1, 0] == (x + 1) % width


def test_render_matches_independent_nearest_sampler() -> None:
    """render_view(NEAREST) equals a direct per-pixel evaluation of the documented formulas."""
    rng = np.random.default_rng(5)
    img = rng.integers(0, 256, (90, 360, 3), dtype=np.uint8)
    pano = Panorama(img, 50.0, -40.0, azimuth0_deg=17.0)
    w, h = 41, 30
    for _ in range(10):
        cam = Camera(
            hfov_deg=float(rng.uniform(30, 100)),
            yaw_deg=float(rng.uniform(-400, 400)),
            pitch_deg=float(rng.uniform(-30, 30)),
            principal_point=None if rng.uniform() < 0.5 else (15.3, 9.8),
        )
        cx, cy = cam.center(w, h)
        f = cam.focal_px(w)
        u, v = np.meshgrid(np.arange(w), np.arange(h))
        x, y_up = (u - cx) / f, (cy - v) / f
        th = math.radians(cam.pitch_deg)
        fw, up, left = math.cos(th) - math.sin(th) * y_up, math.sin(th) + math.cos(th) * y_up, -x
        az = cam.yaw_deg + np.degrees(np.arctan2(left, fw))
        el = np.degrees(np.arctan2(up, np.hypot(fw, left)))
        px = np.mod((17.0 - az) / 360.0 * 360 - 0.5, 360)
        py = np.clip((50.0 - el) / 90.0 * 90 - 0.5, 0, 89)
        expected = img[np.round(py).astype(int) % 90, np.round(px).astype(int) % 360]
        got = render_view(pano, cam, w, h, interpolation=cv2.INTER_NEAREST)
        mismatch = (got != expected).any(axis=2)
        assert mismatch.mean() < 0.01  # only exact .5 ties may round the other way


STRIPE_CASES = [
    # (stripe azimuth, camera yaw, pitch)
    (10.0, 10.0, 0.0),
    (10.0, -10.0, 0.0),  # stripe 20° left of the axis
    (10.0, 35.0, 0.0),  # near the right edge (hfov/2 = 28.45°)
    (10.0, -15.5, 10.0),  # near the left edge, pitched up
    (10.0, 33.0, -10.0),
    (0.3, 359.8, 0.0),  # the seam: stripe and yaw on opposite sides of 0/360
    (359.5, 2.0, 10.0),
    (0.3, 335.0, -10.0),  # stripe across the seam from the axis, near the left edge
    (359.6, 24.0, 10.0),
    (180.0, 180.0, -10.0),
    (200.0, 220.0, 0.0),
]


@pytest.fixture(scope="module")
def stripe_panos() -> dict[float, tuple[Panorama, float]]:
    return {a: _stripe_panorama(a) for a in {case[0] for case in STRIPE_CASES}}


@pytest.mark.parametrize(("azimuth", "yaw", "pitch"), STRIPE_CASES)
def test_vertical_stripe_lands_on_pinhole_column(
    stripe_panos: dict[float, tuple[Panorama, float]], azimuth: float, yaw: float, pitch: float
) -> None:
    pano, centre = stripe_panos[azimuth]
    cam = Camera(yaw_deg=yaw, pitch_deg=pitch)
    view = render_view(pano, cam).astype(float).mean(axis=2)
    delta = float(wrap180(centre - yaw))
    horizon = cam.horizon_row(W_VIEW, H_VIEW)
    row = int(round(horizon))
    measured = _bright_centroid(view[row])

    # exact projection at the measured row, from the ray formulas (measured errors are
    # ~0.05 px; the spec asks for 1 px)
    assert measured == pytest.approx(_pinhole_column(cam, delta, row), abs=0.25)
    # the closed form at the horizon: u = cx - f tan(delta) / cos(pitch)
    cx, _ = cam.center(W_VIEW, H_VIEW)
    f = cam.focal_px(W_VIEW)
    at_horizon = cx - f * math.tan(math.radians(delta)) / math.cos(math.radians(pitch))
    assert measured == pytest.approx(at_horizon, abs=1.0)
    # and the camera model's own column directions agree
    fine = np.linspace(-20.0, W_VIEW + 20.0, 20001)
    offsets = cam.column_offsets_deg(fine, W_VIEW, H_VIEW, row=row)  # decreasing in u
    u_camera = float(np.interp(delta, offsets[::-1], fine[::-1]))
    assert measured == pytest.approx(u_camera, abs=1.0)
    assert cam.column_offsets_deg(np.array([measured]), W_VIEW, H_VIEW)[0] == pytest.approx(
        delta, abs=0.35
    )  # 1 px is ~0.3°


@pytest.mark.parametrize("pitch", [0.0, 10.0, -10.0, 4.3])
def test_horizontal_edge_at_zero_elevation_is_on_the_horizon_row(pitch: float) -> None:
    img = np.full((180, 720, 3), 40, np.uint8)
    img[:90] = 220  # rows above elevation 0 are bright
    pano = Panorama(img)
    cam = Camera(yaw_deg=123.0, pitch_deg=pitch)
    view = render_view(pano, cam).astype(float).mean(axis=2)
    expected = cam.horizon_row(W_VIEW, H_VIEW)
    level = 130.0
    for col in [0, 40, 103, 170, W_VIEW - 1]:
        profile = view[:, col]
        i = int(np.flatnonzero((profile[:-1] >= level) & (profile[1:] < level))[0])
        crossing = i + (profile[i] - level) / (profile[i] - profile[i + 1])
        assert crossing == pytest.approx(expected, abs=1.0)


@pytest.mark.parametrize("yaw", [0.0, 0.3, -0.3, 359.9, 28.0, -28.0, 28.45, 331.55, 90.0])
@pytest.mark.parametrize("pitch", [0.0, 7.0])
def test_seam_has_no_discontinuity(yaw: float, pitch: float) -> None:
    pano = _pano(2, "room")
    shift = pano.width // 2
    rolled = Panorama(
        np.roll(pano.image, shift, axis=1),
        azimuth0_deg=pano.azimuth0_deg + 360 * shift / pano.width,
    )
    cam = Camera(yaw_deg=yaw, pitch_deg=pitch)
    a = render_view(pano, cam).astype(int)
    b = render_view(rolled, cam).astype(int)
    assert np.abs(a - b).max() <= 1


def test_wrap_on_smooth_panorama_is_continuous() -> None:
    """Around the seam column the rendered image is as smooth as anywhere else."""
    width = 720
    az = np.radians(_azimuths(width))
    img = np.empty((180, width, 3), np.uint8)
    img[:] = np.stack([128 + 100 * np.sin(az), 128 + 100 * np.cos(az), 128 + 0 * az], -1)[None]
    view = render_view(Panorama(img), Camera(yaw_deg=0.0)).astype(float)
    steps = np.abs(np.diff(view[80, :, :2], axis=0)).max()
    # sin changes by at most 100 * (pi/180) per degree; a view column is <= 0.3°
    assert steps <= 100 * math.pi / 180 * 0.3 + 1.0


@pytest.mark.parametrize("interpolation", [cv2.INTER_CUBIC, cv2.INTER_LANCZOS4])
def test_rays_outside_the_band_replicate_the_edge_rows(interpolation: int) -> None:
    img = np.full((180, 720, 3), 30, np.uint8)
    img[:90] = 230
    pano = Panorama(img)
    up = render_view(pano, Camera(pitch_deg=40.0), interpolation=interpolation)
    down = render_view(pano, Camera(pitch_deg=-40.0), interpolation=interpolation)
    # the views see elevations 17°-63° (-63°..-17°), i.e. beyond and just inside the band
    # edge, where the kernel must not reach around to the opposite edge
    assert (up == 230).all()
    assert (down == 30).all()


def test_principal_point_crop_matches_full_render() -> None:
    pano = _pano(4, "outdoor")
    full_cam = Camera(yaw_deg=45.0, pitch_deg=5.0)
    full = render_view(pano, full_cam)
    cx, cy = full_cam.center(W_VIEW, H_VIEW)
    c0, r0, w, h = 30, 20, 100, 60
    crop_cam = Camera.from_focal(
        full_cam.focal_px(W_VIEW), w, 45.0, 5.0, principal_point=(cx - c0, cy - r0)
    )
    crop = render_view(pano, crop_cam, w, h)
    assert np.abs(crop.astype(int) - full[r0 : r0 + h, c0 : c0 + w].astype(int)).max() <= 1


def test_render_shape_dtype_and_purity() -> None:
    pano = _pano(0)
    before = pano.image.copy()
    a = render_view(pano, Camera(yaw_deg=12.0), 64, 48)
    b = render_view(pano, Camera(yaw_deg=12.0), 64, 48)
    assert a.shape == (48, 64, 3) and a.dtype == np.uint8
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pano.image, before)


def test_illumination() -> None:
    pano = _pano(1, "room")
    cam = Camera(yaw_deg=200.0)
    base = render_view(pano, cam)
    np.testing.assert_array_equal(render_view(pano, cam, illumination=1.0), base)
    dark = render_view(pano, cam, illumination=0.5)
    assert dark.dtype == np.uint8 and dark.shape == base.shape
    assert (dark <= base).all()
    assert (dark.reshape(-1, 3).mean(0) < base.reshape(-1, 3).mean(0) - 10).all()
    bright = base >= 40
    assert (dark[bright] < base[bright]).all()

    def linear(v: np.ndarray) -> np.ndarray:
        s = v / 255.0
        return np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)

    ratio = linear(dark[bright].astype(float)) / linear(base[bright].astype(float))
    assert np.abs(ratio - 0.5).max() < 0.05  # half the light, not half the sRGB value
    brighter = render_view(pano, cam, illumination=3.0)
    assert (brighter >= base).all()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"width": 1},
        {"height": 1},
        {"width": 20.5},
        {"illumination": 0.0},
        {"illumination": -1.0},
        {"illumination": float("nan")},
        {"illumination": float("inf")},
        {"interpolation": cv2.INTER_AREA},
    ],
)
def test_render_view_rejects_bad_arguments(kwargs: dict) -> None:
    with pytest.raises(ValueError):
        render_view(_pano(0), Camera(), **kwargs)


def test_render_view_rejects_wrong_types() -> None:
    with pytest.raises(TypeError):
        render_view(_pano(0).image, Camera())  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        render_view(_pano(0), 0.0)  # type: ignore[arg-type]


def test_render_view_returns_a_fresh_array_each_call():
    pano = make_panorama(np.random.default_rng(0), width=720, height=180)
    a = render_view(pano, Camera(yaw_deg=10.0))
    b = render_view(pano, Camera(yaw_deg=10.0))
    assert a is not b and not np.shares_memory(a, b)
    np.testing.assert_array_equal(a, b)
