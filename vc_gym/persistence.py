"""Atomic, pickle-free ``.npz`` files with a schema version.

Every file holds a ``schema`` string, an integer ``schema_version`` and numeric or
unicode arrays only. Loading never unpickles (``allow_pickle=False``); a file that is
missing, truncated, of another schema or version raises :class:`MapFileError`
naming the file and the reason.
"""

from __future__ import annotations

import json
import os
import struct
import tempfile
import zipfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import BinaryIO

import numpy as np

from vc_gym.errors import MapFileError

__all__ = [
    "MAX_ARRAY_BYTES",
    "MAX_ENTRY_BYTES",
    "MAX_MEMBERS",
    "MAX_TOTAL_BYTES",
    "NPY_HEADER_BYTES",
    "json_array",
    "load_npz_checked",
    "read_json_array",
    "save_npz_atomic",
    "write_atomic",
    "zip_directory_problem",
    "zip_entries_problem",
]


def _umask_mode() -> int:
    """``0o666`` minus the process umask: what ``open()`` would have given the file."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_atomic(
    path: str | os.PathLike, write: Callable[[str], object], mode: int | None = None
) -> Path:
    """Create ``path`` whole or not at all: ``write(tmp)`` fills a temporary file in the
    same folder, which is then renamed over ``path``.

    A crash or an exception inside ``write`` leaves any previous file at ``path``
    untouched and no temporary file behind. The file gets permissions ``mode``, by
    default those a plain ``open()`` would give under the process umask (``mkstemp``
    alone would make every map, model and result private).

    Parameters
    ----------
    path : path-like
        The file to create or replace; its folder must exist.
    write : callable
        ``write(tmp_path)`` writes the content to ``tmp_path`` (a str).
    mode : int, optional
        Permission bits of the result (default: ``0o666`` minus the umask).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=folder)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, _umask_mode() if mode is None else mode)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path


def json_array(obj: object) -> np.ndarray:
    """Encode a JSON-serialisable object as a 0-d unicode array (no pickling needed)."""
    return np.array(json.dumps(obj, sort_keys=True))


def read_json_array(arrays: Mapping[str, np.ndarray], key: str, path: str | os.PathLike) -> object:
    """Decode an array written by :func:`json_array`, with a clear error on failure."""
    if key not in arrays:
        raise MapFileError(f"{path}: missing entry {key!r}")
    a = arrays[key]
    if a.dtype.kind != "U" or a.ndim != 0:
        raise MapFileError(f"{path}: entry {key!r} is not a JSON string")
    try:
        return json.loads(str(a))
    except json.JSONDecodeError as e:
        raise MapFileError(f"{path}: entry {key!r} is not valid JSON ({e})") from None
    except RecursionError:
        raise MapFileError(f"{path}: entry {key!r} is nested too deeply") from None


def _not_a_file(path: Path) -> str:
    """Why ``path``, which is not a regular file, cannot be read as one."""
    if path.is_dir():
        return "a folder, not a file"
    return "not a regular file" if path.exists() else "no such file"


def save_npz_atomic(
    path: str | os.PathLike, schema: str, version: int, arrays: Mapping[str, np.ndarray]
) -> Path:
    """Write ``arrays`` to ``path`` atomically (temporary file in the same folder + rename).

    A crash while writing leaves any previous file at ``path`` untouched.

    Returns
    -------
    pathlib.Path
        The path written (``.npz`` is appended if missing, like ``numpy.savez``).
    """
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    reserved = {"schema", "schema_version"} & set(arrays)
    if reserved:
        raise ValueError(f"array names {sorted(reserved)} are reserved")
    for k, a in arrays.items():
        a = np.asarray(a)
        if a.dtype.kind not in "biufU":
            raise ValueError(f"array {k!r} has dtype {a.dtype}; only numeric/unicode are saved")
    folder = path.parent if str(path.parent) else Path(".")
    folder.mkdir(parents=True, exist_ok=True)

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(
                fh,
                schema=np.array(schema),
                schema_version=np.array(version, dtype=np.int64),
                **{k: np.asarray(v) for k, v in arrays.items()},
            )
            fh.flush()
            os.fsync(fh.fileno())

    return write_atomic(path, write)


#: Largest array data one entry of a checked ``.npz`` may hold, uncompressed: 64 MiB,
#: the counts of the largest compass map (:data:`vc_gym.compass.config.MAX_MAP_ENTRIES`
#: is derived from it, so every map the compass saves can be read back).
MAX_ARRAY_BYTES = 64 * 2**20
#: Room for an entry's ``.npy`` header on top of its array data (format 1.0 pads the
#: header to a multiple of 64 bytes; a vc_gym array's header takes 128).
NPY_HEADER_BYTES = 4096
#: Largest entry (header and array data), uncompressed.
MAX_ENTRY_BYTES = MAX_ARRAY_BYTES + NPY_HEADER_BYTES
#: Largest sum of its entries, uncompressed.
MAX_TOTAL_BYTES = 256 * 2**20
#: Most entries a checked ``.npz`` may hold. Each costs a directory record and a read
#: (about 0.1 ms even when tiny), so a file of millions of entries, which the byte
#: limits allow, would take minutes to refuse. The largest vc_gym file is an atlas of
#: :data:`vc_gym.compass.atlas.MAX_SPOTS` (1024) spots that each keep their own colour
#: classes: 14 entries a spot and 5 of its own, 14,341 in all; a compass map holds at
#: most 16 entries, a baseline sensor file fewer than 10.
MAX_MEMBERS = 2**14
#: Bytes of zip directory allowed per entry, to bound the time spent parsing the
#: directory before its entries are counted: a record is 46 bytes, the entry's name
#: (under 40 characters in vc_gym files) and at most a 28-byte zip64 extra field.
_DIRECTORY_BYTES_PER_MEMBER = 256
#: Array kinds a vc_gym file holds: bool, integers, reals and text.
_KINDS = "biufU"


def load_npz_checked(
    path: str | os.PathLike,
    schema: str,
    version: int,
    max_entry_bytes: int = MAX_ENTRY_BYTES,
    max_total_bytes: int = MAX_TOTAL_BYTES,
    max_members: int = MAX_MEMBERS,
    legacy_schemas: Sequence[str] = (),
) -> dict[str, np.ndarray]:
    """Load every array of an ``.npz`` written by :func:`save_npz_atomic`, safely.

    Nothing is decompressed before it is checked: the zip may hold at most
    ``max_members`` entries (counted from its end record before the directory is
    parsed, and again after), and every entry must be a ``.npy`` array whose sizes
    (the zip's and the one its header declares) agree and stay within
    ``max_entry_bytes`` (all entries together within ``max_total_bytes``), of a plain
    kind (bool, integer, real, text: never objects, so nothing is unpickled) and
    named once. A hostile file therefore cannot run code, exhaust memory or take long
    to refuse. A file whose schema is one of ``legacy_schemas`` (another spelling of
    ``schema``) is read as a ``schema`` file.

    Raises
    ------
    MapFileError
        If the file is missing, empty, truncated, corrupt or not a zip, holds too many
        entries, an entry that is not a plain array or is too large, has no or another
        schema, or a schema version that is not this integer.
    """
    path = Path(path)
    if not path.is_file():
        raise MapFileError(f"{path}: {_not_a_file(path)}")
    if path.stat().st_size == 0:
        raise MapFileError(f"{path}: file is empty")
    try:
        arrays = _read_entries(path, max_entry_bytes, max_total_bytes, max_members)
    except MapFileError:
        raise
    except Exception as e:  # noqa: BLE001 - a hostile file finds every kind: zlib.error,
        # BadZipFile, NotImplementedError (zip version), TokenError (npy header), ...
        raise MapFileError(f"{path}: not a readable .npz file ({type(e).__name__}: {e})") from None
    if "schema" not in arrays or "schema_version" not in arrays:
        raise MapFileError(f"{path}: not a vc_gym file (no schema / schema_version entry)")
    got = arrays.pop("schema")
    if got.dtype.kind != "U" or got.ndim != 0:
        raise MapFileError(f"{path}: schema is not a text entry")
    if str(got) != schema and str(got) not in legacy_schemas:
        raise MapFileError(f"{path}: holds a {str(got)!r}, expected a {schema!r}")
    got_version = arrays.pop("schema_version")
    if got_version.dtype.kind not in "iu" or got_version.ndim != 0:
        # "1" or 1.9 is not version 1
        raise MapFileError(f"{path}: schema_version is not an integer")
    if int(got_version) != version:
        raise MapFileError(
            f"{path}: schema version {int(got_version)}, this vc_gym reads version {version}"
        )
    return arrays


def zip_entries_problem(
    infos: Sequence[zipfile.ZipInfo],
    max_entry: int,
    max_total: int,
    max_members: int | None = None,
) -> str | None:
    """What makes a zip unsafe to open, judged from its directory alone (nothing is
    decompressed): more than ``max_members`` entries (when given), a repeated entry
    name (a second entry hiding behind the first), an entry larger than ``max_entry``
    bytes or more than ``max_total`` in all. ``None`` if there is nothing; maps
    (:func:`load_npz_checked`) and models (:mod:`vc_gym.training.safe_load`) are both
    checked with it."""
    if max_members is not None and len(infos) > max_members:
        return f"it holds {len(infos)} entries, more than {max_members}"
    seen: set[str] = set()
    for info in infos:
        if info.filename in seen:
            return f"entry {info.filename!r} is repeated (it appears twice)"
        seen.add(info.filename)
        if info.file_size > max_entry:
            return f"entry {info.filename!r} is larger than {max_entry} bytes"
    total = sum(i.file_size for i in infos)
    if total > max_total:
        return f"its entries hold {total} bytes, more than {max_total}"
    return None


#: The zip end records :func:`zip_directory_problem` reads the entry count and the
#: directory size from.
_EOCD = struct.Struct("<4s4H2LH")  # end of central directory, 22 bytes
_EOCD64_LOCATOR = struct.Struct("<4sLQL")  # zip64 end record locator, 20 bytes
_EOCD64 = struct.Struct("<4sQ2H2L4Q")  # zip64 end of central directory, 56 bytes
#: Longest zip comment: the end record lies within this many bytes of the file's end.
_MAX_ZIP_COMMENT = 65535


def zip_directory_problem(fh: BinaryIO, max_members: int) -> str | None:
    """What the end record of the zip open as ``fh`` says that makes it unsafe to
    parse: more than ``max_members`` entries, or a directory larger than
    ``max_members`` records of a few hundred bytes (which a lying entry count would
    hide). Only the last 64 KiB of the file are read. ``None`` if there is nothing or
    no end record is found (:class:`zipfile.ZipFile` then reports the damage)."""
    fh.seek(0, os.SEEK_END)
    size = fh.tell()
    start = max(0, size - _EOCD.size - _MAX_ZIP_COMMENT)
    fh.seek(start)
    tail = fh.read()
    pos = tail.rfind(b"PK\x05\x06")
    if pos < 0 or len(tail) - pos < _EOCD.size:
        return None
    _, _, _, _, members, directory, _, _ = _EOCD.unpack_from(tail, pos)
    if members == 0xFFFF or directory == 0xFFFFFFFF:
        # zip64: the real figures are in the record just before its locator
        at = start + pos - _EOCD64_LOCATOR.size - _EOCD64.size
        if at >= 0:
            fh.seek(at)
            record = fh.read(_EOCD64.size + _EOCD64_LOCATOR.size)
            if record[_EOCD64.size :].startswith(b"PK\x06\x07") and record.startswith(
                b"PK\x06\x06"
            ):
                fields = _EOCD64.unpack_from(record)
                members, directory = fields[7], fields[8]
    if members > max_members:
        return f"it holds {members} entries, more than {max_members}"
    if directory > max_members * _DIRECTORY_BYTES_PER_MEMBER:
        return (
            f"its directory takes {directory} bytes, more than {max_members} entries need "
            f"({_DIRECTORY_BYTES_PER_MEMBER} bytes each)"
        )
    return None


def _read_entries(
    path: Path, max_entry: int, max_total: int, max_members: int
) -> dict[str, np.ndarray]:
    """The arrays of the zip at ``path``, each checked before it is decompressed."""
    arrays: dict[str, np.ndarray] = {}
    with open(path, "rb") as fh:
        problem = zip_directory_problem(fh, max_members)
    if problem is not None:
        raise MapFileError(f"{path}: {problem}")
    with zipfile.ZipFile(path) as zf:
        infos = zf.infolist()
        problem = zip_entries_problem(infos, max_entry, max_total, max_members)
        if problem is not None:
            raise MapFileError(f"{path}: {problem}")
        for info in infos:
            name = info.filename
            if not name.endswith(".npy"):
                raise MapFileError(f"{path}: unexpected entry {name!r}")
            with zf.open(info) as fh:
                major, minor = np.lib.format.read_magic(fh)
                read_header = (
                    np.lib.format.read_array_header_1_0
                    if (major, minor) == (1, 0)
                    else np.lib.format.read_array_header_2_0
                )
                shape, fortran, dtype = read_header(fh)
                if dtype.kind not in _KINDS or dtype.hasobject:
                    raise MapFileError(f"{path}: entry {name!r} has dtype {dtype}, not plain data")
                nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
                if nbytes != info.file_size - fh.tell():
                    raise MapFileError(
                        f"{path}: entry {name!r} declares shape {shape} ({nbytes} bytes) but "
                        f"holds {info.file_size - fh.tell()} bytes"
                    )
            with zf.open(info) as fh:
                arrays[name[:-4]] = np.lib.format.read_array(fh, allow_pickle=False)
    return arrays
