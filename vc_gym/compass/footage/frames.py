"""Frames of your own footage: a video file or a folder of images, read one at a time.

Frames
------
:class:`Footage` reads a video file through OpenCV (``cv2.VideoCapture``; every
format the installed FFmpeg reads) or a folder of ``.jpg``/``.jpeg``/``.png``/``.bmp``
images in natural order (``img2`` before ``img10``; other files are ignored). Frames are
converted to RGB ``uint8`` and **streamed**: one frame is decoded at a time, so a long
video never has to fit in memory. A frame may have at most :data:`MAX_FRAME_PIXELS`
pixels, counted after the scaling ``width`` asks for; an image's size is read from its
file header (and a video's from its stream) before anything is decoded, so a small file
cannot make the reader allocate gigabytes. Every frame must have the size of the first.

An image file that ends before its image does (a JPEG without its end-of-image marker, a
PNG without its closing chunk, a BMP shorter than its pixels) is a bad frame, and so is a
video frame that cannot be decoded: reading one raises :class:`BadFrameError` naming it,
or, with ``skip_bad_frames=True``, skips it and counts it in :attr:`Footage.skipped`.
"""

from __future__ import annotations

import io
import math
import os
import re
import struct
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from vc_gym.validation import flag, int_at_least, int_in_range

__all__ = [
    "IMAGE_SUFFIXES",
    "MAX_FRAME_PIXELS",
    "MAX_IMAGE_FILE_BYTES",
    "BadFrameError",
    "Footage",
    "image_file_size",
    "image_file_problem",
    "scaled_size",
]

#: Image files a footage folder may hold (other files in it are ignored).
IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp")
#: Most pixels one frame may have: 50 million (a 12-megapixel phone photo has 12, an
#: 8K video frame 33). Checked from the header before a frame is decoded; a frame this
#: size takes 150 MB as RGB.
MAX_FRAME_PIXELS = 50_000_000
#: Largest image file read whole to check that it is complete (bytes): an uncompressed
#: BMP of :data:`MAX_FRAME_PIXELS` pixels takes 150 MB.
MAX_IMAGE_FILE_BYTES = 256 * 2**20
#: Most JPEG segments read looking for the frame header (a real file has a dozen).
_MAX_JPEG_SEGMENTS = 1000
#: The closing chunk of every PNG: length 0, ``IEND``, and its fixed CRC.
_PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"


class BadFrameError(ValueError):
    """A frame that cannot be used: a truncated or corrupt image file, or a video frame
    that cannot be decoded. The message names the file (or the video and frame)."""


# ----------------------------------------------------------------------------- headers
def image_file_size(path: str | os.PathLike) -> tuple[int, int]:
    """``(height, width)`` of a PNG, JPEG or BMP file, read from its header alone.

    Raises
    ------
    ValueError
        If the file is not one of these formats or its header is damaged.
    """
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(32)
            if head.startswith(b"\x89PNG\r\n\x1a\n") and head[12:16] == b"IHDR":
                width, height = struct.unpack(">II", head[16:24])
            elif head.startswith(b"BM") and len(head) >= 26:
                (dib,) = struct.unpack("<I", head[14:18])
                if dib == 12:
                    width, height = struct.unpack("<HH", head[18:22])
                else:
                    width, height = struct.unpack("<ii", head[18:26])
                height = abs(height)  # negative: rows stored top-down
            elif head.startswith(b"\xff\xd8"):
                height, width = _jpeg_size(fh)
            else:
                raise ValueError(f"{path}: not a PNG, JPEG or BMP image")
    except OSError as exc:
        raise ValueError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    except struct.error:
        raise ValueError(f"{path}: damaged image header") from None
    if width < 1 or height < 1:
        raise ValueError(f"{path}: image header gives a size of {width}x{height}")
    return int(height), int(width)


def _jpeg_size(fh: io.BufferedReader) -> tuple[int, int]:
    """``(height, width)`` from the first start-of-frame segment of a JPEG."""
    fh.seek(2)
    for _ in range(_MAX_JPEG_SEGMENTS):
        marker = _jpeg_marker(fh)
        if marker is None or marker in (0xD9, 0xDA):  # end, or scan before a frame header
            break
        if marker == 0x01 or 0xD0 <= marker <= 0xD8:  # markers without a length
            continue
        (length,) = struct.unpack(">H", fh.read(2))
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            _, height, width = struct.unpack(">BHH", fh.read(5))
            return height, width
        fh.seek(length - 2, os.SEEK_CUR)
    raise ValueError(f"{getattr(fh, 'name', 'file')}: JPEG without a frame header")


def _jpeg_marker(fh: io.BufferedIOBase) -> int | None:
    """The next marker's code (after its ``0xFF`` and any fill bytes), ``None`` at the end."""
    byte = fh.read(1)
    while byte == b"\xff":
        byte = fh.read(1)
    return byte[0] if byte else None


def _jpeg_scan_start(data: bytes) -> int | None:
    """Offset of the first start-of-scan segment's data in a JPEG, ``None`` if none."""
    fh = io.BytesIO(data)
    fh.seek(2)
    for _ in range(_MAX_JPEG_SEGMENTS):
        marker = _jpeg_marker(fh)
        if marker is None or marker == 0xD9:
            return None
        if marker == 0x01 or 0xD0 <= marker <= 0xD8:
            continue
        raw = fh.read(2)
        if len(raw) < 2:
            return None
        (length,) = struct.unpack(">H", raw)
        fh.seek(length - 2, os.SEEK_CUR)
        if marker == 0xDA:
            return fh.tell()
    return None


def image_file_problem(data: bytes) -> str | None:
    """What makes an image file's bytes incomplete, or ``None`` when it is whole.

    Decoders fill the missing part of a truncated image with grey and at most print a
    warning, so the file's structure is checked instead: a JPEG must hold its
    end-of-image marker after the start of its scan (inside the scan a ``0xFF`` byte is
    always escaped, so the marker cannot appear by chance), a PNG must end with its
    ``IEND`` chunk, and a BMP must hold the pixel rows its header declares.
    """
    if data.startswith(b"\xff\xd8"):
        scan = _jpeg_scan_start(data)
        if scan is None:
            return "a JPEG without image data"
        if data.find(b"\xff\xd9", scan) < 0:
            return "the JPEG ends before its image does (truncated file)"
    elif data.startswith(b"\x89PNG\r\n\x1a\n"):
        if data.rfind(_PNG_END) < 0:
            return "the PNG ends before its image does (truncated file)"
    elif data.startswith(b"BM") and len(data) >= 30:
        (offset,) = struct.unpack("<I", data[10:14])
        (dib,) = struct.unpack("<I", data[14:18])
        if dib == 12:
            width, height, _, bits = struct.unpack("<HHHH", data[18:26])
            compression = 0
        else:
            width, height, _, bits, compression = struct.unpack("<iiHHI", data[18:34])
        if compression in (0, 3, 6):  # uncompressed rows (3, 6: with bit masks)
            row = (abs(width) * bits + 31) // 32 * 4
            if len(data) < offset + row * abs(height):
                return "the BMP ends before its pixel rows do (truncated file)"
    return None


def _natural_key(name: str) -> list[Any]:
    """Sort key putting ``img2`` before ``img10``."""
    return [int(p) if p.isdigit() else p.lower() for p in re.split(r"(\d+)", name)]


def _check_pixels(what: str, height: int, width: int) -> None:
    if height * width > MAX_FRAME_PIXELS:
        raise ValueError(
            f"{what}: frames of {width}x{height} pixels are larger than "
            f"{MAX_FRAME_PIXELS:,} pixels; scale the footage down first"
        )


def _widest(height: int, width: int) -> int:
    """The largest width a ``width`` x ``height`` frame may be scaled to and still fit
    :data:`MAX_FRAME_PIXELS`."""
    w = int(math.sqrt(MAX_FRAME_PIXELS * width / height))
    while w > 16 and math.prod(scaled_size(height, width, w)) > MAX_FRAME_PIXELS:
        w -= 1
    return w


def scaled_size(height: int, width: int, to_width: int | None) -> tuple[int, int]:
    """``(height, width)`` of a ``width`` x ``height`` frame scaled to ``to_width``
    pixels wide, keeping its aspect ratio (``None``: as it is)."""
    if to_width is None or to_width == width:
        return height, width
    return max(2, round(height * to_width / width)), to_width


# ----------------------------------------------------------------------------- footage
class Footage:
    """The frames of a video file or of a folder of images, read one at a time.

    Parameters
    ----------
    path : path-like
        A video file, or a folder of ``.jpg``/``.jpeg``/``.png``/``.bmp`` images
        (read in natural order of their names; other files are ignored).
    start : int
        Index of the first frame used (0: the first frame of the input).
    step : int
        Use every ``step``-th frame from ``start``.
    max_frames : int, optional
        Use at most this many frames.
    width : int, optional
        Scale every frame to this width (keeping its aspect ratio) before the compass
        sees it. The field of view does not change, so the camera stays the same; a
        smaller frame is faster to learn and track. The scaled frame must fit
        :data:`MAX_FRAME_PIXELS` too.
    skip_bad_frames : bool
        Skip frames that cannot be used (a truncated or corrupt image file, a video
        frame that cannot be decoded) and count them in :attr:`skipped`, instead of
        raising :class:`BadFrameError`.
    names : dict, optional
        The names to use in error messages, by argument (a command's flags, e.g.
        ``{"width": "--width"}``).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        For a folder without images, an image or video that cannot be read, frames
        larger than :data:`MAX_FRAME_PIXELS` (as stored or as scaled to ``width``) or
        of different sizes, a video without frames, or bad selection arguments.

    Notes
    -----
    Frame indices always count frames of the input (before ``start``/``step``), so a
    yaw CSV has one row per frame of the input. A video's frames are counted once,
    by decoding it (a container's frame count is only an estimate).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        *,
        start: int = 0,
        step: int = 1,
        max_frames: int | None = None,
        width: int | None = None,
        skip_bad_frames: bool = False,
        names: Mapping[str, str] | None = None,
    ) -> None:
        label = dict(names or {})

        def name(arg: str) -> str:
            return label.get(arg, arg)

        self.path = Path(path)
        self.start = int_at_least(name("start"), start, 0)
        self.step = int_at_least(name("step"), step, 1)
        self.max_frames = (
            None if max_frames is None else int_at_least(name("max_frames"), max_frames, 1)
        )
        self.width = None if width is None else int_in_range(name("width"), width, 16, 16384)
        self.skip_bad_frames = flag(name("skip_bad_frames"), skip_bad_frames)
        self._skip_hint = label.get("skip_bad_frames", "skip_bad_frames=True")
        self._skipped: dict[int, str] = {}
        self._names: tuple[str, ...] | None = None
        self._count: int | None = None
        self._fps: float | None = None
        self._source_size: tuple[int, int] = (0, 0)  # as declared: stream, first header
        if not self.path.exists():
            raise FileNotFoundError(f"{self.path}: no such file or folder")
        if self.path.is_dir():
            self._names, self._source_size = self._list_folder()
            self._count = len(self._names)
        elif self.path.suffix.lower() in IMAGE_SUFFIXES:
            raise ValueError(f"{self.path}: a single image; pass the folder that holds the frames")
        elif not self.path.is_file():  # a pipe or a device could block or never end
            raise ValueError(f"{self.path}: not a regular file")
        else:
            self._source_size = self._open_video()
        if self.start >= self.n_source:
            raise ValueError(
                f"{self.path}: start frame {self.start} is past the last frame "
                f"(the input has {self.n_source})"
            )
        h, w = self._source_size
        if self.width is not None and h > 0 and w > 0:
            sh, sw = scaled_size(h, w, self.width)
            if sh * sw > MAX_FRAME_PIXELS:
                raise ValueError(
                    f"{name('width')} {self.width}: frames of {w}x{h} pixels would be scaled "
                    f"to {sw}x{sh}, more than {MAX_FRAME_PIXELS:,} pixels; give a width of at "
                    f"most {_widest(h, w)}"
                )

    # --------------------------------------------------------------- opening
    def _list_folder(self) -> tuple[tuple[str, ...], tuple[int, int]]:
        try:
            names = [
                p.name
                for p in self.path.iterdir()
                if p.suffix.lower() in IMAGE_SUFFIXES and not p.name.startswith(".") and p.is_file()
            ]
        except OSError as exc:
            raise ValueError(f"{self.path}: cannot list it ({exc.strerror or exc})") from None
        if not names:
            raise ValueError(
                f"{self.path}: holds no images ({', '.join(IMAGE_SUFFIXES)}); pass a video "
                "file or a folder of frames"
            )
        names.sort(key=_natural_key)
        # every header is read before any work: a wrong file fails now, not mid-run
        sizes: dict[tuple[int, int], str] = {}
        first: tuple[int, int] | None = None
        for file in names:
            h, w = image_file_size(self.path / file)
            _check_pixels(str(self.path / file), h, w)
            first = first or (h, w)
            sizes.setdefault((min(h, w), max(h, w)), file)
        if len(sizes) > 1:
            (a, first), (b, other) = list(sizes.items())[:2]
            raise ValueError(
                f"{self.path}: frames of different sizes ({first} is {a[1]}x{a[0]}, "
                f"{other} is {b[1]}x{b[0]} pixels, either way round); all must be alike"
            )
        assert first is not None
        return tuple(names), first  # as stored: a photo's EXIF turn is checked per frame

    def _capture(self) -> cv2.VideoCapture:
        cap = cv2.VideoCapture(str(self.path))
        if not cap.isOpened():
            cap.release()
            raise ValueError(f"{self.path}: cannot be read as a video")
        return cap

    def _open_video(self) -> tuple[int, int]:
        cap = self._capture()
        try:
            w = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH))
            h = int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
            fps = float(cap.get(cv2.CAP_PROP_FPS))
            self._fps = fps if math.isfinite(fps) and 0 < fps <= 1000 else None
            if w > 0 and h > 0:
                _check_pixels(str(self.path), h, w)
            count = 0
            while cap.grab():  # decodes without converting: the exact frame count
                count += 1
        finally:
            cap.release()
        if count == 0:
            raise ValueError(f"{self.path}: a video without frames")
        self._count = count
        return h, w

    # --------------------------------------------------------------- properties
    @property
    def is_video(self) -> bool:
        """True for a video file, False for a folder of images."""
        return self._names is None

    @property
    def fps(self) -> float | None:
        """Frames per second of a video, if its file says (``None`` for a folder)."""
        return self._fps

    @property
    def names(self) -> tuple[str, ...] | None:
        """The folder's image file names in frame order (``None`` for a video)."""
        return self._names

    @property
    def n_source(self) -> int:
        """Number of frames of the input, before ``start``, ``step`` and ``max_frames``."""
        assert self._count is not None
        return self._count

    @property
    def indices(self) -> np.ndarray:
        """Input indices of the frames used, ascending."""
        idx = np.arange(self.start, self.n_source, self.step, dtype=np.int64)
        return idx if self.max_frames is None else idx[: self.max_frames]

    def __len__(self) -> int:
        return int(self.indices.size)

    def frame_name(self, index: int) -> str:
        """A frame's name in messages: its file name, or ``video.mp4 frame 12``."""
        if self._names is not None:
            return str(self.path / self._names[index])
        return f"{self.path} frame {index}"

    @property
    def frame_size(self) -> tuple[int, int]:
        """``(height, width)`` of the frames the compass sees: as stored, scaled to
        :attr:`width` when given (for photos, before any EXIF turn)."""
        return scaled_size(*self.first_size(), self.width)

    @property
    def skipped(self) -> dict[int, str]:
        """The frames skipped so far (``skip_bad_frames``): input index -> what was wrong."""
        return dict(self._skipped)

    # --------------------------------------------------------------- reading
    def frames(self, indices: Sequence[int] | None = None) -> Iterator[tuple[int, np.ndarray]]:
        """Yield ``(index, frame)`` for the frames used (or for ``indices``, ascending
        input indices), each an ``(H, W, 3)`` ``uint8`` RGB array, decoded one at a time.

        With ``skip_bad_frames`` a frame that cannot be used is left out (and recorded in
        :attr:`skipped`) instead of raising.

        Raises
        ------
        BadFrameError
            If a frame's file is truncated or cannot be decoded, or a video ends before
            a frame it was counted to have (not with ``skip_bad_frames``).
        ValueError
            If a frame differs in size from the first or is larger than
            :data:`MAX_FRAME_PIXELS` once scaled.
        """
        wanted = self.indices if indices is None else np.asarray(indices, dtype=np.int64)
        if wanted.size and (np.any(np.diff(wanted) <= 0) or wanted[0] < 0):
            raise ValueError("frame indices must be ascending and >= 0")
        if wanted.size and wanted[-1] >= self.n_source:
            raise ValueError(f"frame index {wanted[-1]} is past the last frame ({self.n_source})")
        raw = self._folder_frames(wanted) if self._names is not None else self._video_frames(wanted)
        shape: tuple[int, ...] | None = None
        for index, frame in raw:
            if isinstance(frame, str):
                if not self.skip_bad_frames:
                    raise BadFrameError(f"{frame} ({self._skip_hint} leaves such frames out)")
                self._skipped[index] = frame
                continue
            if shape is None:
                shape = frame.shape
            elif frame.shape != shape:
                raise ValueError(
                    f"{self.frame_name(index)}: {frame.shape[1]}x{frame.shape[0]} pixels, "
                    f"but the first frame has {shape[1]}x{shape[0]}; all must be alike"
                )
            yield index, self._scaled(self.frame_name(index), frame)

    def _folder_frames(self, wanted: np.ndarray) -> Iterator[tuple[int, np.ndarray | str]]:
        """``(index, RGB frame)``, or ``(index, what is wrong)`` for a bad file."""
        assert self._names is not None
        for index in wanted.tolist():
            path = self.path / self._names[index]
            try:
                with open(path, "rb") as fh:
                    data = fh.read(MAX_IMAGE_FILE_BYTES + 1)
            except OSError as exc:
                yield index, f"{path}: cannot read it ({exc.strerror or exc})"
                continue
            if len(data) > MAX_IMAGE_FILE_BYTES:
                yield index, f"{path}: larger than {MAX_IMAGE_FILE_BYTES:,} bytes"
                continue
            problem = image_file_problem(data)
            if problem is not None:
                yield index, f"{path}: {problem}"
                continue
            bgr = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
            if bgr is None or bgr.ndim != 3:
                yield index, f"{path}: cannot be decoded as an image (corrupt file?)"
                continue
            yield index, cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)

    def _video_frames(self, wanted: np.ndarray) -> Iterator[tuple[int, np.ndarray | str]]:
        """``(index, RGB frame)``; after a frame that cannot be decoded, ``(index, what
        is wrong)`` for it and every later one (a video cannot be read past it)."""
        cap = self._capture()
        try:
            pos = 0
            for k, index in enumerate(wanted.tolist()):
                ok = True
                while ok and pos < index:
                    ok = cap.grab()
                    pos += 1
                if ok:
                    ok, bgr = cap.read()
                    pos += 1
                if not ok or bgr is None:
                    for rest in wanted[k:].tolist():
                        yield rest, self._ended(index)
                    return
                if bgr.ndim == 2:
                    bgr = cv2.cvtColor(bgr, cv2.COLOR_GRAY2BGR)
                _check_pixels(self.frame_name(index), *bgr.shape[:2])
                yield index, cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
        finally:
            cap.release()

    def _ended(self, index: int) -> str:
        return (
            f"{self.path}: the video ended (or could not be decoded) at frame {index} "
            f"of the {self.n_source} it was counted to have"
        )

    def _scaled(self, what: str, frame: np.ndarray) -> np.ndarray:
        h, w = scaled_size(frame.shape[0], frame.shape[1], self.width)
        if (h, w) == frame.shape[:2]:
            return frame
        if h * w > MAX_FRAME_PIXELS:  # a photo turned by its EXIF tag, a video's real size
            raise ValueError(
                f"{what}: scaled to a width of {w} it would have {w}x{h} pixels, more than "
                f"{MAX_FRAME_PIXELS:,}; give a smaller width"
            )
        return cv2.resize(frame, (w, h), interpolation=cv2.INTER_AREA)

    def first_size(self) -> tuple[int, int]:
        """``(height, width)`` of the input's frames as stored (before ``width``; for
        photos, after the turn their EXIF orientation asks for)."""
        if self._names is None:
            h, w = self._source_size
            if h > 0 and w > 0:
                return h, w
            first = self._video_frames(np.array([0]))
        else:
            first = self._folder_frames(np.array([0]))
        try:
            _, frame = next(first)
        finally:
            first.close()  # releases the video now, not when collected
        if isinstance(frame, str):
            raise BadFrameError(f"{frame}; the frame size is read from the first frame")
        return int(frame.shape[0]), int(frame.shape[1])

    def __repr__(self) -> str:
        kind = "video" if self.is_video else "folder"
        return (
            f"Footage({str(self.path)!r}, {kind}, {len(self)} of {self.n_source} frames, "
            f"start={self.start}, step={self.step})"
        )
