"""The compass' estimate drawn on a frame, and frames written to a video file."""

from __future__ import annotations

import math
import os
from pathlib import Path

import cv2
import numpy as np

from vc_gym.compass.visual_compass import CompassEstimate
from vc_gym.images import check_image
from vc_gym.validation import finite_real

__all__ = ["VIDEO_SUFFIXES", "VideoSink", "draw_estimate"]

#: Video containers :class:`VideoSink` writes (with the ``mp4v`` codec).
VIDEO_SUFFIXES = (".mp4", ".avi", ".mov", ".m4v")


# ----------------------------------------------------------------------------- drawing
def draw_estimate(
    frame: np.ndarray, estimate: CompassEstimate, true_deg: float | None = None
) -> np.ndarray:
    """A copy of ``frame`` with the estimate drawn on it: a compass dial in the top
    left corner whose needle points at the heading (0° up, counter-clockwise positive,
    as seen from above), the true yaw as a thin green needle if given, and the text
    ``heading ± spread``.

    Parameters
    ----------
    frame : numpy.ndarray
        ``(H, W, 3)`` ``uint8`` RGB image.
    estimate : CompassEstimate
        The compass' estimate for it.
    true_deg : float, optional
        The known yaw.

    Returns
    -------
    numpy.ndarray
        The annotated ``(H, W, 3)`` ``uint8`` RGB image.
    """
    img = np.ascontiguousarray(check_image(frame, "frame")).copy()
    h, w = img.shape[:2]
    r = max(8, min(h, w) // 8)
    cx, cy = r + max(4, r // 4), r + max(4, r // 4)
    thick = max(1, r // 16)
    cv2.circle(img, (cx, cy), r, (255, 255, 255), -1, cv2.LINE_AA)
    cv2.circle(img, (cx, cy), r, (0, 0, 0), thick, cv2.LINE_AA)

    def tip(angle_deg: float, length: float) -> tuple[int, int]:
        a = math.radians(angle_deg)  # 0 up; counter-clockwise on screen
        return round(cx - length * math.sin(a)), round(cy - length * math.cos(a))

    if true_deg is not None and math.isfinite(true_deg):
        cv2.line(img, (cx, cy), tip(true_deg, 0.95 * r), (0, 160, 0), thick, cv2.LINE_AA)
    if estimate.has_evidence:
        cv2.arrowedLine(
            img,
            (cx, cy),
            tip(estimate.heading_deg, 0.85 * r),
            (220, 0, 0),
            2 * thick,
            cv2.LINE_AA,
            tipLength=0.3,
        )
        spread = estimate.spread_deg
        shown = "<0.1" if spread < 0.1 else f"{spread:.1f}" if spread < 1000 else "inf"
        text = f"{estimate.heading_deg:.1f} +- {shown} deg"
    else:
        text = "no evidence"
    # white text on a dark box under the dial (Hershey fonts have no degree sign)
    scale = max(0.4, min(h, w) / 480)
    font = cv2.FONT_HERSHEY_SIMPLEX
    (tw, th), base = cv2.getTextSize(text, font, scale, thick)
    x0, y0 = cx - r, cy + r + max(4, r // 4)
    cv2.rectangle(img, (x0, y0), (x0 + tw + 8, y0 + th + base + 8), (0, 0, 0), -1)
    cv2.putText(img, text, (x0 + 4, y0 + th + 4), font, scale, (255, 255, 255), thick, cv2.LINE_AA)
    return img


class VideoSink:
    """Frames written to a video file with ``cv2.VideoWriter`` (``mp4v`` codec).

    Use as a context manager; the file is complete once it closes. Write to a
    temporary name and rename it (:func:`vc_gym.persistence.write_atomic`) so that a
    failed run leaves no half video.

    Parameters
    ----------
    path : path-like
        The file; its suffix picks the container (:data:`VIDEO_SUFFIXES`).
    fps : float
        Frames per second, in ``(0, 1000]``.
    """

    def __init__(self, path: str | os.PathLike, fps: float = 10.0) -> None:
        self.path = Path(path)
        if self.path.suffix.lower() not in VIDEO_SUFFIXES:
            raise ValueError(
                f"{self.path}: a video needs one of the suffixes {', '.join(VIDEO_SUFFIXES)}"
            )
        self.fps = finite_real("fps", fps)
        if not 0 < self.fps <= 1000:
            raise ValueError(f"fps must be in (0, 1000], got {fps!r}")
        self._writer: cv2.VideoWriter | None = None
        self._size: tuple[int, int] | None = None
        self.frames_written = 0

    def write(self, frame: np.ndarray) -> None:
        """Append one ``(H, W, 3)`` ``uint8`` RGB frame (all of one size)."""
        check_image(frame, "frame")
        size = (frame.shape[1], frame.shape[0])
        if self._writer is None:
            self._writer = cv2.VideoWriter(
                str(self.path), cv2.VideoWriter_fourcc(*"mp4v"), self.fps, size
            )
            if not self._writer.isOpened():
                self._writer = None
                raise RuntimeError(f"{self.path}: OpenCV cannot write an mp4v video there")
            self._size = size
        elif size != self._size:
            raise ValueError(f"frame of {size[0]}x{size[1]} in a video of {self._size}")
        self._writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
        self.frames_written += 1

    def close(self) -> None:
        """Finish the file."""
        if self._writer is not None:
            self._writer.release()
            self._writer = None

    def __enter__(self) -> VideoSink:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
