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


def _load_map(kind: str, path: Path) -> None:
    try:
        loaded = _MAP_LOADERS[kind](path)
    except MapFileError:
        return
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
    how = data.draw(st.sampled_from(["scale", "value", "shape", "drop", "text"]))
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


@pytest.fixture(scope="module")
def agent_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("agent") / "agent"
    shutil.copytree(PRETRAINED_MODEL.parent, folder)
    return folder


def _load_agent(folder: Path) -> None:
    try:
        LearnedHomingAgent(folder / "model.zip")
    except ValueError:  # UnsafeModelError is one
        pass


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
