"""Hostile and broken .npz files: every one a MapFileError naming the file, fast, small."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

from vc_gym.compass import VisualCompass
from vc_gym.errors import MapFileError
from vc_gym.persistence import load_npz_checked, save_npz_atomic

SCHEMA, VERSION = "vc_gym.Test", 1


@pytest.fixture
def good(tmp_path):
    return save_npz_atomic(tmp_path / "good.npz", SCHEMA, VERSION, {"a": np.arange(6.0)})


def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, array, allow_pickle=True)
    return buf.getvalue()


def _zip(path, entries: dict[str, bytes], compress=zipfile.ZIP_DEFLATED):
    with zipfile.ZipFile(path, "w", compress) as zf:
        for name, data in entries.items():
            zf.writestr(name, data)
    return path


def _header_only(shape, dtype="<f8") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": dtype, "fortran_order": False, "shape": shape}
    )
    return buf.getvalue()


def _base() -> dict[str, bytes]:
    return {
        "schema.npy": _npy(np.array(SCHEMA)),
        "schema_version.npy": _npy(np.array(VERSION, np.int64)),
    }


def test_a_good_file_round_trips(good):
    np.testing.assert_array_equal(load_npz_checked(good, SCHEMA, VERSION)["a"], np.arange(6.0))


def test_a_huge_zero_entry_is_refused_before_it_is_decompressed(tmp_path):
    # 1 GiB of zeros compresses to ~1 MB; it used to be decompressed (1.6 GB peak)
    path = tmp_path / "bomb.npz"
    header = _header_only((2**27,))
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in _base().items():
            zf.writestr(name, data)
        with zf.open("extra.npy", "w", force_zip64=True) as fh:
            fh.write(header)
            chunk = bytes(2**24)
            for _ in range(2**30 // 2**24):
                fh.write(chunk)
    with pytest.raises(MapFileError, match="bomb.npz.*more than|bomb.npz.*larger than"):
        load_npz_checked(path, SCHEMA, VERSION)


def test_a_header_declaring_a_huge_shape_is_refused(tmp_path):
    # used to raise MemoryError
    bad = _zip(tmp_path / "shape.npz", {**_base(), "a.npy": _header_only((10**6, 10**6))})
    with pytest.raises(MapFileError, match="shape.npz.*declares shape"):
        load_npz_checked(bad, SCHEMA, VERSION)


@pytest.mark.parametrize(
    "entries",
    [
        {"a.npy": b"\x93NUMPY\x01\x00\x10\x00{'descr': '<f8'    \n"},  # malformed header
        {"a.npy": _npy(np.array([object()], dtype=object))},  # a pickled object array
        {"a.npy": _npy(np.array([1 + 2j]))},  # complex
        {"notes.txt": b"hello"},  # not an array
    ],
)
def test_entries_that_are_not_plain_arrays_are_refused(tmp_path, entries):
    bad = _zip(tmp_path / "odd.npz", {**_base(), **entries})
    with pytest.raises(MapFileError, match="odd.npz"):
        load_npz_checked(bad, SCHEMA, VERSION)


def test_a_repeated_entry_is_refused(tmp_path):
    path = tmp_path / "twice.npz"
    with zipfile.ZipFile(path, "w") as zf, pytest.warns(UserWarning, match="Duplicate"):
        for name, data in _base().items():
            zf.writestr(name, data)
        zf.writestr("a.npy", _npy(np.zeros(2)))
        zf.writestr("a.npy", _npy(np.ones(2)))
    with pytest.raises(MapFileError, match="repeated"):
        load_npz_checked(path, SCHEMA, VERSION)


@pytest.mark.parametrize("version", [np.array("1"), np.array(1.9), np.array([1])])
def test_a_schema_version_that_is_not_an_integer_is_refused(tmp_path, version):
    bad = _zip(tmp_path / "v.npz", {**_base(), "schema_version.npy": _npy(version)})
    with pytest.raises(MapFileError, match="not an integer"):
        load_npz_checked(bad, SCHEMA, VERSION)


def test_bit_flips_and_a_renamed_npy_give_map_file_errors(good, tmp_path):
    # a flipped bit used to escape as zlib.error, a renamed .npy as TypeError
    data = good.read_bytes()
    errors = 0
    for i in range(0, len(data), max(1, len(data) // 80)):
        flipped = bytearray(data)
        flipped[i] ^= 0xFF
        path = tmp_path / "flipped.npz"
        path.write_bytes(bytes(flipped))
        try:
            load_npz_checked(path, SCHEMA, VERSION)
        except MapFileError as e:
            assert "flipped.npz" in str(e)
            errors += 1
    assert errors > 10
    renamed = tmp_path / "array.npz"
    np.save(tmp_path / "array.npy", np.zeros(3))
    (tmp_path / "array.npy").rename(renamed)
    with pytest.raises(MapFileError, match="array.npz"):
        load_npz_checked(renamed, SCHEMA, VERSION)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("exposure_reference", np.array("0.5"), "exposure_reference"),
        ("exposure_reference", np.array(0.5 + 1j), "exposure_reference|complex"),
        ("counts", "negate-a-pair", "negative counts"),
    ],
)
def test_compass_entries_of_the_wrong_kind(room_compass, tmp_path, key, value, message):
    arrays = dict(room_compass.to_arrays())
    if value == "negate-a-pair":  # the sum per pair stays right: only the sign check sees it
        counts = arrays["counts"].astype(np.int64)
        s, p = np.argwhere(counts.sum(axis=2) > 0)[0]
        counts[s, p, 1] += counts[s, p, 0] + 1
        counts[s, p, 0] = -1
        value = counts
    arrays[key] = value
    path = tmp_path / "map.npz"
    entries = {f"{k}.npy": _npy(np.asarray(v)) for k, v in arrays.items()}
    with np.load(room_compass.save(tmp_path / "ref.npz")) as data:
        schema = {f"{k}.npy": _npy(data[k]) for k in ("schema", "schema_version")}
    _zip(path, {**schema, **entries})
    with pytest.raises(MapFileError, match=message):
        VisualCompass.load(path)


def test_a_deeply_nested_config_is_a_map_file_error(room_compass, tmp_path):
    # used to escape as RecursionError
    arrays = dict(room_compass.to_arrays())
    arrays["config"] = np.array("[" * 100_000 + "]" * 100_000)
    entries = {f"{k}.npy": _npy(np.asarray(v)) for k, v in arrays.items()}
    with np.load(room_compass.save(tmp_path / "ref.npz")) as data:
        schema = {f"{k}.npy": _npy(data[k]) for k in ("schema", "schema_version")}
    path = _zip(tmp_path / "deep.npz", {**schema, **entries})
    with pytest.raises(MapFileError, match="deep.npz.*nested too deeply"):
        VisualCompass.load(path)


@pytest.mark.parametrize(("umask", "expected"), [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_saved_files_get_the_permissions_of_the_umask(tmp_path, umask, expected):
    """A map used to be written 0600 whatever the umask (the temporary file's mode)."""
    import os
    import stat

    old = os.umask(umask)
    try:
        path = save_npz_atomic(tmp_path / "map.npz", SCHEMA, VERSION, {"a": np.arange(3.0)})
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == expected
