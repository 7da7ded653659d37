"""Spot score vectors: every spot's goodness of a frame, the input of the position estimators.

A score vector holds, for each spot ``T_i`` of an atlas, the raw score of a frame under
that spot's map at its best heading (:meth:`~vc_gym.compass.CompassAtlas.scores`: the
mean log-probability per term, ``log L_i`` of eq. 28). Averaged over the frames of one
view or of a full turn, it is what :mod:`~vc_gym.localization.goodness_calibration` and
:mod:`~vc_gym.localization.turn_signature` turn into a position. :func:`finite_array` is
the input check those estimators share.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vc_gym.compass import Camera, CompassAtlas

__all__ = ["finite_array", "mean_spot_scores"]


def finite_array(name: str, value: object, shape: tuple[int | None, ...]) -> np.ndarray:
    """``value`` as a non-empty, finite float64 array of ``shape``, or a ``ValueError``.

    Parameters
    ----------
    name : str
        The argument's name, for the error message.
    value : array_like
        What was given.
    shape : tuple of int or None
        The expected shape; ``None`` allows any length along that axis.

    Returns
    -------
    numpy.ndarray
        ``value`` as float64.

    Raises
    ------
    ValueError
        A value that is not numeric, of another shape, empty, or holding NaN or inf.
    """
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of numbers, got {value!r}") from None
    if a.ndim != len(shape) or any(
        w is not None and n != w for n, w in zip(a.shape, shape, strict=False)
    ):
        raise ValueError(f"{name} must have shape {shape} (None: any), got {a.shape}")
    if a.size == 0:
        raise ValueError(f"{name} must be non-empty and finite, got an empty array")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be non-empty and finite, got NaN or inf")
    return a


def mean_spot_scores(
    atlas: CompassAtlas, images: Sequence[np.ndarray], camera: Camera
) -> np.ndarray:
    """Every spot's raw score of the images, averaged over them (``log L_i``, eq. 28).

    Over the frames of one view it is the one-view score vector of
    :func:`~vc_gym.localization.locate_by_goodness`; over the frames of a full turn on
    the spot it is the turn signature of
    :func:`~vc_gym.localization.locate_by_turn_signature`.

    Parameters
    ----------
    atlas : CompassAtlas
        The maps of the spots (one score per spot, in ``atlas.names`` order).
    images : sequence of numpy.ndarray
        ``(H, W, 3)`` uint8 RGB camera images, at least one.
    camera : Camera
        Intrinsics and pitch of the camera (each spot takes its best heading, so the
        yaw plays no part).

    Returns
    -------
    numpy.ndarray
        ``(len(atlas),)`` float64 mean scores.

    Raises
    ------
    ValueError
        An atlas that is not a :class:`~vc_gym.compass.CompassAtlas`, no images, or an
        image the compass refuses.
    """
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if isinstance(images, np.ndarray) or not isinstance(images, Sequence) or len(images) == 0:
        raise ValueError("images must be a non-empty sequence of (H, W, 3) uint8 images")
    return np.mean([atlas.scores(image, camera)[0] for image in images], axis=0)
