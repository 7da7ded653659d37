"""Yaws of your own footage: read from a CSV, or assumed from a constant turn.

Yaws
----
Degrees, counter-clockwise positive seen from above (turning left increases the yaw;
:mod:`vc_gym.angles`), relative to whatever direction you call 0. Either from a CSV
(:func:`read_yaw_csv`) or assumed: the camera turned at a constant rate through
``turn_deg`` over the whole input, the first frame at 0 (:func:`footage_yaws`).
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vc_gym.compass.footage.frames import Footage
from vc_gym.validation import MAX_ABS_DEG, finite_real

__all__ = ["MAX_YAW_CSV_BYTES", "YawTable", "footage_yaws", "read_yaw_csv"]

#: Largest yaw CSV read (bytes): millions of rows.
MAX_YAW_CSV_BYTES = 64 * 2**20
#: Header names of a yaw CSV's file-name column (compared in lower case).
_NAME_COLUMNS = ("image", "file", "filename", "file_name", "name", "path")


# ----------------------------------------------------------------------------- yaws
@dataclass(frozen=True)
class YawTable:
    """Yaws read from a CSV by :func:`read_yaw_csv`.

    Attributes
    ----------
    yaws_deg : numpy.ndarray
        ``(N,)`` finite yaws in degrees, one per row, in file order.
    names : tuple of str or None
        The file name of each row's frame, when the CSV has a file-name column.
    column : str
        The column the yaws were read from (its header name, or ``#index``).
    source : pathlib.Path
        The CSV file.
    """

    yaws_deg: np.ndarray
    names: tuple[str, ...] | None
    column: str
    source: Path

    def __len__(self) -> int:
        return int(self.yaws_deg.size)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_yaw_csv(path: str | os.PathLike, column: str | int | None = None) -> YawTable:
    """Read yaws (degrees, counter-clockwise positive) from a CSV file.

    The format: comma-separated, one row per frame of the input in frame order; blank
    lines and lines starting with ``#`` are skipped. A **header** is optional: the
    first row is one when none of its cells is a number. The yaw **column** is
    ``column`` (a header name, or a 0-based index), else the first column whose header
    contains ``yaw`` (any case), else, without a header, the only column or the only one
    holding numbers. With a header, a column named ``image``, ``file``, ``filename``,
    ``file_name``, ``name`` or ``path`` gives each row's frame file name: frames of a
    folder are then matched to rows by name, in any order. So the ground truth of the
    real rotation sets (``image,yaw_left_deg_autostitch,...``) is read as it is.

    Raises
    ------
    FileNotFoundError
        If there is no such file (a folder or a device there is a ``ValueError``).
    ValueError
        Naming the file and line: larger than :data:`MAX_YAW_CSV_BYTES`, not UTF-8, no
        rows, rows of different lengths, an unknown or ambiguous column, a yaw that is
        not a finite number (``nan``, empty, text) or beyond
        :data:`~vc_gym.validation.MAX_ABS_DEG`, a file name listed twice.
    """
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{path}: a folder, not a CSV file")
    if not path.is_file():
        if path.exists():
            raise ValueError(f"{path}: not a regular file")
        raise FileNotFoundError(f"{path}: no such file")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_YAW_CSV_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    if len(data) > MAX_YAW_CSV_BYTES:
        raise ValueError(f"{path}: larger than {MAX_YAW_CSV_BYTES} bytes")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a UTF-8 text file") from None
    try:
        rows = [
            (line_no, [cell.strip() for cell in row])
            for line_no, row in enumerate(csv.reader(io.StringIO(text)), start=1)
            if row and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")
        ]
    except csv.Error as exc:
        raise ValueError(f"{path}: not a readable CSV file ({exc})") from None
    if not rows:
        raise ValueError(f"{path}: holds no rows")
    header = None if any(_is_number(c) for c in rows[0][1]) else rows[0][1]
    body = rows[1:] if header is not None else rows
    if not body:
        raise ValueError(f"{path}: holds a header but no rows")
    n_cols = len(rows[0][1])
    for line_no, row in rows:
        if len(row) != n_cols:
            raise ValueError(f"{path} line {line_no}: {len(row)} cells, the first row has {n_cols}")
    col = _yaw_column(path, header, body, column, n_cols)
    yaws = np.empty(len(body))
    for k, (line_no, row) in enumerate(body):
        cell = row[col]
        try:
            value = float(cell)
        except ValueError:
            raise ValueError(f"{path} line {line_no}: yaw {cell!r} is not a number") from None
        if not math.isfinite(value) or abs(value) > MAX_ABS_DEG:
            raise ValueError(
                f"{path} line {line_no}: yaw {cell!r} must be a finite number of degrees "
                f"(|yaw| <= {MAX_ABS_DEG:g})"
            )
        yaws[k] = value
    names = None
    if header is not None:
        lowered = [h.lower() for h in header]
        name_col = next((lowered.index(n) for n in _NAME_COLUMNS if n in lowered), None)
        if name_col is not None and name_col != col:
            names = tuple(Path(row[name_col]).name for _, row in body)
            seen: dict[str, int] = {}
            for (line_no, _), name in zip(body, names, strict=True):
                if name in seen:
                    raise ValueError(
                        f"{path} line {line_no}: {name!r} is listed twice (also line {seen[name]})"
                    )
                seen[name] = line_no
    label = header[col] if header is not None else f"#{col}"
    return YawTable(yaws, names, label, path)


def _yaw_column(
    path: Path,
    header: list[str] | None,
    body: list[tuple[int, list[str]]],
    column: str | int | None,
    n_cols: int,
) -> int:
    """Index of the yaw column (see :func:`read_yaw_csv`)."""
    shown = ", ".join(header) if header is not None else f"{n_cols} columns without a header"
    if column is not None:
        text = str(column).strip()
        if text.isdigit():
            index = int(text)
            if index >= n_cols:
                raise ValueError(f"{path}: no column {index} (0-based; it has {shown})")
            return index
        if header is None:
            raise ValueError(f"{path}: has no header, so no column {text!r}: give a 0-based index")
        if text in header:
            return header.index(text)
        lowered = [h.lower() for h in header]
        if text.lower() in lowered:
            return lowered.index(text.lower())
        raise ValueError(f"{path}: no column {text!r} (columns: {shown})")
    if header is not None:
        for i, h in enumerate(header):
            if "yaw" in h.lower():
                return i
    if n_cols == 1:
        return 0
    numeric = [i for i in range(n_cols) if all(_is_number(row[i]) for _, row in body)]
    if header is None and len(numeric) == 1:
        return numeric[0]
    raise ValueError(
        f"{path}: which column holds the yaw? none is named '...yaw...'; pass the "
        f"column's name or 0-based index (columns: {shown})"
    )


def footage_yaws(
    footage: Footage, table: YawTable | None = None, turn_deg: float = 360.0
) -> np.ndarray:
    """Yaw (degrees) of each frame :attr:`Footage.indices` selects.

    With ``table``: a folder's frames are matched to rows by file name when the CSV has
    a file-name column (it must list every image of the folder); otherwise the CSV
    must have exactly one row per frame of the input, in order. Without ``table``, the
    camera is taken to have turned at a constant rate through ``turn_deg`` (positive:
    to the left) over the whole input: frame ``k`` of ``N`` is at ``turn_deg * k / N``
    (the frame after the last would look where the first did).

    Raises
    ------
    ValueError
        If the rows do not match the frames, or ``turn_deg`` is 0 or not finite.
    """
    idx = footage.indices
    if table is None:
        turn = finite_real("turn_deg", turn_deg)
        if turn == 0 or abs(turn) > MAX_ABS_DEG:
            raise ValueError(
                f"turn_deg must be non-zero and at most {MAX_ABS_DEG:g}, got {turn_deg!r}"
            )
        return turn * idx / footage.n_source
    if table.names is not None and footage.names is not None:
        rows = {name: k for k, name in enumerate(table.names)}
        missing = [n for n in footage.names if n not in rows]
        extra = sorted(set(rows) - set(footage.names))
        if missing or extra:
            parts = []
            if missing:
                parts.append(f"no row for {len(missing)} image(s) ({', '.join(missing[:3])})")
            if extra:
                parts.append(
                    f"{len(extra)} row(s) for no image in the folder ({', '.join(extra[:3])})"
                )
            raise ValueError(f"{table.source}: {'; '.join(parts)} of {footage.path}")
        return np.array([table.yaws_deg[rows[footage.names[i]]] for i in idx.tolist()])
    if len(table) != footage.n_source:
        raise ValueError(
            f"{table.source}: {len(table)} rows, but {footage.path} has {footage.n_source} "
            "frames; give one row per frame of the input"
        )
    return table.yaws_deg[idx].copy()
