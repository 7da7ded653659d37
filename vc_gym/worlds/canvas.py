"""The one painting surface of vc_gym: a float RGB image addressed in surface units.

Every procedural picture of vc_gym is painted on a :class:`Canvas`: the seamless 360°
panoramas of :mod:`vc_gym.worlds.panorama_painters` and the walls, floors, facades and
sky of the PyBullet scenes (:mod:`vc_gym.sim.textures`, :mod:`vc_gym.sim.scenes`).

A canvas is a rectangle of surface, ``x`` to the right (0 .. ``width_m``) and ``y`` up
(0 .. ``height_m``), painted as a ``float32`` RGB image whose row 0 is the top edge
``y = height_m``. It is measured in metres (``Canvas(width_m, height_m, px_per_m, rgb)``,
a texture) or in degrees (:meth:`Canvas.panorama`: 360° of azimuth by the elevation
band). Pixels are addressed in two ways:

* by rectangles and discs in surface coordinates (:meth:`~Canvas.rect`,
  :meth:`~Canvas.shade`, :meth:`~Canvas.outline`, :meth:`~Canvas.paste`,
  :meth:`~Canvas.disc`) and the wall things made of them (doors, windows, boards, ...);
* by masks over the columns whose coordinate (:attr:`~Canvas.column_coords`: ``x`` of a
  texture's column centres, the azimuth a panorama's column looks at) lies near a
  centre (:meth:`~Canvas.columns`, then :meth:`~Canvas.paint`); a panorama's columns
  wrap around 360°, so a feature may straddle its seam.

:meth:`Canvas.image` gives the painted ``uint8`` RGB image. All randomness comes from
the ``numpy.random.Generator`` passed in.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from vc_gym.angles import wrap180, wrap360
from vc_gym.worlds.paint import random_color, smooth_noise, to_uint8

__all__ = ["Canvas"]


class Canvas:
    """A flat surface measured in metres (or degrees), painted as an RGB image.

    ``x`` runs to the right (0 .. ``width_m``), ``y`` up (0 .. ``height_m``); the image's
    row 0 is the top edge ``y = height_m``, so its bottom row is texture ``v = 0``.

    Parameters
    ----------
    width_m, height_m : float
        Size of the surface (> 0).
    px_per_m : float
        Resolution (the image is at least 2 x 2 pixels).
    rgb : sequence of float
        Background colour (0..255).

    Attributes
    ----------
    img : numpy.ndarray
        The ``(H, W, 3)`` ``float32`` RGB image being painted (0..255).
    width_m, height_m : float
        Size of the surface (degrees for a :meth:`panorama` canvas).
    sx, sy : float
        Pixels per unit along ``x`` and ``y``.
    column_coords : numpy.ndarray
        ``(W,)``: what each column is at, as :meth:`columns` measures it: ``x`` of the
        column centre, or the azimuth (degrees) a panorama's column looks at.
    row_coords : numpy.ndarray
        ``(H,)``: ``y`` of each row centre, or the elevation (degrees) a panorama's row
        looks at; decreasing down the image.
    wraps : bool
        Whether :attr:`column_coords` are azimuths that wrap around 360°.
    """

    def __init__(
        self, width_m: float, height_m: float, px_per_m: float, rgb: Sequence[float]
    ) -> None:
        if not (width_m > 0 and height_m > 0 and px_per_m > 0):
            raise ValueError(
                f"canvas size and resolution must be > 0, got {width_m}, {height_m}, {px_per_m}"
            )
        w = max(2, int(round(width_m * px_per_m)))
        h = max(2, int(round(height_m * px_per_m)))
        self._set_surface(float(width_m), float(height_m), w, h, rgb)
        self.column_coords = (np.arange(w) + 0.5) / self.sx
        self.row_coords = self.height_m - (np.arange(h) + 0.5) / self.sy
        self.wraps = False

    @classmethod
    def panorama(
        cls,
        width: int,
        height: int,
        elev_top_deg: float = 45.0,
        elev_bottom_deg: float = -45.0,
        azimuth0_deg: float = 0.0,
        rgb: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> Canvas:
        """A 360° panorama band, seen from inside (moving right turns clockwise).

        Column ``c`` looks at azimuth ``azimuth0_deg - 360 (c + 0.5) / width`` (mod 360)
        and row ``r`` at elevation ``top - (top - bottom) (r + 0.5) / height``, the
        conventions of :class:`vc_gym.worlds.panorama.Panorama`. Surface coordinates are
        degrees: ``x`` clockwise from the left edge, ``y`` up from the bottom edge.

        Parameters
        ----------
        width, height : int
            Size of the image in pixels.
        elev_top_deg, elev_bottom_deg : float
            Elevation of the top edge of row 0 and of the bottom edge of the last row.
        azimuth0_deg : float
            Azimuth of the left edge of column 0.
        rgb : sequence of float
            Background colour (0..255); black by default.

        Returns
        -------
        Canvas
            A canvas whose :attr:`column_coords` are azimuths (``float64``, wrapping)
            and :attr:`row_coords` elevations (``float32``).
        """
        canvas = cls.__new__(cls)
        top, bottom = float(elev_top_deg), float(elev_bottom_deg)
        canvas._set_surface(360.0, top - bottom, int(width), int(height), rgb)
        canvas.column_coords = np.asarray(
            wrap360(azimuth0_deg - 360.0 * (np.arange(width) + 0.5) / width)
        )
        elevation = top - (top - bottom) * (np.arange(height) + 0.5) / height
        canvas.row_coords = elevation.astype(np.float32)
        canvas.wraps = True
        return canvas

    def _set_surface(
        self, width_m: float, height_m: float, w: int, h: int, rgb: Sequence[float]
    ) -> None:
        self.width_m, self.height_m = width_m, height_m
        self.sx, self.sy = w / self.width_m, h / self.height_m
        self.img = np.empty((h, w, 3), np.float32)
        self.img[:] = np.asarray(rgb, np.float32)

    def image(self) -> np.ndarray:
        """The painted image as ``uint8`` RGB (rounded and clipped; a new array)."""
        return to_uint8(self.img)

    # ------------------------------------------------------------ columns and masks
    def columns(self, centre: float, half_width: float) -> tuple[np.ndarray, np.ndarray]:
        """Columns within ``half_width`` of ``centre``, and their signed offsets.

        Parameters
        ----------
        centre : float
            A column coordinate (:attr:`column_coords`): ``x``, or an azimuth.
        half_width : float
            Largest distance from ``centre``, in the same unit.

        Returns
        -------
        cols : numpy.ndarray
            Column indices, increasing (on a panorama they may wrap from the last
            column to the first).
        offsets : numpy.ndarray
            ``column_coords[cols] - centre``: to the right for ``x``; for an azimuth
            wrapped to ``[-180, 180)``, positive to the left (counter-clockwise).
        """
        if self.wraps:
            rel = np.asarray(wrap180(self.column_coords - centre))
        else:
            rel = self.column_coords - centre
        cols = np.flatnonzero(np.abs(rel) <= half_width)
        return cols, rel[cols]

    def paint(self, cols: np.ndarray, mask: np.ndarray, colour: np.ndarray) -> None:
        """Set the pixels ``mask`` (shape ``(H, len(cols))``) of columns ``cols``.

        Parameters
        ----------
        cols : numpy.ndarray
            Increasing column indices, e.g. from :meth:`columns`.
        mask : numpy.ndarray
            Boolean mask broadcastable to ``(H, len(cols))``.
        colour : numpy.ndarray
            RGB (0..255), or one colour per masked pixel.
        """
        if cols.size == 0:
            return
        mask = np.broadcast_to(mask, (self.img.shape[0], cols.size))
        if not mask.any():
            return
        if cols[-1] - cols[0] == cols.size - 1:  # contiguous: paint through a view
            self.img[:, cols[0] : cols[-1] + 1][mask] = colour
            return
        block = self.img[:, cols]  # straddles the seam: gather, paint, scatter
        block[mask] = colour
        self.img[:, cols] = block

    # ------------------------------------------------------- rectangles and discs
    def _box(self, x0: float, x1: float, y0: float, y1: float) -> tuple[slice, slice]:
        h, w = self.img.shape[:2]
        c0 = min(max(int(round(x0 * self.sx)), 0), w)
        c1 = min(max(int(round(x1 * self.sx)), 0), w)
        r0 = min(max(int(round((self.height_m - y1) * self.sy)), 0), h)
        r1 = min(max(int(round((self.height_m - y0) * self.sy)), 0), h)
        return slice(r0, r1), slice(c0, c1)

    def rect(self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float]) -> None:
        """Fill the rectangle ``[x0, x1] x [y0, y1]``."""
        rows, cols = self._box(x0, x1, y0, y1)
        self.img[rows, cols] = np.asarray(rgb, np.float32)

    def shade(self, x0: float, x1: float, y0: float, y1: float, factor: float) -> None:
        """Multiply the rectangle's colours by ``factor``."""
        rows, cols = self._box(x0, x1, y0, y1)
        self.img[rows, cols] *= np.float32(factor)

    def outline(
        self, x0: float, x1: float, y0: float, y1: float, width: float, rgb: Sequence[float]
    ) -> None:
        """A frame of bars ``width`` wide just inside the rectangle."""
        self.rect(x0, x1, y0, y0 + width, rgb)
        self.rect(x0, x1, y1 - width, y1, rgb)
        self.rect(x0, x0 + width, y0, y1, rgb)
        self.rect(x1 - width, x1, y0, y1, rgb)

    def paste(self, x0: float, x1: float, y0: float, y1: float, image: np.ndarray) -> None:
        """Resample ``image`` (RGB) onto the rectangle (area interpolation)."""
        rows, cols = self._box(x0, x1, y0, y1)
        h, w = rows.stop - rows.start, cols.stop - cols.start
        if h <= 0 or w <= 0:
            return
        inter = cv2.INTER_AREA if image.shape[0] >= h else cv2.INTER_LINEAR
        self.img[rows, cols] = cv2.resize(image, (w, h), interpolation=inter).astype(np.float32)

    def disc(
        self, cx: float, cy: float, r: float, rgb: Sequence[float], inner: float = 0.0
    ) -> None:
        """A filled disc of radius ``r`` (a ring if ``inner > 0``)."""
        rows, cols = self._box(cx - r, cx + r, cy - r, cy + r)
        if rows.stop <= rows.start or cols.stop <= cols.start:
            return
        ys = self.height_m - (np.arange(rows.start, rows.stop) + 0.5) / self.sy
        xs = (np.arange(cols.start, cols.stop) + 0.5) / self.sx
        d = np.hypot(xs[None, :] - cx, ys[:, None] - cy)
        block = self.img[rows, cols]
        block[(d <= r) & (d >= inner)] = np.asarray(rgb, np.float32)

    def mottle(self, rng: np.random.Generator, amount: float, blob_m: float = 0.5) -> None:
        """Multiply by ``1 + amount * noise`` with blobs about ``blob_m`` across.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of the noise (:func:`~vc_gym.worlds.paint.smooth_noise`).
        amount : float
            Standard deviation of the relative change.
        blob_m : float
            Size of the blobs (surface units).
        """
        h, w = self.img.shape[:2]
        cells = max(1.0, self.width_m / blob_m)
        self.img *= (1.0 + np.float32(amount) * smooth_noise(rng, h, w, cells))[..., None]

    # ------------------------------------------------------------- things on walls
    def framed(
        self,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        image: np.ndarray,
        frame_rgb: Sequence[float] = (30, 30, 30),
        frame_m: float = 0.04,
    ) -> None:
        """A picture with a frame ``frame_m`` wide around it (outer size given)."""
        self.rect(x0, x1, y0, y1, frame_rgb)
        self.paste(x0 + frame_m, x1 - frame_m, y0 + frame_m, y1 - frame_m, image)

    def door(
        self, x0: float, x1: float, top: float, leaf: Sequence[float], casing: Sequence[float]
    ) -> None:
        """A door from the floor to ``top``: casing, leaf, a handle and a kick plate."""
        self.rect(x0 - 0.07, x1 + 0.07, 0.0, top + 0.07, casing)
        self.rect(x0, x1, 0.0, top, leaf)
        self.shade(x0 + 0.1, x1 - 0.1, top * 0.55, top - 0.12, 0.9)  # upper panel
        self.shade(x0 + 0.1, x1 - 0.1, 0.15, top * 0.45, 0.9)  # lower panel
        self.rect(x1 - 0.16, x1 - 0.06, 0.98, 1.04, (200, 200, 205))  # handle

    def window(
        self,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        view: np.ndarray,
        frame: Sequence[float] = (240, 240, 240),
        mullions: int = 1,
    ) -> None:
        """A window: frame, sill, glass showing ``view`` and ``mullions`` vertical bars."""
        self.rect(x0 - 0.05, x1 + 0.05, y0 - 0.06, y0, (225, 225, 220))  # sill
        self.rect(x0, x1, y0, y1, frame)
        f = 0.06
        self.paste(x0 + f, x1 - f, y0 + f, y1 - f, view)
        for i in range(1, mullions + 1):
            x = x0 + (x1 - x0) * i / (mullions + 1)
            self.rect(x - 0.03, x + 0.03, y0, y1, frame)
        self.rect(x0, x1, y0 + 0.62 * (y1 - y0) - 0.03, y0 + 0.62 * (y1 - y0) + 0.03, frame)

    def blinds(self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float]) -> None:
        """Venetian blinds half down: coarse slats 10 cm apart over the top part."""
        bottom = y0 + 0.45 * (y1 - y0)
        y = y1
        dark = np.asarray(rgb, np.float32) * np.float32(0.8)
        while y - 0.1 >= bottom:
            self.rect(x0, x1, y - 0.07, y, rgb)
            self.rect(x0, x1, y - 0.1, y - 0.07, dark)
            y -= 0.1
        self.rect(x0, x1, bottom - 0.04, bottom, dark)

    def curtains(
        self, x0: float, x1: float, y0: float, y1: float, rgb: Sequence[float], width: float
    ) -> None:
        """Two curtains ``width`` wide on either side of ``[x0, x1]`` with broad folds."""
        base = np.asarray(rgb, np.float32)
        self.rect(x0 - width - 0.1, x1 + width + 0.1, y1 - 0.05, y1, (90, 70, 50))  # rod
        for cx0 in (x0 - width, x1 - 0.15):
            n = 3
            fw = (width + 0.15) / n
            for i in range(n):
                f = 1.0 if i % 2 == 0 else 0.82
                self.rect(cx0 + i * fw, cx0 + (i + 1) * fw, y0, y1 - 0.05, base * np.float32(f))

    def radiator(self, x0: float, x1: float, y0: float, y1: float) -> None:
        """A white radiator with three coarse horizontal ribs."""
        self.rect(x0, x1, y0, y1, (232, 232, 228))
        for k in range(3):
            y = y0 + (k + 0.5) * (y1 - y0) / 3
            self.rect(x0, x1, y - 0.025, y + 0.025, (190, 190, 188))

    def clock(self, cx: float, cy: float, r: float, rim: Sequence[float]) -> None:
        """A wall clock: rim, white face, two thick hands."""
        self.disc(cx, cy, r, rim)
        self.disc(cx, cy, r - 0.035, (245, 245, 240))
        self.rect(cx - 0.015, cx + 0.015, cy, cy + 0.7 * r, (20, 20, 20))
        self.rect(cx, cx + 0.55 * r, cy - 0.015, cy + 0.015, (20, 20, 20))

    def board(
        self,
        rng: np.random.Generator,
        x0: float,
        x1: float,
        y0: float,
        y1: float,
        kind: str = "white",
    ) -> None:
        """A whiteboard with coarse coloured drawings, or a cork board with notes.

        Parameters
        ----------
        rng : numpy.random.Generator
            Source of the drawings or notes.
        x0, x1, y0, y1 : float
            The board's rectangle.
        kind : {"white", "cork"}
            ``"white"``: a whiteboard; anything else: a cork board.
        """
        if kind == "white":
            self.rect(x0, x1, y0, y1, (170, 172, 178))
            self.rect(x0 + 0.04, x1 - 0.04, y0 + 0.04, y1 - 0.04, (246, 246, 246))
            self.rect(x0 + 0.1, x1 - 0.1, y0 - 0.05, y0, (150, 150, 155))  # pen tray
            for _ in range(int(rng.integers(3, 6))):
                color = rng.choice([(200, 30, 30), (30, 60, 180), (20, 120, 40), (30, 30, 30)])
                bx = rng.uniform(x0 + 0.15, x1 - 0.5)
                by = rng.uniform(y0 + 0.15, y1 - 0.35)
                bw, bh = rng.uniform(0.25, 0.6), rng.uniform(0.15, 0.3)
                if rng.uniform() < 0.5:
                    self.outline(bx, bx + bw, by, by + bh, 0.03, color)
                else:
                    for k in range(int(rng.integers(1, 4))):  # "text" lines
                        yy = by + bh - k * 0.09
                        self.rect(bx, bx + bw * rng.uniform(0.5, 1.0), yy - 0.03, yy, color)
        else:
            self.rect(x0, x1, y0, y1, (120, 85, 50))
            self.rect(x0 + 0.04, x1 - 0.04, y0 + 0.04, y1 - 0.04, (190, 145, 95))
            for _ in range(int(rng.integers(4, 9))):
                w, h = rng.uniform(0.12, 0.3), rng.uniform(0.1, 0.3)
                bx, by = (
                    rng.uniform(x0 + 0.06, x1 - 0.06 - w),
                    rng.uniform(y0 + 0.06, y1 - 0.06 - h),
                )
                color = random_color(rng, s=(0.0, 0.6), v=(0.8, 1.0))
                self.rect(bx, bx + w, by, by + h, color)
