"""Loading the real photo sets that live beside the project (never inside it).

The sets are looked up in ``$VC_GYM_REAL_DATA``, then ``../shared/data/real`` relative
to the current directory and to the project checkout. Callers skip cleanly when no
folder is found.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

__all__ = ["RotationPhoto", "default_real_data_dir", "load_rotation_set", "ROTATION_SETS"]

#: Rotation sets (folder name -> description) used by the real-photo experiment.
ROTATION_SETS = {
    "rotation_grail": "indoor lab, 18 photos, full turn",
    "rotation_parrington": "outdoor lawn, 18 photos, full turn",
}


@dataclass(frozen=True)
class RotationPhoto:
    """One photo of a camera turning in place."""

    name: str
    image: np.ndarray  # (H, W, 3) uint8 RGB
    yaw_deg: float  # CCW positive, relative to the set's first photo
    focal_px: float


def default_real_data_dir() -> Path | None:
    """The folder holding the real photo sets, or ``None`` if there is none."""
    candidates = []
    env = os.environ.get("VC_GYM_REAL_DATA")
    if env:
        candidates.append(Path(env))
    candidates.append(Path.cwd() / ".." / "shared" / "data" / "real")
    candidates.append(Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "real")
    for c in candidates:
        if c.is_dir():
            return c.resolve()
    return None


def load_rotation_set(folder: str | os.PathLike) -> list[RotationPhoto]:
    """Read a rotation set: photos plus ``yaw_ground_truth.csv``, in capture order.

    Raises
    ------
    FileNotFoundError
        If the folder or its CSV is missing.
    ValueError
        If a listed photo cannot be read or a row has no finite yaw/focal length.
    """
    folder = Path(folder)
    csv_path = folder / "yaw_ground_truth.csv"
    if not csv_path.is_file():
        raise FileNotFoundError(f"{csv_path}: no such file")
    photos = []
    with csv_path.open(newline="") as fh:
        for row in csv.DictReader(fh):
            name = row["image"]
            yaw = float(row["yaw_left_deg_autostitch"])
            focal = float(row["focal_px_autostitch"])
            if not (math.isfinite(yaw) and math.isfinite(focal) and focal > 0):
                raise ValueError(f"{csv_path}: bad yaw/focal for {name}")
            bgr = cv2.imread(str(folder / name), cv2.IMREAD_COLOR)
            if bgr is None:
                raise ValueError(f"{folder / name}: cannot be read as an image")
            photos.append(RotationPhoto(name, cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), yaw, focal))
    if not photos:
        raise ValueError(f"{csv_path}: lists no photos")
    return photos
