"""Writing results atomically: a JSON file or a figure appears whole or not at all.

Figures are :class:`matplotlib.figure.Figure` objects made by :func:`new_figure`, never
through ``pyplot``: nothing here switches matplotlib's global backend or keeps figures
alive in pyplot's registry, so the package can plot inside a user's notebook session.

Every file is written by :func:`vc_gym.persistence.write_atomic`: its content goes to a
temporary file ``.{name}.{8 random characters}.tmp{suffix}`` in the same folder, which
is flushed to the disk (``fsync``) and then renamed over the result, and the folder is
synced too, so that a power cut leaves the old file or the new one, never an empty one.
:func:`check_out_file` and :func:`check_out_dir` make sure, before any work starts, that
those names fit the file system and the folder can be written, so that a result is never
computed only to be lost.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from vc_gym.persistence import write_atomic

__all__ = [
    "DEFAULT_NAME_MAX",
    "check_apart",
    "check_new_files",
    "DEFAULT_PATH_MAX",
    "MAX_JSON_BYTES",
    "OUT_DIR_NAME_RESERVE",
    "TEMP_NAME_EXTRA",
    "check_out_dir",
    "check_out_file",
    "new_figure",
    "new_out_dir",
    "removed_on_failure",
    "read_json",
    "save_figure",
    "write_json",
    "write_text",
]

#: Longest file name (bytes) assumed where the file system does not say
#: (``os.pathconf(folder, "PC_NAME_MAX")``).
DEFAULT_NAME_MAX = 255
#: Longest path (bytes) assumed where the file system does not say (``PC_PATH_MAX``).
DEFAULT_PATH_MAX = 4096
#: Bytes the atomic writer's temporary name adds to a file's name and suffix:
#: ``"."`` + name + ``"."`` + 8 random characters + ``".tmp"`` + suffix.
TEMP_NAME_EXTRA = 1 + 1 + 8 + len(".tmp")
#: Bytes of path kept free below an output folder for what a run writes inside it
#: (``jobs/<stage>/<key>.json`` and their temporary names).
OUT_DIR_NAME_RESERVE = 255
#: Largest JSON file :func:`read_json` reads (bytes): far above any result or job
#: file vc_gym writes.
MAX_JSON_BYTES = 64 * 2**20


def _limit(folder: Path, name: str, default: int) -> int:
    """``os.pathconf(folder, name)``, or ``default`` where the system does not say."""
    try:
        value = os.pathconf(folder, name)
    except (OSError, ValueError, AttributeError):
        return default
    return value if value and value > 0 else default


def _exists(path: Path) -> bool:
    """``path.exists()``, False where the path cannot even be looked up (a name too long)."""
    try:
        return path.exists()
    except OSError:
        return False


def _is_dir(path: Path) -> bool:
    """``path.is_dir()``, False where the path cannot even be looked up."""
    try:
        return path.is_dir()
    except OSError:
        return False


def _shown(path: Path) -> str:
    """``path`` for an error message, shortened in the middle when long."""
    text = str(path)
    return text if len(text) <= 100 else f"{text[:60]}...{text[-30:]}"


def _existing_ancestor(path: Path) -> Path:
    """The nearest folder at or above ``path`` that exists (what ``pathconf`` can ask)."""
    p = path.absolute()
    while not _exists(p) and p != p.parent:
        p = p.parent
    return p


def _check_name_fits(label: str, name: str, folder: Path, extra: int = 0) -> None:
    """Refuse ``name`` if it, plus ``extra`` bytes of temporary name, does not fit
    ``folder``'s name limit (``PC_NAME_MAX``)."""
    name_max = _limit(_existing_ancestor(folder), "PC_NAME_MAX", DEFAULT_NAME_MAX)
    size = len(os.fsencode(name))
    if size + extra <= name_max:
        return
    shown = name if len(name) <= 40 else name[:40] + "..."
    if extra:
        raise ValueError(
            f"{label}: the name {shown!r} is {size} bytes; with the {extra} bytes its "
            f"temporary file adds it must fit the file system's {name_max}-byte limit: "
            f"give a name of at most {name_max - extra} bytes"
        )
    raise ValueError(
        f"{label}: the folder name {shown!r} is {size} bytes, more than the file "
        f"system's {name_max}-byte limit"
    )


def _check_path_fits(label: str, folder: Path, reserve: int) -> None:
    """Refuse ``folder`` if its absolute path plus ``reserve`` bytes exceeds the path
    limit (``PC_PATH_MAX``; ``label`` starts the error message)."""
    path_max = _limit(_existing_ancestor(folder), "PC_PATH_MAX", DEFAULT_PATH_MAX)
    size = len(os.fsencode(str(folder.absolute())))
    if size + reserve > path_max:
        raise ValueError(
            f"{label}: the path is {size} bytes; with {reserve} bytes for what is "
            f"written there it must fit the file system's {path_max}-byte limit"
        )


def _prepare_dir(label: str, folder: Path, reserve: int) -> None:
    """Check every name of ``folder`` and its length with ``reserve`` bytes to spare,
    create it and write and remove a file in it (``label`` starts the error messages)."""
    for part in folder.parts:
        if part not in (folder.anchor, ".", ".."):
            _check_name_fits(label, part, folder)
    _check_path_fits(label, folder, reserve)
    if _exists(folder) and not _is_dir(folder):
        raise ValueError(f"{label}: {_shown(folder)} exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ValueError(f"{label}: cannot write there ({exc.strerror or exc})") from None


def check_out_dir(path: str | os.PathLike, flag: str = "--out") -> Path:
    """Make sure ``path`` is (or can become) a writable folder, before any work starts.

    The folder is created (with its parents) and a file is written and removed in it;
    folders it created are removed again when it refuses the path.
    Every part of the path must fit the file system's name limit (``PC_NAME_MAX``), and
    the whole path must leave :data:`OUT_DIR_NAME_RESERVE` bytes below the path limit
    (``PC_PATH_MAX``) for the files a run writes inside it.

    Parameters
    ----------
    path : path-like
        The folder.
    flag : str
        The option that named it, starting the error messages.

    Raises
    ------
    ValueError
        ``--out PATH: ...`` for an existing file, a name or path too long for the file
        system, or a place that cannot be written.
    """
    if os.fspath(path) == "":
        raise ValueError(f"{flag}: give a folder name")
    out = Path(path)
    made = _created_dirs(out)
    try:
        _prepare_dir(f"{flag} {_shown(out)}", out, OUT_DIR_NAME_RESERVE)
    except ValueError:
        _remove_empty(made)  # a refused folder leaves nothing behind
        raise
    return out


def _created_dirs(path: Path) -> list[Path]:
    """The folders that creating ``path`` (with its parents) would make, deepest first."""
    made = []
    p = path.absolute()
    while not _exists(p) and p != p.parent:
        made.append(p)
        p = p.parent
    return made


@contextlib.contextmanager
def new_out_dir(path: str | os.PathLike) -> Iterator[Path]:
    """:func:`check_out_dir` for a run: if the run fails (or is interrupted) before it
    writes anything, the folders this call created are removed again (a refused
    argument leaves nothing)."""
    with removed_on_failure(path):
        yield check_out_dir(path)


@contextlib.contextmanager
def removed_on_failure(*folders: str | os.PathLike) -> Iterator[None]:
    """Remove again, while empty, the ``folders`` (and their parents) that do not exist
    when the block starts, if the block fails or is interrupted (Ctrl-C, SIGTERM)."""
    made = {d for folder in folders for d in _created_dirs(Path(folder))}
    deepest_first = sorted(made, key=lambda d: len(d.parts), reverse=True)
    try:
        yield
    except BaseException:
        _remove_empty(deepest_first, stop_at_first=False)
        raise


def check_out_file(path: str | os.PathLike, flag: str = "--out") -> Path:
    """Make sure a result file can be written at ``path``, before any work starts (its
    folder is created; an existing file there will be replaced).

    The file's name and the atomic writer's temporary name for it
    (``.{name}.{8 characters}.tmp{suffix}``) must both fit the file system's name limit
    (``PC_NAME_MAX``, :data:`DEFAULT_NAME_MAX` where unknown), and such a temporary file
    is created and removed in the folder as a test.

    Parameters
    ----------
    path : path-like
        The file.
    flag : str
        The option that named it, starting the error messages (e.g. ``"--plot"``).

    Raises
    ------
    ValueError
        ``--out PATH: ...`` for a folder, a name too long for the file system, or a
        place that cannot be written.
    """
    if os.fspath(path) == "":
        raise ValueError(f"{flag}: give a file name (e.g. result.json)")
    out = Path(path)
    label = f"{flag} {_shown(out)}"
    folder = out.parent if str(out.parent) else Path(".")
    extra = TEMP_NAME_EXTRA + len(os.fsencode(out.suffix))
    _check_name_fits(label, out.name, folder, extra)
    if _is_dir(out):
        raise ValueError(f"{label}: is a folder; give a file name")
    made = _created_dirs(folder)
    try:
        _prepare_dir(label, folder, len(os.fsencode(out.name)) + extra + 1)
        try:
            # exactly the temporary name write_atomic will use (same prefix and suffix)
            fd, probe = tempfile.mkstemp(
                prefix=f".{out.name}.", suffix=".tmp" + out.suffix, dir=folder
            )
            os.close(fd)
            os.unlink(probe)
        except OSError as exc:
            raise ValueError(f"{label}: cannot write there ({exc.strerror or exc})") from None
    except ValueError:
        _remove_empty(made)
        raise
    return out


def _same_place(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name the same file or folder: the same inode where both
    exist (hard links, bind mounts), else the same path once symbolic links, ``..`` and
    the working folder are resolved."""
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        pass
    return os.path.realpath(a) == os.path.realpath(b)


def check_apart(
    outputs: Iterable[tuple[str, str | os.PathLike]],
    inputs: Iterable[tuple[str, str | os.PathLike | None]],
    reads: Callable[[Path], bool] | None = None,
) -> None:
    """Refuse, before any work, an output that would replace or change an input.

    Parameters
    ----------
    outputs : iterable of (flag, path)
        Every file (and output folder) the command writes, with the option that named
        it (``("--out", "track/headings.csv")``).
    inputs : iterable of (flag, path or None)
        Every file or folder it reads (``None``: not given).
    reads : callable, optional
        ``reads(path)``: whether a file of that name inside an input *folder* would be
        read as part of it (a footage folder reads its images). Such an output is
        refused too: the next run on that folder would take it for input.

    Raises
    ------
    ValueError
        One line naming both options, e.g. ``--video v.mp4 is INPUT v.mp4: ...``.
    """
    given = [(flag, Path(p)) for flag, p in inputs if p is not None and os.fspath(p) != ""]
    for out_flag, out in ((f, Path(p)) for f, p in outputs):
        for in_flag, inp in given:
            if _same_place(out, inp):
                raise ValueError(
                    f"{out_flag} {_shown(out)} is {in_flag} {_shown(inp)}: an output never "
                    "replaces an input; write it elsewhere"
                )
            if reads is not None and _is_dir(inp) and _same_place(out.parent, inp) and reads(out):
                raise ValueError(
                    f"{out_flag} {_shown(out)} is inside {in_flag} {_shown(inp)}, which would "
                    "then read it as input; write it elsewhere"
                )


def check_new_files(
    files: Iterable[tuple[str, str | os.PathLike]], overwrite: bool = False
) -> None:
    """Refuse, before any work, to replace a file that exists (``overwrite`` allows it
    for regular files; a folder, a device or a pipe at that name is always refused).

    Parameters
    ----------
    files : iterable of (flag, path)
        The files a command will write, with the option that named each.
    overwrite : bool
        The user's ``--overwrite``.

    Raises
    ------
    ValueError
        Naming the option and the file, and how to go on.
    """
    for flag, path in ((f, Path(p)) for f, p in files):
        if not (path.exists() or path.is_symlink()):
            continue
        if not path.is_file():
            kind = "a folder" if path.is_dir() else "not a regular file"
            raise ValueError(f"{flag} {_shown(path)} is {kind}; give a file name")
        if not overwrite:
            raise ValueError(
                f"{flag}: {_shown(path)} exists; write elsewhere, or give --overwrite to replace it"
            )


def _remove_empty(made: list[Path], stop_at_first: bool = True) -> None:
    """Remove the folders in ``made`` (deepest first) while they are empty (all that
    are empty, with ``stop_at_first=False``: ``made`` then spans several branches)."""
    for folder in made:
        try:
            folder.rmdir()
        except OSError:
            if stop_at_first:
                break


def _fsync_dir(folder: Path) -> None:
    """Sync ``folder`` (a rename in it is durable only then); skipped where folders
    cannot be opened (Windows)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write_synced(tmp: str, data: bytes) -> None:
    """Write ``data`` to ``tmp`` and flush it to the disk before it is renamed."""
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())


def _sync_file(tmp: str) -> None:
    """Flush a file another writer has closed to the disk."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_json(path: str | os.PathLike, obj: object) -> None:
    """Write ``obj`` as indented JSON to ``path`` atomically and durably (its folder is
    created; the temporary file is synced before the rename, the folder after it)."""
    write_text(path, json.dumps(obj, indent=2))


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically and durably, as :func:`write_json`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = text.encode("utf-8")
    write_atomic(path, lambda tmp: _write_synced(tmp, data))
    _fsync_dir(path.parent if str(path.parent) else Path("."))


def read_json(path: str | os.PathLike, max_bytes: int = MAX_JSON_BYTES) -> Any:
    """Read a JSON file of at most ``max_bytes`` bytes.

    Only a regular file is opened (a FIFO or a device named like a result would block
    or never end), and no more than ``max_bytes + 1`` bytes are read, so a file that
    grows while it is read cannot exhaust memory.

    Raises
    ------
    ValueError
        Naming the file: not a regular file, unreadable, larger than ``max_bytes``,
        not UTF-8, not valid JSON or nested too deeply.
    """
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{p}: not a regular file")
    try:
        with open(p, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise ValueError(f"{p}: cannot read it ({exc.strerror or exc})") from None
    if len(data) > max_bytes:
        raise ValueError(f"{p}: larger than {max_bytes} bytes")
    try:
        return json.loads(data.decode("utf-8"))
    except RecursionError:
        raise ValueError(f"{p}: nested too deeply") from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{p}: not valid JSON ({exc})") from None


def new_figure(**kwargs: Any) -> Figure:
    """A figure not registered with pyplot (``kwargs`` go to ``Figure``)."""
    return Figure(**kwargs)


def save_figure(fig: Figure, path: str | os.PathLike, dpi: int = 100) -> None:
    """Save a figure as PNG to ``path`` atomically and durably (its folder is created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)

    def write(tmp: str) -> None:
        fig.savefig(tmp, dpi=dpi, format="png")
        _sync_file(tmp)

    write_atomic(path, write)
    _fsync_dir(path.parent if str(path.parent) else Path("."))
