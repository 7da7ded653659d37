"""Heading from ORB keypoints learned with the world direction they were seen at.

RoboCup humanoid teams tell their heading on a symmetric field from the background
beyond it: keypoints of the stands and walls, learned with the direction they lie in,
are matched in each new frame, and every match votes for the heading that puts the
stored direction under the matched pixel. :class:`FeatureCompass` does that with
OpenCV's ORB (Rublee et al., 2011) and a robust vote over the heading grid.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import cv2
import numpy as np

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass import Camera
from vc_gym.errors import NotLearnedError
from vc_gym.heading_sensors.base import BaselineCompass, FrameScore, check_camera
from vc_gym.images import check_image
from vc_gym.validation import int_at_least, int_in_range, open_fraction, positive_float

__all__ = ["FeatureCompass", "keypoint_directions"]

#: Bytes of an ORB descriptor.
DESCRIPTOR_BYTES = 32
#: Most keypoints ORB looks for in a frame, and most a learned map keeps (64 MB of
#: descriptors at the most).
MAX_FEATURES = 100_000
MAX_KEYPOINTS = 2_000_000
# OpenCV allocates a pyramid per level and a border of the patch size: beyond these a
# sensor file's parameters would ask it for gigabytes (10**6 levels: an allocation error)
_MAX_LEVELS = 32
_MAX_PATCH_SIZE = 255


def keypoint_directions(
    points: np.ndarray, camera: Camera, width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth offset (left positive, from the camera's yaw) and elevation of pixels.

    Parameters
    ----------
    points : numpy.ndarray
        ``(N, 2)`` pixel positions ``(u, v)`` (column, row; may be fractional).
    camera : Camera
        Intrinsics, principal point and pitch (its yaw is not used).
    width, height : int
        Image size.

    Returns
    -------
    offsets_deg, elevations_deg : numpy.ndarray
        ``(N,)`` each: the pixel's ray looks at world azimuth ``yaw + offset`` and at
        ``elevation`` above the horizon (docs/design.md's camera conventions; the offset is
        :meth:`Camera.column_offsets_deg` evaluated at the pixel's own row).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    u, v = pts[:, 0], pts[:, 1]
    cx, cy = camera.center(width, height)
    f = camera.focal_px(width)
    theta = math.radians(camera.pitch_deg)
    x = (u - cx) / f  # right
    y_up = (cy - v) / f  # up
    forward = math.cos(theta) - math.sin(theta) * y_up
    up = math.sin(theta) + math.cos(theta) * y_up
    offsets = -np.degrees(np.arctan2(x, forward))
    elevations = np.degrees(np.arctan2(up, np.hypot(forward, x)))
    return offsets, elevations


def _log_i0e(kappa: float) -> float:
    """``log(I0(kappa) * exp(-kappa))``, stable for large ``kappa``."""
    if kappa < 500.0:
        return float(math.log(np.i0(kappa)) - kappa)
    # asymptotic series of the modified Bessel function
    return -0.5 * math.log(2.0 * math.pi * kappa) + math.log1p(
        1.0 / (8.0 * kappa) + 9.0 / (128.0 * kappa**2)
    )


class FeatureCompass(BaselineCompass):
    """ORB keypoints learned with their world azimuth; matches vote for the heading.

    Parameters
    ----------
    n_features : int
        Most ORB keypoints detected per frame (learning and localising).
    fast_threshold : int
        FAST corner threshold (grey levels, 1-254). Low, so that the plain walls of the
        simulator's 208 x 160 frames still give keypoints.
    patch_size : int
        ORB patch size and border (pixels, 5-255): smaller keeps keypoints nearer the
        edges of small frames.
    n_levels : int
        Pyramid levels of the detector, 1-32 (a camera turning in place sees no change
        of scale, so few are needed). Both bounds keep a sensor file from asking
        OpenCV for gigabytes.
    scale_factor : float
        Pyramid scale step, ``> 1``.
    ratio : float
        Lowe's ratio test, ``0 < ratio <= 1``: a match is kept when its Hamming distance
        is below ``ratio`` times that of the nearest stored keypoint lying in another
        direction (stored keypoints in the same direction, the same feature learned
        from overlapping frames, are not a rival).
    sigma_deg : float
        Standard deviation of one match's heading vote (von Mises kernel,
        ``kappa = 1 / sigma_rad**2``).
    outlier_prob : float
        Prior probability, ``0 < p < 1``, that a match is wrong (its vote is then
        uniform over the circle).
    max_elevation_diff_deg : float
        A match whose stored and query elevations differ by more is dropped (the
        camera turns about a vertical axis, so a keypoint keeps its elevation).
    max_keypoints : int
        Largest number of keypoints the map holds; see Notes for the thinning policy.
        Matching is brute force, so the cost per frame grows with it: in robolab, a
        learning turn of 64 frames left 10,000 keypoints (8.6 ms a frame); thinned to
        4,000 the errors at 0, 1 and 2 m stayed the same (0.4°, 10°, 17°) at 4.2 ms.
    seed : int
        Seed of the thinning draws (``>= 0``).
    heading_step_deg : float
        Step of the candidate heading grid.

    Notes
    -----
    **Learning** a frame whose camera yaw is ``Y`` detects ORB keypoints on the grey
    image and stores each descriptor (32 bytes) with the world azimuth
    ``Y + offset(u, v)`` and the elevation of its pixel (:func:`keypoint_directions`,
    which handles pitch and principal point).

    **Log-likelihood.** A new frame's keypoints are matched with the map (brute-force
    Hamming k-nearest neighbours, as ``cv2.BFMatcher(NORM_HAMMING).knnMatch``) and
    filtered by the ratio test and the elevation gate. A good match ``m`` of a keypoint
    at azimuth offset ``a_m`` with a stored azimuth ``s_m`` says the heading is
    ``h_m = s_m - a_m``. Each match is a robust mixture: with probability
    ``1 - outlier_prob`` its vote is von Mises around ``h_m`` (``sigma_deg``), else
    uniform. The log-likelihood at heading ``h`` is

        ``ll(h) = w * sum_m log((1 - p) * 360 * vM(h; h_m, kappa) + p)``,

    the log of the likelihood *ratio* against a frame whose matches say nothing
    (each term is 0 for a uniform vote), so a frame with no match gives exactly
    zeros everywhere (a flat likelihood, never a confident one). Matches of one frame
    are not independent (they share the frame's calibration, parallax and
    mismatched repeated structures), so their evidence is tempered by
    ``w = 1 / sqrt(n)``: ``n`` good matches count as ``sqrt(n)`` independent votes.
    A clear 208 x 160 view (40-100 matches) then gets a posterior spread of about
    1 degree (its errors are mostly below half a degree), while a frame with a dozen
    matches of which a few happen to agree gets a spread of tens of degrees instead
    of a confident wrong heading. (Untempered, hundreds of matches would give a
    posterior narrower than the grid whatever the frame.)

    **Goodness** (:attr:`CompassEstimate.score`): the fraction of the frame's
    keypoints whose good match agrees with the best heading within
    ``2 * sigma_deg``, in ``[0, 1]`` (0 when the frame has no keypoint).
    ``n_terms`` is the number of good matches.

    **Map cap.** When a learned frame brings the map above ``max_keypoints``, it is
    thinned evenly in azimuth: keypoints are put in 1-degree azimuth bins and each
    bin keeps at most ``q`` of them, ``q`` the largest quota that fits (water
    filling), the remaining room going to randomly chosen bins; within a bin a random
    subset survives. The draws come from ``numpy.random.default_rng([seed,
    frames_learned])``, so the same frames in the same order give the same map, also
    across :meth:`save` / :meth:`load`.

    References
    ----------
    E. Rublee, V. Rabaud, K. Konolige, G. Bradski, "ORB: an efficient alternative to
    SIFT or SURF", ICCV 2011. D. G. Lowe, "Distinctive image features from
    scale-invariant keypoints", IJCV 2004 (ratio test). The RoboCup humanoid team
    Hamburg Bit-Bots' ``bitbots_visual_compass`` (ROS package, 2019) tags the ORB
    keypoints of the field's surroundings with the angle they were recorded at and
    matches new frames against them.
    """

    name = "feature"
    schema = "vc_gym.FeatureCompass"

    #: Neighbours fetched per query keypoint (the ratio test looks for the nearest
    #: one in another direction among them).
    n_neighbours = 4

    def __init__(
        self,
        n_features: int = 300,
        fast_threshold: int = 7,
        patch_size: int = 15,
        n_levels: int = 3,
        scale_factor: float = 1.2,
        ratio: float = 0.8,
        sigma_deg: float = 3.0,
        outlier_prob: float = 0.2,
        max_elevation_diff_deg: float = 5.0,
        max_keypoints: int = 4000,
        seed: int = 0,
        heading_step_deg: float = 1.0,
    ):
        super().__init__(heading_step_deg)
        self.n_features = int_in_range("n_features", n_features, 1, MAX_FEATURES)
        self.fast_threshold = int_at_least("fast_threshold", fast_threshold, 1)
        if self.fast_threshold > 254:
            raise ValueError(f"fast_threshold must be <= 254, got {fast_threshold}")
        self.patch_size = int_at_least("patch_size", patch_size, 5)
        if self.patch_size > _MAX_PATCH_SIZE:
            raise ValueError(f"patch_size must be <= {_MAX_PATCH_SIZE}, got {patch_size}")
        self.n_levels = int_at_least("n_levels", n_levels, 1)
        if self.n_levels > _MAX_LEVELS:
            raise ValueError(f"n_levels must be <= {_MAX_LEVELS}, got {n_levels}")
        self.scale_factor = positive_float("scale_factor", scale_factor)
        if not 1.0 < self.scale_factor <= 4.0:
            raise ValueError(f"scale_factor must be in (1, 4], got {scale_factor}")
        self.ratio = positive_float("ratio", ratio)
        if self.ratio > 1.0:
            raise ValueError(f"ratio must be in (0, 1], got {ratio}")
        self.sigma_deg = positive_float("sigma_deg", sigma_deg)
        if self.sigma_deg > 90.0:
            raise ValueError(f"sigma_deg must be <= 90, got {sigma_deg}")
        self.outlier_prob = open_fraction("outlier_prob", outlier_prob)
        self.max_elevation_diff_deg = positive_float(
            "max_elevation_diff_deg", max_elevation_diff_deg
        )
        self.max_keypoints = int_in_range("max_keypoints", max_keypoints, 1, MAX_KEYPOINTS)
        self.seed = int_at_least("seed", seed, 0)
        self._orb = self._make_orb()
        self._kappa = 1.0 / math.radians(self.sigma_deg) ** 2
        # 360 * (von Mises density per degree) = exp(kappa (cos d - 1)) / I0e(kappa)
        self._log_peak = -_log_i0e(self._kappa)
        self._descriptors = np.zeros((0, DESCRIPTOR_BYTES), dtype=np.uint8)
        self._azimuths = np.zeros(0, dtype=np.float64)
        self._elevations = np.zeros(0, dtype=np.float64)
        h = np.radians(self.headings_deg)
        self._heading_cs = np.stack([np.cos(h), np.sin(h)])  # (2, n_headings)

    # ------------------------------------------------------------------ properties
    @property
    def n_keypoints(self) -> int:
        """Number of keypoints in the map."""
        return int(self._azimuths.size)

    @property
    def descriptors(self) -> np.ndarray:
        """The map's ORB descriptors, ``(N, 32)`` uint8 (read-only view)."""
        d = self._descriptors.view()
        d.setflags(write=False)
        return d

    @property
    def azimuths_deg(self) -> np.ndarray:
        """World azimuth of each map keypoint in ``[0, 360)`` (read-only view)."""
        a = self._azimuths.view()
        a.setflags(write=False)
        return a

    @property
    def elevations_deg(self) -> np.ndarray:
        """Elevation of each map keypoint (read-only view)."""
        e = self._elevations.view()
        e.setflags(write=False)
        return e

    # ------------------------------------------------------------------ features
    def _make_orb(self) -> cv2.ORB:
        return cv2.ORB_create(
            nfeatures=self.n_features,
            scaleFactor=self.scale_factor,
            nlevels=self.n_levels,
            edgeThreshold=self.patch_size,
            patchSize=self.patch_size,
            fastThreshold=self.fast_threshold,
        )

    def __getstate__(self) -> dict[str, Any]:
        # an OpenCV detector does not pickle: rebuild it from the config
        state = self.__dict__.copy()
        del state["_orb"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._orb = self._make_orb()

    def _detect(
        self, image: np.ndarray, camera: Camera
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """ORB descriptors ``(K, 32)`` of a checked frame, with each keypoint's azimuth
        offset from the yaw (left positive) and elevation, ``(K,)`` each."""
        grey = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
        keypoints, desc = self._orb.detectAndCompute(grey, None)
        if desc is None or len(keypoints) == 0:
            empty = np.zeros(0, dtype=np.float64)
            return np.zeros((0, DESCRIPTOR_BYTES), dtype=np.uint8), empty, empty.copy()
        pts = cv2.KeyPoint_convert(keypoints).astype(np.float64)
        h, w = image.shape[:2]
        offsets, elevations = keypoint_directions(pts, camera, w, h)
        return np.ascontiguousarray(desc, dtype=np.uint8), offsets, elevations

    # ------------------------------------------------------------------ learning
    def _learn(self, image: np.ndarray, camera: Camera) -> None:
        desc, offsets, elevations = self._detect(image, camera)
        if desc.shape[0] == 0:
            return
        # one contiguous array: the brute-force matcher reads it as is
        self._descriptors = np.ascontiguousarray(np.concatenate([self._descriptors, desc]))
        self._azimuths = np.concatenate([self._azimuths, wrap360(camera.yaw_deg + offsets)])
        self._elevations = np.concatenate([self._elevations, elevations])
        if self._azimuths.size > self.max_keypoints:
            rng = np.random.default_rng([self.seed, self.frames_learned])
            keep = _thin_by_azimuth(self._azimuths, self.max_keypoints, rng)
            self._descriptors = np.ascontiguousarray(self._descriptors[keep])
            self._azimuths = self._azimuths[keep]
            self._elevations = self._elevations[keep]

    # ------------------------------------------------------------------ scoring
    def match(self, image: np.ndarray, camera: Camera) -> tuple[np.ndarray, int]:
        """The heading votes of a frame's good matches (what :meth:`log_likelihood`
        is built from).

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` uint8 RGB.
        camera : Camera
            Intrinsics and pitch (the yaw is ignored).

        Returns
        -------
        votes_deg : numpy.ndarray
            ``(M,)`` heading in ``[0, 360)`` each good match implies,
            ``h_m = stored azimuth - offset of the frame's keypoint``.
        n_keypoints : int
            Number of keypoints detected in the frame.

        Raises
        ------
        NotLearnedError
            Before the first :meth:`learn`.
        """
        check_image(image)
        check_camera(camera)
        if not self.is_learned:
            raise NotLearnedError(f"{type(self).__name__} has learned no frame yet")
        return self._votes(image, camera)

    def _votes(self, image: np.ndarray, camera: Camera) -> tuple[np.ndarray, int]:
        desc, offsets, elevations = self._detect(image, camera)
        n_query = desc.shape[0]
        n_map = self._azimuths.size
        if n_query == 0 or n_map == 0:
            return np.zeros(0, dtype=np.float64), n_query
        k = min(self.n_neighbours, n_map)
        # brute-force Hamming kNN: what cv2.BFMatcher(NORM_HAMMING).knnMatch computes
        # (it calls batchDistance), as arrays instead of lists of DMatch objects
        dist, idx = cv2.batchDistance(
            desc, self._descriptors, cv2.CV_32S, normType=cv2.NORM_HAMMING, K=k
        )
        best = idx[:, 0]
        passes = np.abs(elevations - self._elevations[best]) <= self.max_elevation_diff_deg
        if k > 1:
            az = self._azimuths[idx]  # (Q, k)
            el = self._elevations[idx]
            # a neighbour is a rival when it lies in another direction than the best one;
            # the same feature learned from overlapping frames is no ambiguity
            rival = (np.abs(wrap180(az[:, 1:] - az[:, :1])) > 2.0 * self.sigma_deg) | (
                np.abs(el[:, 1:] - el[:, :1]) > self.max_elevation_diff_deg
            )
            first = np.argmax(rival, axis=1) + 1
            rival_dist = dist[np.arange(n_query), first].astype(np.float64)
            passes &= ~rival.any(axis=1) | (dist[:, 0] < self.ratio * rival_dist)
        votes = wrap360(self._azimuths[best[passes]] - offsets[passes])
        return np.atleast_1d(np.asarray(votes, dtype=np.float64)), n_query

    def _score(self, image: np.ndarray, camera: Camera) -> FrameScore:
        votes, n_query = self._votes(image, camera)
        n = votes.size
        if n == 0:
            return FrameScore(np.zeros(self.headings_deg.size), 0.0, 0)
        v = np.radians(votes)
        cos_d = np.stack([np.cos(v), np.sin(v)], axis=1) @ self._heading_cs  # (M, H)
        log_kernel = math.log1p(-self.outlier_prob) + self._log_peak + self._kappa * (cos_d - 1.0)
        terms = np.logaddexp(log_kernel, math.log(self.outlier_prob))
        weight = 1.0 / math.sqrt(n)  # n matches count as sqrt(n) independent votes
        ll = weight * terms.sum(axis=0)
        best_heading = self.headings_deg[int(np.argmax(ll))]
        agree = np.abs(wrap180(votes - best_heading)) <= 2.0 * self.sigma_deg
        return FrameScore(ll, float(np.sum(agree)) / n_query, n)

    # ------------------------------------------------------------------ persistence
    def _config(self) -> dict[str, Any]:
        return {
            "n_features": self.n_features,
            "fast_threshold": self.fast_threshold,
            "patch_size": self.patch_size,
            "n_levels": self.n_levels,
            "scale_factor": self.scale_factor,
            "ratio": self.ratio,
            "sigma_deg": self.sigma_deg,
            "outlier_prob": self.outlier_prob,
            "max_elevation_diff_deg": self.max_elevation_diff_deg,
            "max_keypoints": self.max_keypoints,
            "seed": self.seed,
            "heading_step_deg": self.heading_step_deg,
        }

    def _map_arrays(self) -> dict[str, np.ndarray]:
        return {
            "descriptors": self._descriptors.copy(),
            "azimuths_deg": self._azimuths.copy(),
            "elevations_deg": self._elevations.copy(),
        }

    def _from_map_arrays(self, arrays: Mapping[str, np.ndarray]) -> None:
        desc = np.asarray(arrays["descriptors"])
        if desc.dtype != np.uint8 or desc.ndim != 2 or desc.shape[1] != DESCRIPTOR_BYTES:
            raise ValueError(
                f"descriptors must be uint8 of shape (N, {DESCRIPTOR_BYTES}), "
                f"got {desc.dtype} {desc.shape}"
            )
        n = desc.shape[0]
        if n > self.max_keypoints:
            raise ValueError(
                f"descriptors holds {n} keypoints, max_keypoints is {self.max_keypoints}"
            )
        out = {}
        for key in ("azimuths_deg", "elevations_deg"):
            a = np.asarray(arrays[key])
            if a.dtype.kind != "f" or a.shape != (n,):
                raise ValueError(
                    f"{key} must be a float array of shape ({n},), got {a.dtype} {a.shape}"
                )
            if not np.all(np.isfinite(a)):
                raise ValueError(f"{key} holds non-finite values")
            out[key] = a.astype(np.float64)
        if np.any((out["azimuths_deg"] < 0.0) | (out["azimuths_deg"] >= 360.0)):
            raise ValueError("azimuths_deg must lie in [0, 360)")
        if np.any(np.abs(out["elevations_deg"]) >= 90.0):
            raise ValueError("elevations_deg must lie in (-90, 90)")
        self._descriptors = np.ascontiguousarray(desc)
        self._azimuths = out["azimuths_deg"]
        self._elevations = out["elevations_deg"]


def _thin_by_azimuth(azimuths: np.ndarray, cap: int, rng: np.random.Generator) -> np.ndarray:
    """Indices (sorted) of at most ``cap`` keypoints, spread evenly over 1-degree bins."""
    n = azimuths.size
    bins = np.minimum(np.floor(azimuths).astype(np.int64), 359)
    counts = np.bincount(bins, minlength=360)
    # largest quota q with sum(min(counts, q)) <= cap (water filling)
    sorted_counts = np.sort(counts)
    below = np.concatenate([[0], np.cumsum(sorted_counts)])  # sum of the smallest i
    q_candidates = np.arange(sorted_counts[-1] + 1)
    n_below = np.searchsorted(sorted_counts, q_candidates, side="left")
    filled = below[n_below] + q_candidates * (360 - n_below)
    q = int(q_candidates[filled <= cap][-1])
    spare = cap - int(np.minimum(counts, q).sum())
    # a random rank of each keypoint within its bin
    order = np.lexsort((rng.random(n), bins))
    first_of_bin = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n) - first_of_bin[bins[order]]
    quota = np.minimum(counts, q)
    fuller = np.flatnonzero(counts > q)
    lucky = rng.choice(fuller, size=min(spare, fuller.size), replace=False)
    quota[lucky] += 1
    return np.flatnonzero(rank < quota[bins])
