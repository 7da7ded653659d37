"""Mutated files: every file vc_gym reads either loads or fails with its documented error,
quickly, and never runs code.

Hypothesis mutates saved compass maps and atlases (bytes and array contents), model zips
(bytes and ``data`` fields) and settings files (text), then loads them: the loader must
return or raise only the kind of error it documents (``MapFileError`` for maps, a
``ValueError`` for agents and settings), within the examples' deadline.
"""

from __future__ import annotations

import io
import json
import shutil
import zipfile
from datetime import timedelta
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vc_gym.agents.learned import PRETRAINED_MODEL, LearnedHomingAgent
from vc_gym.compass import Camera, CompassAtlas, VisualCompass
from vc_gym.config_files import read_settings
from vc_gym.errors import MapFileError
from vc_gym.persistence import load_npz_checked, save_npz_atomic
from vc_gym.worlds.panorama import render_view
from vc_gym.worlds.panorama_painters import make_panorama

#: Every example must finish within this (a hang or a memory blow-up is a failure).
DEADLINE = timedelta(seconds=20)
FUZZ = settings(
    max_examples=60,
    deadline=DEADLINE,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    derandomize=True,
)

json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(2**70), 2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=20),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=10,
)


def _mutated(raw: bytes, edits: list[tuple[int, int]], cut: int | None) -> bytes:
    """``raw`` with bytes overwritten at (relative) offsets and optionally truncated."""
    data = bytearray(raw)
    for pos, value in edits:
        data[pos % len(data)] = value
    if cut is not None:
        data = data[: cut % len(data)]
    return bytes(data)


#: Numbers at and beyond the edges of the documented ranges (temperatures 0.01-1000,
#: smoothing 1e-3-1e4, colours 0-255, sharpness 0.01-1e4, counts >= 0).
EDGE_VALUES = [-1.0, 0.0, 1e-4, 0.009, 0.01, 1000.0, 1000.5, 1e4, 1e5, 255.5, 1e300, -0.0]

byte_edits = st.lists(st.tuples(st.integers(0, 2**31), st.integers(0, 255)), max_size=8)
cuts = st.none() | st.integers(0, 2**31)


@pytest.fixture(scope="module")
def saved_maps(tmp_path_factory) -> dict[str, Path]:
    """A learned compass and a two-spot atlas, saved."""
    folder = tmp_path_factory.mktemp("maps")
    pano = make_panorama(np.random.default_rng(3), width=1200, height=300, kind="room")
    compasses = []
    for shift in (0, 40):
        vc = VisualCompass()
        vc.fit_colors([render_view(pano, Camera(yaw_deg=a)) for a in range(0, 360, 90)])
        for a in range(0, 360, 45):
            vc.learn(render_view(pano, Camera(yaw_deg=a + shift)), Camera(yaw_deg=a))
        compasses.append(vc)
    compasses[0].save(folder / "compass.npz")
    atlas = CompassAtlas(
        {"a": ((0.0, 0.0), compasses[0]), "b": ((1.0, 0.0), compasses[1])}, home="a"
    )
    atlas.save(folder / "atlas.npz")
    return {"compass": folder / "compass.npz", "atlas": folder / "atlas.npz"}


_MAP_LOADERS = {"compass": VisualCompass.load, "atlas": CompassAtlas.load}

# The ranges docs/file-formats.md ("What a file may do": maps and atlases) documents for
# whatever a map file loads as, written out as numbers: a loader that lets more through
# fails here even if the package's own constants were changed with it.
TEMPERATURES = (0.01, 1000.0)
SMOOTHINGS = (1e-3, 1e4)
COLOR_RANGE = (0.0, 255.0)
SHARPNESSES = (0.01, 1e4)
MAP_MEMORY = 512 * 2**20
ATLAS_MEMORY = 2**30
#: The spread calibration a map keeps (vc_gym.compass.calibration): floor 0-90°.
SPREAD_FLOORS = (0.0, 90.0)


def check_compass_in_range(vc: VisualCompass) -> None:
    """AssertionError unless a loaded compass' config, spread, colour classes and map
    lie within the documented ranges."""
    cfg = vc.config
    assert TEMPERATURES[0] <= cfg.temperature <= TEMPERATURES[1], cfg
    assert SMOOTHINGS[0] <= cfg.smoothing <= SMOOTHINGS[1], cfg
    assert cfg.memory_bytes() <= MAP_MEMORY, cfg
    assert TEMPERATURES[0] <= vc.spread_temperature <= TEMPERATURES[1], vc.spread_temperature
    assert SPREAD_FLOORS[0] <= vc.spread_floor_deg <= SPREAD_FLOORS[1], vc.spread_floor_deg
    counts, seen = vc.map_counts, vc.sector_observations
    assert counts.shape == (cfg.n_sectors, cfg.n_colors**2, cfg.n_bins)
    assert np.all(np.isfinite(counts)) and np.all(counts >= 0)
    assert seen.shape == (cfg.n_sectors,) and np.all(seen >= 0)
    # one count per class pair of a sector for each frame that saw it (eq. 6)
    np.testing.assert_array_equal(
        counts.sum(axis=2), np.broadcast_to(seen[:, None], counts.shape[:2])
    )
    assert vc.frames_learned >= 0 and (vc.frames_learned == 0) == (seen.sum() == 0)
    assert 0.0 <= vc.learned_fraction <= 1.0
    colors = vc.colors
    if colors is None:
        return
    lo, hi = COLOR_RANGE
    assert colors.means.shape == (cfg.n_colors, 3)
    assert np.all(np.isfinite(colors.means)), colors.means
    assert np.all(colors.means >= lo - 1e-6) and np.all(colors.means <= hi + 1e-6), colors.means
    cov = colors.covariances
    assert cov.shape == (cfg.n_colors, 3, 3) and np.all(np.isfinite(cov))
    np.testing.assert_allclose(cov, np.swapaxes(cov, 1, 2), rtol=1e-9, atol=1e-9)
    assert np.all(np.linalg.eigvalsh(cov) > 0), "covariances not positive definite"
    assert np.all(np.isfinite(colors.weights)) and np.all(colors.weights >= 0)


def check_atlas_in_range(atlas: CompassAtlas) -> None:
    """AssertionError unless a loaded atlas and every map in it lie within the
    documented ranges."""
    assert len(atlas) >= 1 and len(atlas.compasses) == len(atlas.names)
    assert SHARPNESSES[0] <= atlas.sharpness <= SHARPNESSES[1], atlas.sharpness
    assert atlas.positions.shape == (len(atlas), 2) and np.all(np.isfinite(atlas.positions))
    assert np.all(np.isfinite(atlas.home_position))
    cfg = atlas.compasses[0].config
    assert cfg.memory_bytes(n_maps=len(atlas)) <= ATLAS_MEMORY, (cfg, len(atlas))
    for vc in atlas.compasses:
        assert vc.config == cfg
        check_compass_in_range(vc)


_RANGE_CHECKS = {"compass": check_compass_in_range, "atlas": check_atlas_in_range}


def _load_map(kind: str, path: Path) -> None:
    try:
        loaded = _MAP_LOADERS[kind](path)
    except MapFileError:
        return
    _RANGE_CHECKS[kind](loaded)  # what loads holds only what the documentation allows
    if kind == "compass":  # what loads must work, or refuse the frame with a ValueError
        frame = np.full((160, 208, 3), 128, np.uint8)
        try:
            loaded.estimate(frame, Camera())
        except ValueError:
            pass


@pytest.mark.parametrize("kind", ["compass", "atlas"])
@FUZZ
@given(edits=byte_edits, cut=cuts)
def test_a_map_with_mutated_bytes_loads_or_is_refused(saved_maps, tmp_path, kind, edits, cut):
    bad = tmp_path / f"{kind}.npz"
    bad.write_bytes(_mutated(saved_maps[kind].read_bytes(), edits, cut))
    _load_map(kind, bad)


@pytest.mark.parametrize("kind", ["compass", "atlas"])
@FUZZ
@given(data=st.data())
def test_a_map_with_mutated_arrays_loads_or_is_refused(saved_maps, tmp_path, kind, data):
    schema_of = {"compass": "vc_gym.VisualCompass", "atlas": "vc_gym.CompassAtlas"}
    with np.load(saved_maps[kind], allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    schema, version = str(arrays.pop("schema")), int(arrays.pop("schema_version"))
    assert schema == schema_of[kind]
    name = data.draw(st.sampled_from(sorted(arrays)))
    a = arrays[name]
    how = data.draw(st.sampled_from(["scale", "value", "shape", "drop", "text", "field"]))
    if how == "scale" and a.dtype.kind in "iuf":
        factor = data.draw(st.sampled_from([-1.0, 0.0, 1e-300, 1e300, np.inf, np.nan]))
        with np.errstate(all="ignore"):
            arrays[name] = (a.astype(np.float64) * factor).astype(a.dtype, copy=False)
    elif how == "value" and a.size and a.dtype.kind in "iuf":
        flat = a.astype(np.float64).ravel()
        flat[data.draw(st.integers(0, flat.size - 1))] = data.draw(
            st.sampled_from([-1.0, 1e308, np.nan, 2.0**40])
        )
        with np.errstate(all="ignore"):
            arrays[name] = flat.reshape(a.shape).astype(a.dtype, copy=False)
    elif how == "shape":
        arrays[name] = a.ravel()[: max(a.size - 1, 0)]
    elif how == "drop":
        del arrays[name]
    elif how == "field":
        # one field of a JSON entry (a config, the atlas' settings) set to a value at or
        # beyond the edge of its documented range
        settings_entries = sorted(k for k, v in arrays.items() if v.dtype.kind == "U")
        name = data.draw(st.sampled_from(settings_entries))
        fields = json.loads(str(arrays[name]))
        key = data.draw(st.sampled_from(sorted(fields)))
        fields[key] = data.draw(st.sampled_from(EDGE_VALUES) | json_values)
        arrays[name] = np.array(json.dumps(fields, allow_nan=True))
    else:
        arrays[name] = np.array(json.dumps(data.draw(json_values), allow_nan=True))
    bad = save_npz_atomic(tmp_path / f"{kind}.npz", schema, version, arrays)
    _load_map(kind, bad)


def test_the_map_mutation_test_reads_real_schemas(saved_maps):
    for kind, path in saved_maps.items():
        with np.load(path, allow_pickle=False) as z:
            schema = str(z["schema"])
        load_npz_checked(path, schema, int(np.load(path)["schema_version"]))
        assert _MAP_LOADERS[kind](path) is not None
        _RANGE_CHECKS[kind](_MAP_LOADERS[kind](path))


def _with_entry(saved: Path, out: Path, entry: str, change) -> Path:
    """``saved`` with ``change(entry's value)`` stored in place of ``entry``: a JSON
    entry is changed as a dict, an array as a float64 copy (cast back)."""
    with np.load(saved, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    schema, version = str(arrays.pop("schema")), int(arrays.pop("schema_version"))
    a = arrays[entry]
    if a.dtype.kind == "U":
        fields = json.loads(str(a))
        change(fields)
        arrays[entry] = np.array(json.dumps(fields))
    else:
        b = a.astype(np.float64)
        change(b)
        arrays[entry] = b.astype(a.dtype)
    return save_npz_atomic(out, schema, version, arrays)


def _set(key, value):
    def change(target):
        target[key] = value

    return change


#: (file, entry, change, within the documented range?): each documented edge, just
#: inside and just beyond. A loader that lets one beyond through fails the test, and the
#: range checks of the fuzz tests reject what it loads.
EDGES = [
    ("compass", "config", _set("temperature", 0.01), True),
    ("compass", "config", _set("temperature", 1000.0), True),
    ("compass", "config", _set("temperature", 0.0099), False),
    ("compass", "config", _set("temperature", 1000.5), False),
    ("compass", "config", _set("smoothing", 1e-3), True),
    ("compass", "config", _set("smoothing", 1e4), True),
    ("compass", "config", _set("smoothing", 0.99e-3), False),
    ("compass", "config", _set("smoothing", 1.01e4), False),
    ("compass", "colors_means", _set((0, 0), 255.0), True),
    ("compass", "colors_means", _set((0, 0), 0.0), True),
    ("compass", "colors_means", _set((0, 0), 255.5), False),
    ("compass", "colors_means", _set((0, 0), -0.5), False),
    ("compass", "spread_calibration", _set(0, 1000.0), True),
    ("compass", "spread_calibration", _set(0, 1000.5), False),
    ("compass", "spread_calibration", _set(1, 90.5), False),
    ("compass", "counts", _set((0, 0, 0), -1.0), False),  # wraps round: sums no longer match
    ("atlas", "atlas", _set("sharpness", 0.01), True),
    ("atlas", "atlas", _set("sharpness", 1e4), True),
    ("atlas", "atlas", _set("sharpness", 0.0099), False),
    ("atlas", "atlas", _set("sharpness", 1.01e4), False),
    ("atlas", "spot1/config", _set("temperature", 1000.5), False),
    ("atlas", "spot1/colors_means", _set((1, 2), 255.5), False),
    ("atlas", "spot0/spread_calibration", _set(1, 90.5), False),
]


@pytest.mark.parametrize(("kind", "entry", "change", "within"), EDGES)
def test_a_map_loads_within_its_documented_ranges_and_not_beyond(
    saved_maps, tmp_path, kind, entry, change, within
):
    path = _with_entry(saved_maps[kind], tmp_path / f"{kind}.npz", entry, change)
    if within:
        _RANGE_CHECKS[kind](_MAP_LOADERS[kind](path))
    else:
        with pytest.raises(MapFileError):
            _MAP_LOADERS[kind](path)


def test_the_range_checks_reject_out_of_range_content(saved_maps):
    """The checks the fuzz tests run on whatever loads fail for content beyond the
    documented ranges (set past the loader, as a loader that let it through would)."""
    vc = VisualCompass.load(saved_maps["compass"])
    check_compass_in_range(vc)
    vc._spread = (1000.5, 0.5)
    with pytest.raises(AssertionError):
        check_compass_in_range(vc)
    vc = VisualCompass.load(saved_maps["compass"])
    means = vc.colors.means.copy()
    means[0, 0] = 255.5
    vc._colors = SimpleNamespace(
        means=means, covariances=vc.colors.covariances, weights=vc.colors.weights
    )
    with pytest.raises(AssertionError):
        check_compass_in_range(vc)
    atlas = CompassAtlas.load(saved_maps["atlas"])
    check_atlas_in_range(atlas)
    atlas.sharpness = 1.01e4
    with pytest.raises(AssertionError):
        check_atlas_in_range(atlas)


@pytest.fixture(scope="module")
def agent_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("agent") / "agent"
    shutil.copytree(PRETRAINED_MODEL.parent, folder)
    return folder


#: What a loaded model may ask for (docs/file-formats.md, "Models"): at most 64 envs,
#: 65,536 rollout steps, 2·10⁶ replay transitions, 8 hidden layers of 4,096 units.
MODEL_ENVS, MODEL_ROLLOUT, MODEL_REPLAY = 64, 65_536, 2_000_000
MODEL_LAYERS, MODEL_WIDTH = 8, 4_096


def check_agent_in_range(agent: LearnedHomingAgent) -> None:
    """AssertionError unless a loaded agent's model lies within the documented bounds."""
    import torch

    model = agent.model
    assert 1 <= model.n_envs <= MODEL_ENVS, model.n_envs
    assert getattr(model, "n_steps", 1) <= MODEL_ROLLOUT, model.n_steps
    assert getattr(model, "buffer_size", 1) <= MODEL_REPLAY, model.buffer_size
    layers = [m for m in model.policy.modules() if isinstance(m, torch.nn.Linear)]
    assert layers and all(m.out_features <= MODEL_WIDTH for m in layers)
    for net in ("policy_net", "value_net"):
        hidden = getattr(getattr(model.policy, "mlp_extractor", None), net, None)
        if hidden is not None:
            n = sum(isinstance(m, torch.nn.Linear) for m in hidden.modules())
            assert n <= MODEL_LAYERS, (net, n)


def _load_agent(folder: Path) -> None:
    try:
        agent = LearnedHomingAgent(folder / "model.zip")
    except ValueError:  # UnsafeModelError is one
        return
    check_agent_in_range(agent)


def test_the_agent_range_check_rejects_a_model_beyond_the_bounds(agent_dir):
    agent = LearnedHomingAgent(agent_dir / "model.zip")
    check_agent_in_range(agent)
    agent.model.n_envs = MODEL_ENVS + 1  # as a loader that let it through would load it
    with pytest.raises(AssertionError):
        check_agent_in_range(agent)


@FUZZ
@given(edits=byte_edits, cut=cuts)
def test_a_model_zip_with_mutated_bytes_loads_or_is_refused(agent_dir, tmp_path, edits, cut):
    folder = tmp_path / "agent"
    shutil.copytree(agent_dir, folder, dirs_exist_ok=True)
    model = folder / "model.zip"
    model.write_bytes(_mutated(model.read_bytes(), edits, cut))
    _load_agent(folder)


@FUZZ
@given(data=st.data())
def test_a_model_zip_with_mutated_data_loads_or_is_refused(agent_dir, tmp_path, data):
    folder = tmp_path / "agent"
    shutil.copytree(agent_dir, folder, dirs_exist_ok=True)
    model = folder / "model.zip"
    with zipfile.ZipFile(agent_dir / "model.zip") as z:
        entries = {i.filename: z.read(i) for i in z.infolist()}
    fields = json.loads(entries["data"])
    key = data.draw(st.sampled_from([*sorted(fields), "env", "policy_kwargs.net_arch"]))
    value = data.draw(json_values)
    if key == "policy_kwargs.net_arch":
        fields["policy_kwargs"]["net_arch"] = value
    else:
        fields[key] = value
    entries["data"] = json.dumps(fields, allow_nan=True).encode()
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name, content in entries.items():
            z.writestr(name, content)
    model.write_bytes(buf.getvalue())
    _load_agent(folder)


@FUZZ
@given(data=st.data())
def test_an_agent_config_with_mutated_fields_loads_or_is_refused(agent_dir, tmp_path, data):
    folder = tmp_path / "agent"
    shutil.copytree(agent_dir, folder, dirs_exist_ok=True)
    cfg = json.loads((folder / "config.json").read_text())
    where = data.draw(st.sampled_from(["top", "env"]))
    target = cfg if where == "top" else cfg["env"]
    key = data.draw(st.sampled_from([*sorted(target), "tracker", "learner", "extra"]))
    target[key] = data.draw(json_values | st.sampled_from(["os:system", "sys:exit", "this:x"]))
    (folder / "config.json").write_text(json.dumps(cfg, allow_nan=True))
    _load_agent(folder)


settings_text = st.text(
    alphabet=st.sampled_from(list("ab:-[]{}&*!|>'\"\n #0123456789.,?%@`~\\")), max_size=300
)


@pytest.mark.parametrize("suffix", [".yml", ".json"])
@FUZZ
@given(text=settings_text)
def test_a_settings_file_of_any_text_reads_or_is_refused(tmp_path, suffix, text):
    from vc_gym.training.config import read_train_config

    path = tmp_path / f"t{suffix}"
    path.write_text(text)
    try:
        read_settings(path)
    except ValueError:
        pass
    try:
        read_train_config(path)
    except ValueError:
        pass


@FUZZ
@given(data=st.data())
def test_a_training_settings_file_with_any_values_is_read_or_refused(tmp_path, data):
    from vc_gym.training.config import TrainConfig, read_train_config

    names = sorted(TrainConfig.__dataclass_fields__)
    values = {
        data.draw(st.sampled_from(names)): data.draw(
            json_values | st.sampled_from(["os:abort", "sys:exit", "this:x", "64"])
        )
        for _ in range(data.draw(st.integers(1, 3)))
    }
    path = tmp_path / "t.json"
    path.write_text(json.dumps(values, allow_nan=True))
    try:
        read_train_config(path)
    except ValueError:
        pass
