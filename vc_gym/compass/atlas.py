"""Several compasses learned at several spots: goodness of fit and position (eq. 28-30).

One :class:`VisualCompass` map per training spot ``T_i``. For an image, each map's
goodness ``L_i`` (eq. 28) says how well the image fits what was seen at that spot;
after normalising the ``L_i`` so that they are equal at the home spot (paper 5.2),
the position estimate is the likelihood-weighted mean of the spots (eq. 30).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.compass.visual_compass import CompassEstimate, VisualCompass
from vc_gym.errors import NotLearnedError

__all__ = ["CompassAtlas", "AtlasEstimate"]


@dataclass(frozen=True)
class AtlasEstimate:
    """What the atlas says about one image.

    Attributes
    ----------
    position : tuple of float
        Likelihood-weighted mean of the spot positions (eq. 30), world ``(x, y)``.
    goodness : dict
        Normalised goodness ``L̂_i`` per spot name (1.0 for every spot at home after
        :meth:`CompassAtlas.normalize`; larger means the image fits that spot better).
    weights : dict
        The weights of eq. 30 per spot (sum to 1).
    estimates : dict
        Each spot's own :class:`CompassEstimate` (heading, spread, score, ...).
    """

    position: tuple[float, float]
    goodness: dict[str, float]
    weights: dict[str, float]
    estimates: dict[str, CompassEstimate]


class CompassAtlas:
    """Compasses learned at several spots, for goodness-of-fit and position (eq. 28-30).

    Parameters
    ----------
    spots : mapping
        ``{name: ((x, y), compass)}``: the training spot ``T_i`` in world metres and
        the :class:`VisualCompass` learned there. All compasses must share one config.
    home : str
        Name of the home (target) spot. It may be one of the spots or a place of its
        own; :meth:`normalize` is meant to be called with images taken there.
    home_position : tuple of float, optional
        World position of home. Defaults to the named spot's position, or to the
        centroid of the spots when ``home`` is not a spot.
    sharpness : float, optional
        Exponent applied to the goodness before weighting. Each compass's score is a
        mean over ``c²`` class pairs per sector, so the default ``c²`` makes the
        weights the per-sector geometric-mean likelihoods; larger values make the
        position estimate snap to the best spot, smaller ones to the centroid.

    Notes
    -----
    The paper takes ``L_i`` as the maximal likelihood of the image under map ``i``
    (eq. 28). Raw likelihoods are products over hundreds of terms and overflow, so
    here ``L_i = exp(score_i)`` with ``score_i`` the mean log-probability per term at
    the best heading (:attr:`CompassEstimate.score`), i.e. a geometric mean.
    """

    def __init__(
        self,
        spots: Mapping[str, tuple[tuple[float, float], VisualCompass]],
        home: str,
        home_position: tuple[float, float] | None = None,
        sharpness: float | None = None,
    ):
        if not isinstance(spots, Mapping) or len(spots) == 0:
            raise ValueError("spots must be a non-empty mapping {name: ((x, y), compass)}")
        names: list[str] = []
        positions: list[tuple[float, float]] = []
        compasses: list[VisualCompass] = []
        for name, entry in spots.items():
            try:
                pos, vc = entry
                x, y = (float(v) for v in pos)
            except (TypeError, ValueError):
                raise ValueError(
                    f"spot {name!r} must be ((x, y), VisualCompass), got {entry!r}"
                ) from None
            if not (math.isfinite(x) and math.isfinite(y)):
                raise ValueError(f"spot {name!r} position must be finite, got {(x, y)}")
            if not isinstance(vc, VisualCompass):
                raise ValueError(f"spot {name!r} needs a VisualCompass, got {type(vc).__name__}")
            names.append(str(name))
            positions.append((x, y))
            compasses.append(vc)
        configs = {vc.config for vc in compasses}
        if len(configs) > 1:
            raise ValueError("all compasses of an atlas must share one CompassConfig")
        self.names = tuple(names)
        self.positions = np.array(positions, dtype=np.float64)
        self.compasses = tuple(compasses)
        self.home = str(home)
        if home_position is None:
            if self.home in self.names:
                home_position = tuple(self.positions[self.names.index(self.home)])
            else:
                home_position = tuple(self.positions.mean(axis=0))
        hx, hy = (float(v) for v in home_position)
        if not (math.isfinite(hx) and math.isfinite(hy)):
            raise ValueError(f"home_position must be finite, got {home_position}")
        self.home_position = (hx, hy)
        c = compasses[0].config.n_colors
        self.sharpness = float(c * c if sharpness is None else sharpness)
        if not math.isfinite(self.sharpness) or self.sharpness <= 0:
            raise ValueError(f"sharpness must be finite and > 0, got {sharpness}")
        self._home_scores = np.zeros(len(names))
        self.is_normalized = False

    def __len__(self) -> int:
        return len(self.names)

    def scores(self, image: np.ndarray, camera: Camera) -> tuple[np.ndarray, list[CompassEstimate]]:
        """Raw per-spot scores (mean log-probability per term) and estimates."""
        ests = [vc.estimate(image, camera) for vc in self.compasses]
        return np.array([e.score for e in ests]), ests

    def normalize(self, images: Sequence[np.ndarray], cameras: Sequence[Camera]) -> np.ndarray:
        """Normalise the goodness so that every spot reports 1 at home (paper 5.2).

        Parameters
        ----------
        images, cameras : sequences of equal length
            Frames taken at the home spot (several headings recommended).

        Returns
        -------
        numpy.ndarray
            The mean home score of each spot (the normalisers, log domain).
        """
        if isinstance(images, np.ndarray) and images.ndim == 3:
            images = [images]
        if isinstance(cameras, Camera):
            cameras = [cameras]
        if len(images) == 0 or len(images) != len(cameras):
            raise ValueError(
                f"normalize needs as many cameras as images (>0), got {len(images)} images "
                f"and {len(cameras)} cameras"
            )
        scores = np.array(
            [self.scores(img, cam)[0] for img, cam in zip(images, cameras, strict=True)]
        )
        self._home_scores = scores.mean(axis=0)
        self.is_normalized = True
        return self._home_scores.copy()

    def estimate_position(self, image: np.ndarray, camera: Camera) -> AtlasEstimate:
        """Position from the goodness of every spot (eq. 28-30).

        ``L̂_i = exp(score_i - home_score_i)``, weights ``∝ L̂_i ** sharpness``,
        position ``= Σ w_i T_i``. Before :meth:`normalize` the home scores are zero.
        """
        if any(not vc.is_learned for vc in self.compasses):
            missing = [
                n for n, vc in zip(self.names, self.compasses, strict=True) if not vc.is_learned
            ]
            raise NotLearnedError(f"spots without a learned map: {missing}")
        raw, ests = self.scores(image, camera)
        rel = raw - self._home_scores
        logw = self.sharpness * rel
        w = np.exp(logw - logw.max())
        w /= w.sum()
        pos = w @ self.positions
        return AtlasEstimate(
            position=(float(pos[0]), float(pos[1])),
            goodness={n: float(math.exp(r)) for n, r in zip(self.names, rel, strict=True)},
            weights={n: float(v) for n, v in zip(self.names, w, strict=True)},
            estimates=dict(zip(self.names, ests, strict=True)),
        )
