"""Tests of vc_gym.worlds.room: a seeded room and its 2.5-D ray caster."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from vc_gym.angles import wrap180
from vc_gym.compass.camera import Camera
from vc_gym.worlds.room import Room, make_room, render_room_view

W_VIEW, H_VIEW = 208, 160
GREY = 120
RED = (230, 20, 20)
FLOOR = (20, 200, 20)
CEILING = (20, 20, 200)


@functools.cache
def _room(seed: int, open_top: bool = False) -> Room:
    return make_room(np.random.default_rng(seed), open_top=open_top)


def _s_of_point(width: float, depth: float, x: float, y: float) -> float:
    """Perimeter coordinate of a wall point, straight from the documented convention."""
    if math.isclose(x, width / 2):
        return y + depth / 2
    if math.isclose(y, depth / 2):
        return depth + (width / 2 - x)
    if math.isclose(x, -width / 2):
        return depth + width + (depth / 2 - y)
    assert math.isclose(y, -depth / 2)
    return 2 * depth + width + (x + width / 2)


def _plain_room(
    width: float = 6.0,
    depth: float = 4.0,
    height: float = 2.5,
    px_per_m: int = 100,
    markers: tuple[tuple[float, float], ...] = (),
    open_top: bool = False,
) -> tuple[Room, list[tuple[float, float]]]:
    """Plain grey walls with 5 cm wide red vertical stripes at the given wall points.

    Returns the room and the exact world point of each stripe's centre (the mean arc
    length of its texture columns).
    """
    perimeter = 2 * (width + depth)
    tw, th = round(perimeter * px_per_m), round(height * px_per_m)
    tex = np.full((th, tw, 3), GREY, np.uint8)
    s_cols = (np.arange(tw) + 0.5) * perimeter / tw
    centres = []
    for x, y in markers:
        s = _s_of_point(width, depth, x, y)
        cols = np.abs(s_cols - s) <= 0.025
        tex[:, cols] = RED
        sc = float(s_cols[cols].mean())
        # move the point along its wall by the column-rounding offset
        if math.isclose(abs(x), width / 2):
            sign = 1.0 if x > 0 else -1.0
            centres.append((x, y + sign * (sc - s)))
        else:
            sign = -1.0 if y > 0 else 1.0
            centres.append((x + sign * (sc - s), y))
    room = Room(width, depth, height, tex, FLOOR, None if open_top else CEILING)
    return room, centres


def _pinhole_column(camera: Camera, delta_deg: float, row: float) -> float:
    """Column where a vertical line at azimuth offset ``delta`` crosses image row ``row``.

    ``x = -tan(delta) (cos θ - sin θ y_up)`` from the ray formulas; at zero pitch this is
    ``u = cx - f tan(delta)``.
    """
    cx, cy = camera.center(W_VIEW, H_VIEW)
    f = camera.focal_px(W_VIEW)
    theta = math.radians(camera.pitch_deg)
    y_up = (cy - row) / f
    return cx - f * math.tan(math.radians(delta_deg)) * (math.cos(theta) - math.sin(theta) * y_up)


def _red_centroid(row: np.ndarray) -> float:
    redness = np.clip(row[:, 0].astype(float) - row[:, 1].astype(float) - 10.0, 0.0, None)
    assert redness.sum() > 0, "marker not visible"
    return float((redness * np.arange(redness.size)).sum() / redness.sum())


def _srgb_scaled(img: np.ndarray, gain: float) -> np.ndarray:
    v = img.astype(float) / 255.0
    lin = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4) * gain
    lin = np.clip(lin, 0.0, 1.0)
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055) * 255.0


# ------------------------------------------------------------------------- make_room


def test_same_seed_same_room_and_render_other_seed_differs() -> None:
    a = make_room(np.random.default_rng(5))
    b = make_room(np.random.default_rng(5))
    c = make_room(np.random.default_rng(6))
    np.testing.assert_array_equal(a.wall_texture, b.wall_texture)
    assert (a.floor_rgb, a.ceiling_rgb) == (b.floor_rgb, b.ceiling_rgb)
    assert np.abs(a.wall_texture.astype(int) - c.wall_texture.astype(int)).mean() > 5.0
    cam = Camera(yaw_deg=37.0, pitch_deg=5.0)
    ra = render_room_view(a, 0.4, -1.2, cam)
    np.testing.assert_array_equal(ra, render_room_view(b, 0.4, -1.2, cam))
    assert np.abs(ra.astype(int) - render_room_view(c, 0.4, -1.2, cam).astype(int)).mean() > 5.0


def test_make_room_leaves_global_state_alone() -> None:
    before = np.random.get_state()[1].copy()  # noqa: NPY002 (checking the legacy state)
    make_room(np.random.default_rng(1))
    np.testing.assert_array_equal(np.random.get_state()[1], before)  # noqa: NPY002


@pytest.mark.parametrize("ppm", [20, 100])
def test_make_room_geometry_and_texture_size(ppm: int) -> None:
    room = make_room(np.random.default_rng(2), 5.0, 3.0, 2.4, texture_px_per_m=ppm, open_top=True)
    assert (room.width_m, room.depth_m, room.wall_height_m) == (5.0, 3.0, 2.4)
    assert room.perimeter_m == 16.0
    assert room.wall_texture.shape == (round(2.4 * ppm), 16 * ppm, 3)
    assert room.wall_texture.dtype == np.uint8
    assert room.ceiling_rgb is None
    assert _room(0).ceiling_rgb is not None


@pytest.mark.parametrize("seed", range(4))
def test_room_is_colourful_and_coarse(seed: int) -> None:
    tex = _room(seed).wall_texture.astype(float)
    # colourful: plenty of saturated pixels (posters, screens, furniture)
    sat = tex.max(axis=2) - tex.min(axis=2)
    assert (sat > 80).mean() > 0.03
    # coarse: strong edges along a row are never closer than ~3 cm (no fine stripes)
    ppm = tex.shape[1] / _room(seed).perimeter_m
    grey = tex.mean(axis=2)
    for r in range(0, tex.shape[0], 5):
        edges = np.flatnonzero(np.abs(np.diff(grey[r])) > 40.0)
        if edges.size > 1:
            assert np.diff(edges).min() >= 0.03 * ppm - 1, f"fine stripe in row {r}"
    # and most of the texture is low-frequency: small residual after a 5 cm box blur
    k = max(3, round(0.05 * ppm) | 1)
    kernel = np.ones(k) / k
    blurred = np.apply_along_axis(lambda v: np.convolve(v, kernel, mode="same"), 1, grey)
    assert np.median(np.abs(grey - blurred)[:, k:-k]) < 3.0


def test_wall_point_follows_the_perimeter_convention() -> None:
    room, _ = _plain_room(6.0, 4.0)
    for x, y in [(3.0, -2.0), (3.0, 1.0), (3.0, 2.0), (0.5, 2.0), (-3.0, 0.3), (-1.0, -2.0)]:
        sx, sy = room.wall_point(_s_of_point(6.0, 4.0, x, y))
        assert sx == pytest.approx(x) and sy == pytest.approx(y)
    assert room.wall_point(room.perimeter_m + 1.0) == pytest.approx((3.0, -1.0))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"width_m": 1.0},
        {"depth_m": float("nan")},
        {"wall_height_m": 1.5},
        {"width_m": "wide"},
        {"texture_px_per_m": 5},
        {"texture_px_per_m": 50.5},
        {"texture_px_per_m": True},
        {"width_m": 200.0},  # texture wider than cv2.remap allows
    ],
)
def test_make_room_rejects_bad_arguments(kwargs: dict) -> None:
    with pytest.raises(ValueError):
        make_room(np.random.default_rng(0), **kwargs)


def test_make_room_needs_a_generator() -> None:
    with pytest.raises(TypeError, match="Generator"):
        make_room(42)  # type: ignore[arg-type]


def test_room_validation() -> None:
    tex = np.zeros((10, 40, 3), np.uint8)
    Room(2.0, 2.0, 1.0, tex, (0, 0, 0), None)
    with pytest.raises(ValueError, match="wall_texture"):
        Room(2.0, 2.0, 1.0, tex.astype(float), (0, 0, 0), None)
    with pytest.raises(ValueError, match="wall_texture"):
        Room(2.0, 2.0, 1.0, tex[:, :, 0], (0, 0, 0), None)
    with pytest.raises(ValueError, match="width_m"):
        Room(0.0, 2.0, 1.0, tex, (0, 0, 0), None)
    with pytest.raises(ValueError, match="wall_height_m"):
        Room(2.0, 2.0, float("inf"), tex, (0, 0, 0), None)
    with pytest.raises(ValueError, match="floor_rgb"):
        Room(2.0, 2.0, 1.0, tex, (0, 0, 256), None)
    with pytest.raises(ValueError, match="ceiling_rgb"):
        Room(2.0, 2.0, 1.0, tex, (0, 0, 0), (1, 2))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="sky_rgb"):
        Room(2.0, 2.0, 1.0, tex, (0, 0, 0), None, (0.5, 0, 0))  # type: ignore[arg-type]


# ------------------------------------------------------------------ render_room_view

_MARKERS = ((3.0, 0.5), (-1.0, 2.0), (-3.0, -1.2), (1.5, -2.0))


@pytest.mark.parametrize("pitch", [0.0, 12.0, -8.0])
@pytest.mark.parametrize(
    ("x", "y", "offset"),
    [(0.0, 0.0, 0.0), (-2.0, 1.0, 12.0), (1.8, -1.3, -20.0), (0.7, 1.5, 7.5), (-2.6, -1.6, -3.0)],
)
def test_marker_lands_on_the_pinhole_column(
    x: float, y: float, offset: float, pitch: float
) -> None:
    checked = 0
    for marker in _MARKERS:  # one marker per room: never two in view
        room, ((mx, my),) = _plain_room(markers=(marker,))
        # skip markers closer than 1 m, or seen at grazing incidence (< 25° to the wall),
        # where a 5 cm stripe is thinner than the spacing of the pixel rays and aliases
        on_x_wall = math.isclose(abs(mx), 3.0)
        incidence = math.atan2(abs(mx - x) if on_x_wall else abs(my - y),
                               abs(my - y) if on_x_wall else abs(mx - x))  # fmt: skip
        if math.hypot(mx - x, my - y) < 1.0 or math.degrees(incidence) < 25.0:
            continue
        bearing = math.degrees(math.atan2(my - y, mx - x))
        camera = Camera(yaw_deg=bearing + offset, pitch_deg=pitch)
        img = render_room_view(room, x, y, camera)
        row = camera.horizon_row(W_VIEW, H_VIEW)
        r = int(round(row))
        delta = float(wrap180(bearing - camera.yaw_deg))
        expected = _pinhole_column(camera, delta, r)
        assert _red_centroid(img[r]) == pytest.approx(expected, abs=1.0)
        if pitch == 0.0:  # the formula of the brief, at the horizon row
            cx = camera.center(W_VIEW, H_VIEW)[0]
            f = camera.focal_px(W_VIEW)
            assert _red_centroid(img[r]) == pytest.approx(
                cx - f * math.tan(math.radians(delta)), abs=1.0
            )
        checked += 1
    assert checked >= 2


def test_sideways_step_moves_a_near_marker_more_than_a_far_one() -> None:
    """Parallax: after a 0.3 m sideways step each marker is at its new pinhole column,
    and the near one (1 m away) has moved much further than the far one (5 m)."""
    shifts = []
    for marker, yaw in (((3.0, 0.0), 0.0), ((-3.0, 0.0), 180.0)):
        room, ((mx, my),) = _plain_room(markers=(marker,))
        camera = Camera(yaw_deg=yaw)
        row = int(round(camera.horizon_row(W_VIEW, H_VIEW)))
        columns = []
        for y in (0.0, -0.3):
            img = render_room_view(room, 2.0, y, camera)
            delta = float(wrap180(math.degrees(math.atan2(my - y, mx - 2.0)) - yaw))
            columns.append(_red_centroid(img[row]))
            assert columns[-1] == pytest.approx(_pinhole_column(camera, delta, row), abs=1.0)
        shifts.append(abs(columns[1] - columns[0]))
    near, far = shifts
    f = Camera().focal_px(W_VIEW)
    assert near == pytest.approx(f * 0.3 / 1.0, abs=1.5)  # tan(bearing change) * f
    assert far == pytest.approx(f * 0.3 / 5.0, abs=1.5)
    assert near > 4.0 * far


def _first_row(column: np.ndarray, colour: tuple[int, int, int], from_top: bool) -> int:
    match = np.all(column == np.asarray(colour, np.uint8), axis=1)
    rows = np.flatnonzero(~match) if from_top else np.flatnonzero(match)
    return int(rows[0])


@pytest.mark.parametrize(
    ("pitch", "distance", "yaw"),
    [(30.0, 2.0, 0.0), (30.0, 3.0, 0.0), (30.0, 4.5, 0.0), (0.0, 9.0, 0.0), (25.0, 2.5, 90.0)],
)
def test_wall_top_edge_row_matches_projection(pitch: float, distance: float, yaw: float) -> None:
    room, _ = _plain_room(width=10.0, depth=6.0, height=2.5)
    eye = 0.3
    x, y = (5.0 - distance, 0.0) if yaw == 0.0 else (0.5, 3.0 - distance)
    camera = Camera(yaw_deg=yaw, pitch_deg=pitch)
    img = render_room_view(room, x, y, camera, eye_height_m=eye)
    f = camera.focal_px(W_VIEW)
    cx, cy = camera.center(W_VIEW, H_VIEW)
    elevation = math.atan((room.wall_height_m - eye) / distance)
    expected = cy - f * math.tan(elevation - math.radians(pitch))
    assert 1 < expected < H_VIEW - 2
    for u in (int(math.floor(cx)), int(math.ceil(cx))):
        first_wall = _first_row(img[:, u], CEILING, from_top=True)
        assert first_wall - 0.5 == pytest.approx(expected, abs=1.0)
        assert tuple(img[first_wall - 1, u]) == CEILING
        assert tuple(img[first_wall, u]) == (GREY, GREY, GREY)


@pytest.mark.parametrize(("distance", "pitch"), [(2.0, 15.0), (3.0, 10.0), (5.0, 0.0)])
def test_texture_rows_map_to_wall_heights(distance: float, pitch: float) -> None:
    """A red band painted at 1.0-1.6 m (texture rows counted from the top) appears
    between the projected rows of those heights."""
    room, _ = _plain_room(width=10.0, depth=6.0, height=2.5)
    tex = room.wall_texture.copy()
    z_rows = 2.5 - (np.arange(tex.shape[0]) + 0.5) / 100.0
    tex[(z_rows >= 1.0) & (z_rows < 1.6)] = RED
    room = Room(10.0, 6.0, 2.5, tex, FLOOR, CEILING)
    eye = 0.3
    camera = Camera(yaw_deg=0.0, pitch_deg=pitch)
    img = render_room_view(room, 5.0 - distance, 0.0, camera, eye_height_m=eye)
    f = camera.focal_px(W_VIEW)
    cx, cy = camera.center(W_VIEW, H_VIEW)
    theta = math.radians(pitch)

    def row_of(z: float) -> float:
        return cy - f * math.tan(math.atan((z - eye) / distance) - theta)

    column = img[:, int(math.floor(cx))].astype(int)
    red = np.flatnonzero(column[:, 0] - column[:, 1] > 100)  # at least half red
    assert red[0] - 0.5 == pytest.approx(row_of(1.6), abs=1.0)
    assert red[-1] + 0.5 == pytest.approx(row_of(1.0), abs=1.0)


@pytest.mark.parametrize("distance", [1.0, 2.0, 4.0])
def test_wall_bottom_edge_row_matches_projection(distance: float) -> None:
    room, _ = _plain_room(width=10.0, depth=6.0, height=2.5)
    eye = 0.3
    camera = Camera(yaw_deg=180.0)
    img = render_room_view(room, -5.0 + distance, 0.0, camera, eye_height_m=eye)
    f = camera.focal_px(W_VIEW)
    cx, cy = camera.center(W_VIEW, H_VIEW)
    expected = cy + f * eye / distance
    u = int(math.floor(cx))
    column = img[:, u].astype(int)
    floor_like = (column[:, 1] > 150) & (column[:, 0] < 100)  # carpet tiles vary a little
    first_floor = int(np.flatnonzero(floor_like)[0])
    assert first_floor - 0.5 == pytest.approx(expected, abs=1.0)
    assert np.all(floor_like[first_floor:])


def test_nearer_wall_looks_bigger() -> None:
    room, _ = _plain_room(width=10.0, depth=6.0)
    camera = Camera(pitch_deg=30.0)
    sizes = []
    for x in (-2.0, 0.0, 2.0):
        img = render_room_view(room, x, 0.0, camera)
        sizes.append(int(np.all(img == np.uint8(GREY), axis=2).sum()))
    assert sizes[0] < sizes[1] < sizes[2]


def test_floor_below_ceiling_or_sky_above() -> None:
    room, _ = _plain_room()
    down = render_room_view(room, 0.0, 0.0, Camera(pitch_deg=-60.0))
    assert np.all(np.abs(down[-20:].astype(int) - FLOOR).max(axis=2) <= 20)
    up = render_room_view(room, 2.0, 0.0, Camera(pitch_deg=60.0))
    assert np.all(up[:10] == np.asarray(CEILING, np.uint8))
    open_room, _ = _plain_room(open_top=True)
    sky = render_room_view(open_room, 2.0, 0.0, Camera(pitch_deg=60.0))
    assert np.all(sky[:10] == np.asarray(open_room.sky_rgb, np.uint8))
    assert open_room.ceiling_rgb is None


def test_render_shape_dtype_and_purity() -> None:
    room = _room(1)
    texture = room.wall_texture.copy()
    img = render_room_view(room, 1.0, 0.5, Camera(hfov_deg=70.0, yaw_deg=-30.0), 64, 48)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    np.testing.assert_array_equal(room.wall_texture, texture)
    again = render_room_view(room, 1.0, 0.5, Camera(hfov_deg=70.0, yaw_deg=-30.0), 64, 48)
    np.testing.assert_array_equal(img, again)


def test_principal_point_crop_matches_full_render() -> None:
    room = _room(2)
    full_cam = Camera(yaw_deg=100.0, pitch_deg=7.0)
    full = render_room_view(room, -1.0, 0.8, full_cam)
    u0, v0, w, h = 40, 30, 100, 80
    cx, cy = full_cam.center(W_VIEW, H_VIEW)
    crop_cam = Camera.from_focal(
        full_cam.focal_px(W_VIEW), w, 100.0, 7.0, principal_point=(cx - u0, cy - v0)
    )
    crop = render_room_view(room, -1.0, 0.8, crop_cam, w, h)
    diff = np.abs(crop.astype(int) - full[v0 : v0 + h, u0 : u0 + w].astype(int)).max(axis=2)
    assert (diff > 2).mean() < 0.005


def test_illumination_darkens_like_linear_light() -> None:
    room = _room(3)
    cam = Camera(yaw_deg=200.0)
    base = render_room_view(room, 0.5, 0.5, cam)
    np.testing.assert_array_equal(render_room_view(room, 0.5, 0.5, cam, illumination=1.0), base)
    dark = render_room_view(room, 0.5, 0.5, cam, illumination=0.5)
    assert dark.mean() < 0.85 * base.mean()
    assert np.all(dark <= base)
    assert np.abs(dark - _srgb_scaled(base, 0.5)).max() <= 1.0
    bright = render_room_view(room, 0.5, 0.5, cam, illumination=2.0)
    assert bright.mean() > base.mean()


@pytest.mark.parametrize(
    ("x", "y"),
    [(3.0, 0.0), (-3.0, 0.0), (0.0, 2.0), (0.0, -2.0), (10.0, 0.0), (0.0, -7.5), (3.0, 2.0)],
)
def test_rendering_from_outside_raises(x: float, y: float) -> None:
    room, _ = _plain_room(6.0, 4.0)
    with pytest.raises(ValueError, match="inside the room"):
        render_room_view(room, x, y, Camera())


@pytest.mark.parametrize(
    "kwargs",
    [
        {"width": 1},
        {"height": 0},
        {"width": 20.5},
        {"height": True},
        {"illumination": 0.0},
        {"illumination": -1.0},
        {"illumination": float("nan")},
        {"illumination": float("inf")},
        {"eye_height_m": 0.0},
        {"eye_height_m": 2.5},
        {"eye_height_m": -0.1},
        {"eye_height_m": float("nan")},
        {"x": float("nan")},
        {"y": "middle"},
    ],
)
def test_render_rejects_bad_arguments(kwargs: dict) -> None:
    room, _ = _plain_room()
    args = {"x": 0.0, "y": 0.0, "camera": Camera()} | kwargs
    with pytest.raises(ValueError):
        render_room_view(room, **args)


def test_render_rejects_wrong_types() -> None:
    room, _ = _plain_room()
    with pytest.raises(TypeError, match="Camera"):
        render_room_view(room, 0.0, 0.0, 30.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="Room"):
        render_room_view(room.wall_texture, 0.0, 0.0, Camera())  # type: ignore[arg-type]
