"""What a compass map, its colour classes and an atlas may claim: memory, entries, ranges.

A map file is small (its counts compress well) but decides how much memory loading it
and scoring a frame take; every config a file brings goes through the checks a typed
config does.
"""

from __future__ import annotations

import json
import tracemalloc
import zipfile

import numpy as np
import pytest

from vc_gym.compass import (
    AIBO_HFOV_DEG,
    Camera,
    CompassAtlas,
    CompassConfig,
    VisualCompass,
    map_files,
)
from vc_gym.compass.atlas import MAX_ATLAS_BYTES, MAX_SPOTS
from vc_gym.compass.config import MAX_MAP_BYTES, MAX_MAP_ENTRIES
from vc_gym.compass.map_files import MAX_LEARNED_SIZES
from vc_gym.errors import MapFileError
from vc_gym.persistence import MAX_MEMBERS, load_npz_checked
from vc_gym.worlds.panorama import render_view

#: 512 sectors against 35,999 headings: every heading its own phase of the sectors, so
#: scoring one frame would need tens of gigabytes (a 5 kB map file).
HOSTILE = {"n_colors": 3, "sector_deg": 360 / 512, "heading_step_deg": 360 / 35999}
#: A single map of it fits (about 460 MiB with the widest camera), three do not.
WIDE_SCORES = {"n_colors": 3, "sector_deg": 360 / 512, "heading_step_deg": 0.1}


def _learned(pano, config: CompassConfig, yaws=range(0, 360, 45)) -> VisualCompass:
    vc = VisualCompass(config)
    vc.fit_colors([render_view(pano, Camera(yaw_deg=a)) for a in range(0, 360, 90)])
    for yaw in yaws:
        vc.learn(render_view(pano, Camera(yaw_deg=yaw)), Camera(yaw_deg=yaw))
    return vc


def _arrays(path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as d:
        return {k: d[k] for k in d.files}


def _rewrite(path, out, **changes):
    arrays = _arrays(path)
    arrays.update(changes)
    np.savez(out, **arrays)
    return out


def _with_config(arrays: dict[str, np.ndarray], **fields) -> np.ndarray:
    cfg = json.loads(str(arrays["config"]))
    cfg.update(fields)
    return np.array(json.dumps(cfg))


@pytest.fixture(scope="module")
def small_map(room_pano, tmp_path_factory):
    vc = _learned(room_pano, CompassConfig(n_colors=3))
    return vc.save(tmp_path_factory.mktemp("limits") / "small.npz")


# ------------------------------------------------------------------ memory
@pytest.mark.parametrize(
    "fields",
    [
        HOSTILE,
        # exactly MAX_MAP_ENTRIES counts: about 530 MiB to load and score a frame
        {"n_colors": 32, "n_bins": 32, "sector_deg": 360 / 512},
    ],
)
def test_configs_that_would_claim_too_much_memory_are_refused(fields):
    with pytest.raises(ValueError, match="MAX_MAP_BYTES = 512 MiB"):
        CompassConfig(**fields)


def test_a_map_file_whose_config_claims_gigabytes_is_refused(small_map, tmp_path):
    cfg = CompassConfig(n_colors=3)
    arrays = _arrays(small_map)
    n_sectors = 512
    counts = np.zeros((n_sectors, cfg.n_colors**2, cfg.n_bins), dtype=np.uint32)
    counts[0, :, -1] = 1  # one frame saw sector 0
    observations = np.zeros(n_sectors, dtype=np.uint32)
    observations[0] = 1
    path = _rewrite(
        small_map,
        tmp_path / "hostile.npz",
        config=_with_config(arrays, **HOSTILE),
        counts=counts,
        sector_observations=observations,
        frames_learned=np.array(1),
    )
    # refused from the config, before any table the config asks for is built
    with pytest.raises(MapFileError, match="hostile.npz: invalid config.*MAX_MAP_BYTES"):
        VisualCompass.load(path)


@pytest.mark.parametrize(
    "fields",
    [
        # the map's tables dominate (32 bytes a count)
        {"n_colors": 16, "n_bins": 16, "sector_deg": 2.25},
        # the per-frame group scores dominate (45 phases x 84 sectors in view x 512)
        {"n_colors": 3, "sector_deg": 360 / 512, "heading_step_deg": 0.5},
    ],
)
def test_memory_bytes_agrees_with_tracemalloc(room_pano, tmp_path, fields):
    config = CompassConfig(**fields)
    path = _learned(room_pano, config).save(tmp_path / "map.npz")
    image = render_view(room_pano, Camera(yaw_deg=73.0))
    tracemalloc.start()
    try:
        vc = VisualCompass.load(path)
        vc.estimate(image, Camera())
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    predicted = config.memory_bytes(AIBO_HFOV_DEG)
    assert 0.8 < peak / predicted < 1.2, (peak, predicted)
    # the widest camera sees more sectors at once: the bound reckons with it
    assert config.memory_bytes() >= predicted


def test_the_largest_allowed_map_saves_and_loads(room_pano, tmp_path):
    # the most sectors a map of 32 classes and 32 bins may have
    for n_sectors in range(512, 0, -1):
        try:
            config = CompassConfig(n_colors=32, n_bins=32, sector_deg=360 / n_sectors)
        except ValueError:
            continue
        break
    assert config.map_entries > 0.98 * MAX_MAP_ENTRIES
    assert config.memory_bytes() <= MAX_MAP_BYTES
    vc = _learned(room_pano, config, yaws=[30.0])
    path = vc.save(tmp_path / "largest.npz")
    loaded = VisualCompass.load(path)
    assert loaded.config == config and loaded.frames_learned == 1
    np.testing.assert_array_equal(loaded.map_counts, vc.map_counts)


def test_saved_counts_fit_the_loader_entry_limit():
    from vc_gym.compass.config import COUNT_BYTES
    from vc_gym.persistence import MAX_ENTRY_BYTES, NPY_HEADER_BYTES

    assert MAX_MAP_ENTRIES * COUNT_BYTES + NPY_HEADER_BYTES <= MAX_ENTRY_BYTES


# ------------------------------------------------------------------ config ranges
@pytest.mark.parametrize(
    ("field", "value"),
    [("temperature", 1e-300), ("temperature", 1e300), ("smoothing", 1e300), ("smoothing", 1e-300)],
)
def test_a_map_file_with_an_absurd_temperature_or_smoothing_is_refused(
    small_map, tmp_path, field, value
):
    with pytest.raises(ValueError, match=f"{field} must be in"):
        CompassConfig(**{field: value})
    path = _rewrite(
        small_map, tmp_path / "bad.npz", config=_with_config(_arrays(small_map), **{field: value})
    )
    with pytest.raises(MapFileError, match=f"bad.npz: invalid config \\({field} must be in"):
        VisualCompass.load(path)


@pytest.mark.parametrize(
    ("key", "change", "message"),
    [
        ("colors_means", lambda a: a * 1e300, "colors_means must lie in the colour range"),
        ("colors_means", lambda a: a - 300.0, "colors_means must lie in the colour range"),
        ("colors_covariances", lambda a: a * 1e-300, "Cholesky pivots"),
        ("colors_covariances", lambda a: a * 1e6, "variances <="),
        ("colors_exposure_reference", lambda a: a + 5.0, "exposure_reference must be in"),
        ("exposure_reference", lambda a: a + 5.0, "exposure_reference' missing or not a light"),
        (
            "learned_sizes",
            lambda a: np.arange(1, 2 * MAX_LEARNED_SIZES + 3).reshape(-1, 2),
            "frame sizes, more than",
        ),
    ],
)
def test_a_map_file_with_implausible_entries_is_refused(small_map, tmp_path, key, change, message):
    arrays = _arrays(small_map)
    path = _rewrite(small_map, tmp_path / "bad.npz", **{key: change(arrays[key])})
    with pytest.raises(MapFileError, match=message) as info:
        VisualCompass.load(path)
    assert "bad.npz" in str(info.value)


def test_a_map_learns_a_bounded_number_of_frame_sizes(room_pano, monkeypatch):
    monkeypatch.setattr(map_files, "MAX_LEARNED_SIZES", 2)
    vc = _learned(room_pano, CompassConfig(n_colors=3), yaws=[0.0])
    vc.learn(render_view(room_pano, Camera(), width=200, height=150), Camera())
    with pytest.raises(ValueError, match="at most 2 different sizes"):
        vc.learn(render_view(room_pano, Camera(), width=180, height=140), Camera())
    assert vc.frames_learned == 2


# ------------------------------------------------------------------ atlases
@pytest.fixture(scope="module")
def wide_scores_map(room_pano):
    config = CompassConfig(**WIDE_SCORES)
    assert config.memory_bytes() <= MAX_MAP_BYTES
    assert config.memory_bytes(n_maps=3) > MAX_ATLAS_BYTES
    return _learned(room_pano, config, yaws=[0.0, 120.0, 240.0])


def test_an_atlas_whose_maps_claim_too_much_memory_is_refused(wide_scores_map, tmp_path):
    spots = {f"s{i}": ((float(i), 0.0), wide_scores_map) for i in range(3)}
    with pytest.raises(ValueError, match="3 maps of this config.*MAX_ATLAS_BYTES"):
        CompassAtlas(spots, home="s0")
    # the same as a file: one spot saved, copied twice
    one = CompassAtlas({"s0": ((0.0, 0.0), wide_scores_map)}, home="s0")
    arrays = _arrays(one.save(tmp_path / "one.npz"))
    header = json.loads(str(arrays["atlas"]))
    header["names"] = ["s0", "s1", "s2"]
    header["positions"] = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]
    arrays["atlas"] = np.array(json.dumps(header))
    for i in (1, 2):
        arrays.update(
            {
                k.replace("spot0/", f"spot{i}/"): a
                for k, a in arrays.items()
                if k.startswith("spot0/")
            }
        )
    arrays["home_scores"] = np.zeros((0, 3))
    arrays["home_headings"] = np.zeros((0, 3))
    np.savez(tmp_path / "three.npz", **arrays)
    with pytest.raises(MapFileError, match="three.npz: invalid config.*MAX_ATLAS_BYTES"):
        CompassAtlas.load(tmp_path / "three.npz")


def test_an_atlas_file_whose_spots_differ_in_config_is_refused(room_atlas, tmp_path):
    arrays = _arrays(room_atlas.save(tmp_path / "atlas.npz"))
    arrays["spot1/config"] = _with_config({"config": arrays["spot1/config"]}, temperature=2.0)
    np.savez(tmp_path / "mixed.npz", **arrays)
    with pytest.raises(MapFileError, match="mixed.npz: the spots' maps do not share one config"):
        CompassAtlas.load(tmp_path / "mixed.npz")


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("sharpness", 1e300, "sharpness must be in"),
        ("sharpness", 1e-300, "sharpness must be in"),
        ("kappa", 1e300, "kernel concentration"),
        ("positions", [[1e300, 0.0]] * 4, "position must be finite and within"),
        ("home_position", [1e300, 0.0], "home_position must be finite and within"),
        ("names", ["east", "east", "west", "south"], "repeats a spot name"),
    ],
)
def test_an_atlas_file_with_an_absurd_header_is_refused(
    room_atlas, tmp_path, field, value, message
):
    arrays = _arrays(room_atlas.save(tmp_path / "atlas.npz"))
    header = json.loads(str(arrays["atlas"]))
    header[field] = value
    arrays["atlas"] = np.array(json.dumps(header))
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(MapFileError, match=message) as info:
        CompassAtlas.load(tmp_path / "bad.npz")
    assert "bad.npz" in str(info.value)


def test_atlas_arguments_out_of_range_are_value_errors(room_atlas, room_pano):
    spots = {
        name: (position, vc)
        for name, position, vc in zip(
            room_atlas.names, room_atlas.positions.tolist(), room_atlas.compasses, strict=True
        )
    }
    with pytest.raises(ValueError, match="sharpness must be in"):
        CompassAtlas(spots, home="east", sharpness=1e300)
    image = render_view(room_pano, Camera())
    atlas = CompassAtlas(spots, home="east")
    for kernel in (1e-300, 1e-3, 400.0):
        with pytest.raises(ValueError, match="kernel_deg must be in"):
            atlas.normalize([image], [Camera()], kernel_deg=kernel)


def test_the_largest_atlas_file_fits_in_the_entry_count(room_pano, tmp_path):
    # spots with their own colour classes and light maps: the most entries a spot has
    config = CompassConfig(n_colors=3, exposure="map")
    a, b = (_learned(room_pano, config, yaws=[0.0]) for _ in range(2))
    counts = []
    for n in (1, 2):
        atlas = CompassAtlas(
            {f"s{i}": ((float(i), 0.0), vc) for i, vc in enumerate((a, b)[:n])}, "s0"
        )
        with zipfile.ZipFile(atlas.save(tmp_path / f"atlas{n}.npz")) as zf:
            infos = zf.infolist()
        counts.append(len(infos))
    per_spot = counts[1] - counts[0]
    assert per_spot == 15
    assert counts[0] - per_spot + MAX_SPOTS * per_spot <= MAX_MEMBERS
    # every directory record, with the longest spot number, within its allowance
    longest = max(46 + len(i.filename) + len(i.extra) + len(i.comment) for i in infos)
    assert longest + len(str(MAX_SPOTS - 1)) <= 256
    assert load_npz_checked(tmp_path / "atlas2.npz", "vc_gym.CompassAtlas", 1)
