"""Validation of camera images: ``numpy.ndarray``, ``uint8``, shape ``(H, W, 3)``, RGB."""

from __future__ import annotations

import numpy as np

__all__ = ["check_image"]


def check_image(image: object, name: str = "image", min_size: int = 2) -> np.ndarray:
    """Return ``image`` if it is an RGB ``uint8`` array of shape ``(H, W, 3)``.

    Parameters
    ----------
    image : object
        The candidate image.
    name : str
        Name used in the error message.
    min_size : int
        Smallest allowed height and width.

    Raises
    ------
    ValueError
        If the image is not a numpy ``uint8`` array of shape ``(H, W, 3)`` with
        ``H, W >= min_size``. The message names the expected and the received shape/dtype.
    """
    if not isinstance(image, np.ndarray):
        raise ValueError(
            f"{name} must be a numpy.ndarray of shape (H, W, 3) and dtype uint8 (RGB), "
            f"got {type(image).__name__}"
        )
    if image.dtype != np.uint8:
        raise ValueError(
            f"{name} must have dtype uint8 (RGB, 0..255), got {image.dtype}; "
            "convert floats with (img * 255).round().astype(np.uint8)"
        )
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"{name} must have shape (H, W, 3) (RGB), got {image.shape}")
    if image.shape[0] < min_size or image.shape[1] < min_size:
        raise ValueError(
            f"{name} must be at least {min_size}x{min_size} pixels, got {image.shape[:2]}"
        )
    return image
