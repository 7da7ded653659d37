"""Position from a full turn: the calibration places whose goodness signatures are nearest.

A single view's score vector depends on where the camera looks as much as on where the
robot stands. Averaged over a full turn on the spot (the robot facing ``k`` evenly
spaced directions), every spot's score is a property of the place: the turn's
**signature** (:func:`~vc_gym.localization.mean_spot_scores` over the turn's frames).
Signatures recorded by turns at known places (e.g. at
:func:`~vc_gym.localization.calibration_points`) make a map of the field, and a new
turn is placed by place recognition: :func:`locate_by_turn_signature` takes the ``k``
places whose signatures are nearest, each spot's score measured in units of its
residual spread ``σ_i`` (:func:`~vc_gym.localization.calibrate_goodness` on the same
turns), weighted by inverse signature distance.
"""

from __future__ import annotations

import numpy as np

from vc_gym.localization.spot_scores import finite_array
from vc_gym.validation import positive_float

__all__ = ["MIN_STD_M", "NEAREST_K", "locate_by_turn_signature"]

#: Places whose signatures make an estimate.
NEAREST_K = 3
#: Smallest spread reported per axis (metres): a turn that matches one place exactly
#: is still only known to about the places' resolution.
MIN_STD_M = 0.05


def locate_by_turn_signature(
    scores: np.ndarray,
    places: np.ndarray,
    place_scores: np.ndarray,
    sigma: np.ndarray,
    k: int = NEAREST_K,
    min_std_m: float = MIN_STD_M,
) -> tuple[np.ndarray, np.ndarray]:
    """Position from the ``k`` places whose turn signatures are nearest.

    Signature distance: ``sqrt(Σ_i ((s_i − S_pi) / σ_i)²)`` over spots ``i`` between
    the turn's signature ``s`` and place ``p``'s ``S_p``; the ``k`` nearest places
    (ties in place order) weigh ``∝ 1 / distance``.

    Parameters
    ----------
    scores : array_like
        ``(M,)`` the turn's signature: every spot's raw score averaged over the turn.
    places : array_like
        ``(P, 2)`` places ``(x, y)`` whose signatures are known, metres.
    place_scores : array_like
        ``(P, M)`` their signatures (turns taken the same way).
    sigma : array_like
        ``(M,)`` residual spread of each spot's signature score (> 0), e.g.
        ``calibrate_goodness(spots, places, place_scores).sigma``.
    k : int
        How many places make the estimate (fewer if there are fewer places).
    min_std_m : float
        Floor of the reported spread per axis, metres.

    Returns
    -------
    mean : numpy.ndarray
        ``(2,)`` weighted mean of the ``k`` places.
    std : numpy.ndarray
        ``(2,)`` their weighted spread per axis, at least ``min_std_m``.

    Raises
    ------
    ValueError
        Arrays of the wrong shape, empty or not finite; ``sigma <= 0``; ``k`` not an
        int >= 1; ``min_std_m`` not > 0.
    """
    places = finite_array("places", places, (None, 2))
    place_scores = finite_array("place_scores", place_scores, (places.shape[0], None))
    n = place_scores.shape[1]
    scores = finite_array("scores", scores, (n,))
    sigma = finite_array("sigma", sigma, (n,))
    if np.any(sigma <= 0):
        raise ValueError("sigma must be > 0")
    if isinstance(k, bool) or not isinstance(k, int | np.integer) or k < 1:
        raise ValueError(f"k must be an int >= 1, got {k!r}")
    floor = positive_float("min_std_m", min_std_m)
    d = np.sqrt((((place_scores - scores[None, :]) / sigma[None, :]) ** 2).sum(axis=1))
    nearest = np.argsort(d, kind="stable")[: min(k, len(d))]
    w = 1.0 / (d[nearest] + 1e-9)
    w /= w.sum()
    mean = w @ places[nearest]
    std = np.sqrt(np.maximum(w @ (places[nearest] - mean) ** 2, floor**2))
    return mean, std
