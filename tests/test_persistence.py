"""Hostile and broken .npz files: every one a MapFileError naming the file, fast, small."""

from __future__ import annotations

import io
import struct
import zipfile
import zlib

import numpy as np
import pytest

from vc_gym import persistence
from vc_gym.compass import VisualCompass
from vc_gym.errors import MapFileError
from vc_gym.persistence import (
    MAX_ENTRY_BYTES,
    MAX_MEMBERS,
    NPY_HEADER_BYTES,
    load_npz_checked,
    save_npz_atomic,
)

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


def test_another_spelling_of_the_schema_reads_as_the_schema(good):
    arrays = load_npz_checked(good, "vc_gym.Other", VERSION, legacy_schemas=(SCHEMA,))
    np.testing.assert_array_equal(arrays["a"], np.arange(6.0))
    with pytest.raises(MapFileError, match="expected a 'vc_gym.Other'"):
        load_npz_checked(good, "vc_gym.Other", VERSION, legacy_schemas=("vc_gym.Else",))


def test_a_huge_zero_entry_is_refused_before_it_is_decompressed(tmp_path):
    # 1 GiB of zeros compresses to ~1 MB; decompressing it would peak at 1.6 GB
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
    # a MapFileError, not a MemoryError
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
    # no flipped bit escapes as zlib.error, no renamed .npy as TypeError
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
    # a MapFileError, not a RecursionError
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
    """A map gets the permissions of the umask, not the temporary file's 0600."""
    import os
    import stat

    old = os.umask(umask)
    try:
        path = save_npz_atomic(tmp_path / "map.npz", SCHEMA, VERSION, {"a": np.arange(3.0)})
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == expected


# ------------------------------------------------------------------ how many entries
def _stored_zip(path, n: int, data: bytes, declared: int | None = None):
    """A zip of ``n`` stored entries holding ``data`` each, written directly (zipfile
    takes seconds for 10^5 entries); its end record declares ``declared`` entries
    (default ``n``), with zip64 end records when that does not fit in 16 bits."""
    crc = zlib.crc32(data)
    local, central, offset = [], [], 0
    for i in range(n):
        name = f"e{i:06d}.npy".encode()
        head = struct.pack(
            "<4s5H3L2H", b"PK\x03\x04", 20, 0, 0, 0, 0, crc, len(data), len(data), len(name), 0
        )
        local.append(head + name + data)
        central.append(
            struct.pack(
                "<4s6H3L5H2L",
                b"PK\x01\x02",
                20,
                20,
                0,
                0,
                0,
                0,
                crc,
                len(data),
                len(data),
                len(name),
                0,
                0,
                0,
                0,
                0,
                offset,
            )
            + name
        )
        offset += len(head) + len(name) + len(data)
    directory = b"".join(central)
    count = n if declared is None else declared
    tail = b""
    if count >= 0xFFFF:
        end64 = offset + len(directory)
        tail += struct.pack(
            "<4sQ2H2L4Q", b"PK\x06\x06", 44, 45, 45, 0, 0, count, count, len(directory), offset
        )
        tail += struct.pack("<4sLQL", b"PK\x06\x07", 0, end64, 1)
        count = 0xFFFF
    tail += struct.pack("<4s4H2LH", b"PK\x05\x06", 0, 0, count, count, len(directory), offset, 0)
    path.write_bytes(b"".join(local) + directory + tail)
    return path


def test_the_entry_writer_makes_readable_zips(tmp_path):
    path = _stored_zip(tmp_path / "three.npz", 3, _npy(np.zeros(2)))
    with zipfile.ZipFile(path) as zf:
        assert [zf.read(i) for i in zf.infolist()] == [_npy(np.zeros(2))] * 3


@pytest.fixture
def directory_never_parsed(monkeypatch):
    """Fails the test if the zip's central directory is parsed (``zipfile.ZipFile``):
    a refusal from the end record alone costs nothing, whatever the file holds."""

    def parse(*args, **kwargs):
        raise AssertionError("the zip directory was parsed")

    monkeypatch.setattr(persistence.zipfile, "ZipFile", parse)


def test_a_file_of_a_hundred_thousand_entries_is_refused_at_once(
    tmp_path, directory_never_parsed
):
    # 10^5 valid tiny arrays, within every byte limit: reading each would take seconds
    path = _stored_zip(tmp_path / "many.npz", 10**5, _npy(np.zeros(1)))
    message = f"many.npz: it holds 100000 entries, more than {MAX_MEMBERS}"
    with pytest.raises(MapFileError, match=message):
        load_npz_checked(path, SCHEMA, VERSION)


def test_a_directory_larger_than_its_declared_count_is_refused(tmp_path, directory_never_parsed):
    # the end record says 3 entries; parsing the 10^5 records would cost the time
    path = _stored_zip(tmp_path / "liar.npz", 10**5, _npy(np.zeros(1)), declared=3)
    with pytest.raises(MapFileError, match="liar.npz: its directory takes"):
        load_npz_checked(path, SCHEMA, VERSION)


def test_more_entries_than_declared_are_counted_after_parsing(tmp_path):
    # a directory small enough to parse quickly, holding more entries than it declares
    n = MAX_MEMBERS + 100
    path = _stored_zip(tmp_path / "liar.npz", n, b"", declared=3)
    with pytest.raises(MapFileError, match=f"liar.npz: it holds {n} entries"):
        load_npz_checked(path, SCHEMA, VERSION)


def test_a_file_within_the_entry_count_loads(tmp_path):
    arrays = {f"a{i}": np.full(2, i) for i in range(100)}
    path = save_npz_atomic(tmp_path / "hundred.npz", SCHEMA, VERSION, arrays)
    got = load_npz_checked(path, SCHEMA, VERSION, max_members=102)
    assert sorted(got) == sorted(arrays)
    with pytest.raises(MapFileError, match="102 entries, more than 101"):
        load_npz_checked(path, SCHEMA, VERSION, max_members=101)


def test_an_entry_of_the_largest_array_loads(tmp_path):
    # the largest map's counts: 2^24 uint32, 64 MiB of data plus the .npy header; the
    # entry limit leaves room for the header
    counts = np.zeros(2**24, dtype=np.uint32)
    counts[::4096] = 7
    path = save_npz_atomic(tmp_path / "big.npz", SCHEMA, VERSION, {"counts": counts})
    np.testing.assert_array_equal(load_npz_checked(path, SCHEMA, VERSION)["counts"], counts)
    assert MAX_ENTRY_BYTES - counts.nbytes == NPY_HEADER_BYTES
