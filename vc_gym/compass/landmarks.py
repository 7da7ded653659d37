"""Landmarks: the colour-class changes of the learned turns, placed in the room.

The learning phase turns on the spot at several known positions (home, the spots and,
in the ``pose-home`` mode, 0.5 m around each). A colour change on a wall (a door frame,
a poster's side) is seen by each of those turns at another bearing
(:func:`~vc_gym.compass.bearings.frame_bearings`); rays from two positions cross at the
change itself. :func:`learn_landmarks` finds, for every colour pair, the points where the
rays of at least ``min_positions`` positions cross within ``tolerance_deg`` (greedily,
the best supported first; a ray serves one landmark), and places each by weighted least
squares on its rays, with the covariance that the rays' angular scatter gives.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from vc_gym.angles import wrap_pi
from vc_gym.compass.bearings import DEFAULT_BAND_DEG, MAX_BANDS, FrameBearings, check_bands
from vc_gym.exposure import MAX_GAIN_STOPS
from vc_gym.validation import (
    MAX_ABS_METRES,
    finite_float,
    int_at_least,
    open_fraction,
    positive_float,
)

__all__ = [
    "MAX_CANDIDATES",
    "MAX_LANDMARKS",
    "LandmarkMap",
    "LearnedView",
    "eye_positions",
    "learn_landmarks",
]

#: Most landmarks a map file may hold (a room's colour edges number in the hundreds).
MAX_LANDMARKS = 100_000
#: A cloud of poses is scored in two groups, its core (within this distance of its median
#: position, m, and :data:`CORE_DEG` of its mean direction) and the rest.
CORE_M = 0.3
CORE_DEG = 10.0
#: The entries of a landmark map in a map file (see :meth:`LandmarkMap.to_arrays`).
_KEYS = ("positions", "pairs", "std_m", "support")


def _check_camera_poses(xy: object, yaw_rad: object) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 2)`` finite positions and ``(N,)`` finite directions, else a ``ValueError``."""
    xy_a = np.asarray(xy, dtype=np.float64)
    yaw_a = np.asarray(yaw_rad, dtype=np.float64)
    if xy_a.ndim != 2 or xy_a.shape[1] != 2 or yaw_a.shape != (xy_a.shape[0],):
        raise ValueError(
            f"positions must be (N, 2) and directions (N,), got {xy_a.shape} and {yaw_a.shape}"
        )
    if not (np.all(np.isfinite(xy_a)) and np.all(np.isfinite(yaw_a))):
        raise ValueError("positions and directions must be finite")
    return xy_a, yaw_a


def eye_positions(
    body_xy: np.ndarray, body_yaw_rad: np.ndarray, eye_forward_m: float
) -> np.ndarray:
    """``(N, 2)`` camera positions of bodies at ``body_xy`` (``(N, 2)``, m) heading
    ``body_yaw_rad`` (``(N,)``): the camera sits ``eye_forward_m`` ahead of the body's
    centre, along its heading (a pan turns the camera, not where it is)."""
    body_xy, body_yaw_rad = _check_camera_poses(body_xy, body_yaw_rad)
    eye_forward_m = finite_float("eye_forward_m", eye_forward_m)
    return body_xy + eye_forward_m * np.stack([np.cos(body_yaw_rad), np.sin(body_yaw_rad)], 1)


@dataclass(frozen=True)
class LearnedView:
    """One learning frame's changes, seen from a known pose.

    Attributes
    ----------
    bearings : FrameBearings
        The frame's changes (offsets relative to the camera's yaw).
    camera_yaw_deg : float
        World direction of the camera's optical axis (body heading plus head pan).
    x, y : float
        Where the frame was taken (m).
    """

    bearings: FrameBearings
    camera_yaw_deg: float
    x: float
    y: float


@dataclass(frozen=True)
class LandmarkMap:
    """Colour changes placed in the room.

    Attributes
    ----------
    positions : numpy.ndarray
        ``(M, 2)`` landmark positions (m).
    pairs : numpy.ndarray
        ``(M,)`` band and colour-pair code of each (:attr:`FrameBearings.pairs`: the
        classes as the camera sees them from inside the room).
    std_m : numpy.ndarray
        ``(M,)`` position uncertainty, the root mean square of the covariance's axes.
    support : numpy.ndarray
        ``(M,)`` how many learning positions saw it.
    n_colors : int
        Number of colour classes of the map.
    eye_forward_m : float
        How far ahead of the body's centre the camera that learned the map sat (a
        sensor predicts bearings from there for a body pose).
    bands : tuple of (float, float)
        The bands the changes were read in (:func:`~vc_gym.compass.bearings.bands_bearings`).
    light_gain : float
        The light of the learning frames, as the gain that brings them to the colour
        classes' reference level (:class:`~vc_gym.exposure.SessionLight` of their
        per-frame gains; 1 when unknown). Their changes were read without a gain, so a
        later frame is read at its session's gain divided by this one.
    """

    positions: np.ndarray
    pairs: np.ndarray
    std_m: np.ndarray
    support: np.ndarray
    n_colors: int
    eye_forward_m: float = 0.0
    bands: tuple[tuple[float, float], ...] = (DEFAULT_BAND_DEG,)
    light_gain: float = 1.0

    def __len__(self) -> int:
        return int(self.pairs.size)

    def log_likelihood(
        self,
        bearings: FrameBearings,
        eye_xy: np.ndarray,
        camera_yaw_rad: np.ndarray,
        noise_rad: float,
        outlier: float,
    ) -> np.ndarray:
        """``log p(changes | camera pose)`` up to a constant, for ``N`` camera poses.

        Each change of ``bearings`` is explained by the landmark of its colour pair whose
        predicted offset is nearest (a Gaussian of ``noise_rad`` and the landmark's own
        uncertainty seen from its distance; landmarks outside the field of view explain
        nothing), or by nothing with the density floor ``outlier``; the changes' terms
        add up (the outlier-robust form of eq. 16 with bearings).

        Parameters
        ----------
        bearings : FrameBearings
            The frame's changes.
        eye_xy : numpy.ndarray
            ``(N, 2)`` camera positions (m).
        camera_yaw_rad : numpy.ndarray
            ``(N,)`` directions of the optical axis (radians, CCW from ``+x``).
        noise_rad : float
            σ of an observed change's bearing.
        outlier : float
            Density floor relative to a perfect match, in ``(0, 1)``.

        Returns
        -------
        numpy.ndarray
            ``(N,)`` log-likelihoods; zeros when the frame shows no change.
        """
        eye_xy, camera_yaw_rad = _check_camera_poses(eye_xy, camera_yaw_rad)
        noise_rad = positive_float("noise_rad", noise_rad)
        outlier = open_fraction("outlier", outlier)
        total = np.zeros(len(eye_xy))
        if len(bearings) == 0:
            return total
        if tuple(bearings.bands) != tuple(self.bands) or bearings.n_colors != self.n_colors:
            raise ValueError(
                f"the frame's changes were read in bands {bearings.bands} with "
                f"{bearings.n_colors} colours, the map's in {self.bands} with {self.n_colors}"
            )
        half = math.radians(bearings.hfov_deg) / 2.0
        log_floor = math.log(outlier)
        landmark, change = self.candidates(bearings.pairs)
        n_matched = int(np.count_nonzero(np.bincount(change, minlength=len(bearings))))
        total += log_floor * (len(bearings) - n_matched)
        if n_matched == 0:
            return total
        offsets = np.radians(bearings.offsets_deg)
        # a tracker's cloud is tight but for a few particles drawn afresh far away, which
        # would widen the reach of every pose: those are scored apart
        out = np.empty(len(eye_xy))
        for poses in _pose_groups(eye_xy, camera_yaw_rad):
            out[poses] = self._candidates_score(
                landmark, change, offsets, eye_xy[poses], camera_yaw_rad[poses],
                noise_rad, half, log_floor, n_matched,
            )  # fmt: skip
        return total + out

    def candidates(self, pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every (landmark, change) of one band and colour pair, for changes with pair
        codes ``pairs`` (:attr:`FrameBearings.pairs`).

        Returns
        -------
        landmark, change : numpy.ndarray
            ``(C,)`` landmark indices and ``(C,)`` indices into ``pairs``, grouped by
            change in order (a change no landmark shares has none).
        """
        order = np.argsort(self.pairs, kind="stable")
        sorted_pairs = self.pairs[order]
        lo = np.searchsorted(sorted_pairs, pairs, side="left")
        count = np.searchsorted(sorted_pairs, pairs, side="right") - lo
        return order[_gather(lo, lo + count)], np.repeat(np.arange(len(pairs)), count)

    def _candidates_score(
        self,
        landmark: np.ndarray,
        change: np.ndarray,
        offsets: np.ndarray,
        eye_xy: np.ndarray,
        camera_yaw_rad: np.ndarray,
        noise_rad: float,
        half: float,
        log_floor: float,
        n_matched: int,
    ) -> np.ndarray:
        """The matched changes' terms at the poses, from the candidates ``(landmark,
        change)`` (grouped by change) of :meth:`log_likelihood`."""
        # drop the candidates that miss by so much from every pose that their term is
        # below the floor by more than e^20 (the answer changes by less than 1e-8)
        keep = self._within_reach(landmark, offsets[change], eye_xy, camera_yaw_rad,
                                  noise_rad, half, log_floor)  # fmt: skip
        landmark, change = landmark[keep], change[keep]
        changes, c = np.unique(change, return_counts=True)
        total = np.full(len(eye_xy), log_floor * (n_matched - changes.size))
        if changes.size == 0:
            return total
        first = np.cumsum(c) - c
        # every candidate from every pose, in the camera's frame: (N, C) (a landmark
        # rarely explains two changes of a frame, so nothing is shared per landmark)
        px, py = self.positions[landmark, 0], self.positions[landmark, 1]
        cos_yaw, sin_yaw = np.cos(camera_yaw_rad)[:, None], np.sin(camera_yaw_rad)[:, None]
        dx = px[None, :] - eye_xy[:, 0:1]
        dy = py[None, :] - eye_xy[:, 1:2]
        ahead = dx * cos_yaw
        ahead += dy * sin_yaw
        left = dy
        left *= cos_yaw
        left -= dx * sin_yaw
        predicted = np.arctan2(left, ahead)
        # var = noise^2 + (std / distance)^2; score = -err^2 / (2 var) - log(var / noise^2) / 2
        ratio = np.square(ahead, out=ahead)
        ratio += np.square(left, out=left)
        np.maximum(ratio, 0.0025, out=ratio)
        np.divide((self.std_m[landmark] / noise_rad)[None, :] ** 2, ratio, out=ratio)
        ratio += 1.0  # var / noise^2
        # an offset and a prediction both in view differ by less than the field of view,
        # so only a wide view wraps
        err = offsets[change][None, :] - predicted
        if half >= math.pi / 2:
            err = wrap_pi(err)
        score = np.square(err / noise_rad, out=err)
        score /= ratio
        score += np.log(ratio)
        score *= -0.5
        score[np.abs(predicted) > half] = -np.inf  # a landmark out of view explains nothing
        best = np.maximum.reduceat(score, first, axis=1)  # (N, matched changes)
        return total + np.logaddexp(best, log_floor).sum(axis=1)

    def _within_reach(
        self,
        landmark: np.ndarray,
        offset: np.ndarray,
        eye_xy: np.ndarray,
        camera_yaw_rad: np.ndarray,
        noise_rad: float,
        half: float,
        log_floor: float,
    ) -> np.ndarray:
        """Which candidates ``(landmark, observed offset)`` may score within e^20 of the
        floor from some pose: a bound from the poses' centre, their spread in direction
        and in position (which turns a landmark's bearing by at most ``asin(r / d)``)."""
        centre = eye_xy.mean(axis=0)
        yaw = math.atan2(float(np.sin(camera_yaw_rad).sum()), float(np.cos(camera_yaw_rad).sum()))
        turn = float(np.max(np.abs(wrap_pi(camera_yaw_rad - yaw))))
        shift = float(np.max(np.hypot(*(eye_xy - centre).T)))
        d = self.positions[landmark] - centre
        dist = np.hypot(d[:, 0], d[:, 1])
        near = np.maximum(dist - shift, 1e-9)
        reach = turn + np.where(dist > shift, np.arcsin(np.minimum(shift / near, 1.0)), np.pi)
        sigma = np.sqrt(noise_rad**2 + (self.std_m[landmark] / np.maximum(near, 0.05)) ** 2)
        # a score below log_floor - 20 needs |err| > sqrt(2 (20 - log_floor)) sigma
        gate = reach + math.sqrt(2.0 * (20.0 - log_floor)) * sigma
        predicted = wrap_pi(np.arctan2(d[:, 1], d[:, 0]) - yaw)
        return (np.abs(wrap_pi(offset - predicted)) <= gate) & (np.abs(predicted) <= half + reach)

    def to_arrays(self, prefix: str = "landmarks/") -> dict[str, np.ndarray]:
        """The map as plain arrays (for a map file), keys ``prefix + name``."""
        return {
            f"{prefix}positions": self.positions.astype(np.float64),
            f"{prefix}pairs": self.pairs.astype(np.int64),
            f"{prefix}std_m": self.std_m.astype(np.float64),
            f"{prefix}support": self.support.astype(np.int64),
            f"{prefix}eye_forward_m": np.array(self.eye_forward_m, np.float64),
            f"{prefix}bands": np.array(self.bands, np.float64).reshape(-1, 2),
            f"{prefix}light_gain": np.array(self.light_gain, np.float64),
        }

    @classmethod
    def from_arrays(
        cls, arrays: dict[str, np.ndarray], n_colors: int, prefix: str = "landmarks/"
    ) -> LandmarkMap:
        """Check and rebuild what :meth:`to_arrays` wrote.

        Raises
        ------
        ValueError
            On a missing entry, a wrong shape or dtype, more than :data:`MAX_LANDMARKS`,
            positions beyond ±``MAX_ABS_METRES`` or not finite, a pair code outside the
            ``n_colors`` classes, a negative or non-finite uncertainty, a support
            below 2, a camera offset that is not one number within ±1 m (a map
            without one has the camera at the body's centre), or bands that are not 1 to
            ``MAX_BANDS`` pairs of elevations (a map without them: the one default band),
            or a learning light that is not one number within ±``MAX_GAIN_STOPS`` stops
            (a map without one: 1).
        """
        missing = [k for k in _KEYS if prefix + k not in arrays]
        if missing:
            raise ValueError(f"landmark entries missing: {', '.join(prefix + k for k in missing)}")
        pos, pairs, std, support = (np.asarray(arrays[prefix + k]) for k in _KEYS)
        m = pairs.shape[0] if pairs.ndim == 1 else -1
        if not 0 <= m <= MAX_LANDMARKS:
            raise ValueError(f"landmark pairs must be a vector of at most {MAX_LANDMARKS}")
        if pos.shape != (m, 2) or std.shape != (m,) or support.shape != (m,):
            raise ValueError(f"landmark entries disagree on their count ({m})")
        if pos.dtype.kind != "f" or std.dtype.kind != "f":
            raise ValueError("landmark positions and std_m must be floats")
        if pairs.dtype.kind not in "iu" or support.dtype.kind not in "iu":
            raise ValueError("landmark pairs and support must be integers")
        if not np.all(np.isfinite(pos)) or np.any(np.abs(pos) > MAX_ABS_METRES):
            raise ValueError(f"landmark positions must be finite and within ±{MAX_ABS_METRES:g} m")
        raw_bands = np.asarray(arrays.get(prefix + "bands", np.array([DEFAULT_BAND_DEG])))
        if raw_bands.dtype.kind != "f" or raw_bands.ndim != 2 or raw_bands.shape[1] != 2:
            raise ValueError("landmark bands must be (B, 2) float elevations")
        if not 1 <= len(raw_bands) <= MAX_BANDS:
            raise ValueError(f"landmark bands must number 1 to {MAX_BANDS}")
        bands = check_bands(raw_bands.tolist())
        if np.any(pairs < 0) or np.any(pairs >= len(bands) * n_colors * n_colors):
            raise ValueError(
                f"landmark pair codes must name one of {len(bands)} bands and two of "
                f"{n_colors} colour classes"
            )
        if not np.all(np.isfinite(std)) or np.any(std < 0):
            raise ValueError("landmark std_m must be finite and non-negative")
        if np.any(support < 2):
            raise ValueError("a landmark is seen from at least 2 positions")
        eye = np.asarray(arrays.get(prefix + "eye_forward_m", 0.0))
        if eye.shape != () or eye.dtype.kind != "f" or not abs(float(eye)) <= 1.0:
            raise ValueError("landmark eye_forward_m must be one float within ±1 m")
        light = np.asarray(arrays.get(prefix + "light_gain", 1.0))
        if light.shape != () or light.dtype.kind != "f" or not _is_gain(float(light)):
            raise ValueError(
                f"landmark light_gain must be one float within ±{MAX_GAIN_STOPS} stops of 1"
            )
        return cls(
            pos.astype(np.float64), pairs.astype(np.int64), std.astype(np.float64),
            support.astype(np.int64), int(n_colors), float(eye), bands, float(light),
        )  # fmt: skip


def _pose_groups(eye_xy: np.ndarray, camera_yaw_rad: np.ndarray) -> list[np.ndarray]:
    """The poses within :data:`CORE_M` and :data:`CORE_DEG` of their median position and
    mean direction, and the rest (one group when either is empty)."""
    centre = np.median(eye_xy, axis=0)
    yaw = math.atan2(float(np.sin(camera_yaw_rad).sum()), float(np.cos(camera_yaw_rad).sum()))
    core = (np.hypot(*(eye_xy - centre).T) <= CORE_M) & (
        np.abs(wrap_pi(camera_yaw_rad - yaw)) <= math.radians(CORE_DEG)
    )
    if core.all() or not core.any():
        return [np.arange(len(eye_xy))]
    return [np.flatnonzero(core), np.flatnonzero(~core)]


def _is_gain(gain: float) -> bool:
    """A finite gain > 0 within ±MAX_GAIN_STOPS stops of 1."""
    return math.isfinite(gain) and gain > 0 and abs(math.log2(gain)) <= MAX_GAIN_STOPS


def _rays(views: Iterable[LearnedView]) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, tuple]:
    """Every change of every view as a world ray: origins (R, 2), bearings (R,) in
    radians, pair codes (R,); the number of colours and the bands."""
    origins, angles, pairs, n_colors, bands = [], [], [], None, None
    for v in views:
        b = v.bearings
        if n_colors is None:
            n_colors, bands = b.n_colors, tuple(b.bands)
        elif b.n_colors != n_colors or tuple(b.bands) != bands:
            raise ValueError("the views' bearings use different colour classes or bands")
        if not all(math.isfinite(t) for t in (v.camera_yaw_deg, v.x, v.y)):
            raise ValueError(f"a view's pose must be finite, got {(v.x, v.y, v.camera_yaw_deg)}")
        origins.append(np.broadcast_to([v.x, v.y], (len(b), 2)))
        angles.append(np.radians(v.camera_yaw_deg + b.offsets_deg))
        pairs.append(b.pairs)
    if n_colors is None:
        raise ValueError("no views to learn landmarks from")
    cat = np.concatenate
    return cat(origins).astype(np.float64), cat(angles), cat(pairs), n_colors, bands


def _merge_repeats(o: np.ndarray, a: np.ndarray, merge: float) -> tuple[np.ndarray, np.ndarray]:
    """One ray per edge and viewpoint: rays from origins within a centimetre whose
    bearings lie within ``merge`` radians of each other in a chain (the frames of one
    direction, with the head scanning, see an edge many times) become their mean."""
    keys = np.round(o / 0.01).astype(np.int64)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = group.reshape(-1)
    order = np.lexsort((a, group))
    g, angles = group[order], a[order]
    # a run ends where the viewpoint changes or the next bearing is more than merge on
    starts = np.flatnonzero(np.r_[True, (np.diff(g) != 0) | (np.diff(angles) > merge)])
    counts = np.diff(np.r_[starts, len(order)])
    origins = np.add.reduceat(o[order], starts, axis=0) / counts[:, None]
    mean_angle = np.angle(np.add.reduceat(np.exp(1j * angles), starts))
    return origins.astype(np.float64).reshape(-1, 2), mean_angle.astype(np.float64)


#: Most candidate crossings drawn at once for one colour pair (pairs of rays beyond
#: this are drawn at random, seeded, and drawn again once those are used up): bounds
#: the memory and time a map with many rays needs.
MAX_CANDIDATES = 20_000
#: Most candidate x ray entries tested at once.
_CHUNK = 2_000_000


def _intersections(
    o: np.ndarray, a: np.ndarray, min_angle: float, max_range: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """Points where two rays of different origins cross in front of both (at most
    :data:`MAX_CANDIDATES` pairs of rays, drawn at random when there are more): the
    points, the two rays of each and whether they were drawn."""
    n = len(a)
    drawn = n * (n - 1) // 2 > MAX_CANDIDATES
    if not drawn:
        i, j = np.triu_indices(n, k=1)
    else:
        i, j = rng.integers(0, n, (2, MAX_CANDIDATES))
        keep = i != j
        i, j = i[keep], j[keep]
    d = np.stack([np.cos(a), np.sin(a)], axis=1)
    cross = d[i, 0] * d[j, 1] - d[i, 1] * d[j, 0]
    ok = (np.abs(cross) > math.sin(min_angle)) & (np.hypot(*(o[i] - o[j]).T) > 1e-6)
    i, j, cross = i[ok], j[ok], cross[ok]
    w = o[j] - o[i]
    t = (w[:, 0] * d[j, 1] - w[:, 1] * d[j, 0]) / cross
    s = (w[:, 0] * d[i, 1] - w[:, 1] * d[i, 0]) / cross
    front = (t > 0.05) & (s > 0.05) & (t < max_range) & (s < max_range)
    i, j, t = i[front], j[front], t[front]
    return o[i] + t[:, None] * d[i], i, j, drawn


def _sightings(points: np.ndarray, o: np.ndarray, a: np.ndarray, tol: float) -> tuple:
    """Which rays see which points (the angle between the ray and the direction from its
    origin to the point below ``tol``, tested without trigonometry), in chunks: the
    ``(point, ray)`` index pairs, sorted by point."""
    # single precision: a centimetre in a room is far above its rounding
    dx, dy = np.cos(a).astype(np.float32), np.sin(a).astype(np.float32)
    ox, oy = o[:, 0].astype(np.float32), o[:, 1].astype(np.float32)
    tan_tol = np.float32(math.tan(tol))
    chunk = max(1, _CHUNK // max(len(a), 1))
    rows, cols = [], []
    for start in range(0, len(points), chunk):
        p = points[start : start + chunk].astype(np.float32)
        tx = p[:, 0:1] - ox[None, :]
        ty = p[:, 1:2] - oy[None, :]
        along = tx * dx + ty * dy
        r, c = np.nonzero((along > 0) & (np.abs(tx * dy - ty * dx) < tan_tol * along))
        rows.append(r + start)
        cols.append(c)
    return np.concatenate(rows), np.concatenate(cols)


def _gather(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """The indices of every range ``[starts[k], ends[k])``, concatenated."""
    lengths = ends - starts
    offsets = np.cumsum(lengths) - lengths
    return np.arange(int(lengths.sum())) - np.repeat(offsets - starts, lengths)


def _greedy_round(
    points: np.ndarray,
    makers: tuple[np.ndarray, np.ndarray],
    o: np.ndarray,
    a: np.ndarray,
    where: np.ndarray,
    free: np.ndarray,
    tol: float,
    min_positions: int,
) -> list[tuple[int, np.ndarray]]:
    """Take, while one is seen from ``min_positions`` distinct positions, the candidate
    seen from the most (by the rays still ``free``, which it then uses up); a candidate
    made by a used ray is dropped. Returns each taken candidate's support and rays.

    The sightings are found once; taking a candidate only updates the counts of the
    candidates that shared its rays."""
    idx = np.flatnonzero(free)
    cand, col = _sightings(points, o[idx], a[idx], tol)
    ray = idx[col]
    n_pos = int(where.max()) + 1
    units, unit_of = np.unique(cand * n_pos + where[ray], return_inverse=True)
    unit_of = unit_of.reshape(-1)
    rays_in_unit = np.bincount(unit_of, minlength=len(units))
    unit_cand = units // n_pos
    support = np.bincount(unit_cand, minlength=len(points))
    cand_start = np.searchsorted(cand, np.arange(len(points) + 1))
    by_ray = np.argsort(ray, kind="stable")
    ray_start = np.searchsorted(ray[by_ray], np.arange(len(a) + 1))
    dead = np.zeros(len(points), bool)
    taken = []
    while True:
        k = int(np.argmax(np.where(dead, -1, support)))
        if dead[k] or support[k] < min_positions:
            return taken
        rays = ray[cand_start[k] : cand_start[k + 1]]
        rays = rays[free[rays]]
        taken.append((int(support[k]), rays))
        free[rays] = False
        entries = by_ray[_gather(ray_start[rays], ray_start[rays + 1])]
        hit = unit_of[entries]
        np.subtract.at(rays_in_unit, hit, 1)
        emptied = np.sort(hit[rays_in_unit[hit] == 0])  # each emptied unit once
        emptied = emptied[np.r_[True, emptied[1:] != emptied[:-1]]]
        np.subtract.at(support, unit_cand[emptied], 1)
        dead |= ~free[makers[0]] | ~free[makers[1]]


def _fit(o: np.ndarray, a: np.ndarray, floor_rad: float) -> tuple[np.ndarray, float]:
    """Weighted least-squares point nearest the rays (perpendicular distance over range),
    twice (the ranges from the first answer), and its RMS position uncertainty."""
    normal = np.stack([-np.sin(a), np.cos(a)], axis=1)
    weights = np.ones(len(a))
    point = np.zeros(2)
    for _ in range(2):
        A = normal * weights[:, None]
        c = np.sum(normal * o, axis=1) * weights
        point = np.linalg.lstsq(A, c, rcond=None)[0]
        weights = 1.0 / np.maximum(np.hypot(*(point - o).T), 0.1)
    A = normal * weights[:, None]
    residual = A @ point - np.sum(normal * o, axis=1) * weights  # radians, about
    dof = max(len(a) - 2, 1)
    sigma = max(math.sqrt(float(residual @ residual) / dof), floor_rad)
    cov = sigma**2 * np.linalg.pinv(A.T @ A)
    return point, math.sqrt(max(float(np.trace(cov)) / 2.0, 0.0))


def learn_landmarks(
    views: Iterable[LearnedView],
    min_positions: int = 3,
    tolerance_deg: float = 1.0,
    min_angle_deg: float = 2.0,
    max_range_m: float = 20.0,
    resolution_deg: float = 0.15,
    merge_deg: float = 0.5,
) -> LandmarkMap:
    """Place the colour changes that several learning positions saw in the room.

    Parameters
    ----------
    views : iterable of LearnedView
        The learning frames' changes with their known poses.
    min_positions : int
        Fewest distinct positions whose rays must cross at a landmark (at least 2).
    tolerance_deg : float
        Largest angle between a ray and the direction from its origin to a landmark for
        the ray to count as seeing it.
    min_angle_deg : float
        Smallest angle between two rays whose crossing is a candidate.
    max_range_m : float
        Farthest a landmark may lie from the positions that saw it.
    resolution_deg : float
        Smallest angular scatter assumed for a landmark's rays (sub-pixel columns).
    merge_deg : float
        Rays of one viewpoint (origins within 1 cm) whose bearings chain within this
        angle are one sighting, their mean (many frames of a turn see each edge).

    Returns
    -------
    LandmarkMap
    """
    int_at_least("min_positions", min_positions, 2)
    tol = math.radians(positive_float("tolerance_deg", tolerance_deg))
    min_angle = math.radians(positive_float("min_angle_deg", min_angle_deg))
    max_range = positive_float("max_range_m", max_range_m)
    floor = math.radians(positive_float("resolution_deg", resolution_deg))
    merge = math.radians(positive_float("merge_deg", merge_deg))
    origins, angles, pairs, n_colors, bands = _rays(views)
    rng = np.random.default_rng(0)  # the candidates drawn when there are too many
    found: list[tuple[np.ndarray, int, float, int]] = []
    for pair in np.unique(pairs):
        sel = np.flatnonzero(pairs == pair)
        a = np.angle(np.exp(1j * angles[sel]))  # in (-pi, pi]
        o, a = _merge_repeats(origins[sel], a, merge)
        _, where = np.unique(np.round(o / 0.01).astype(np.int64), axis=0, return_inverse=True)
        where = where.reshape(-1)
        free = np.ones(len(a), bool)
        while free.sum() >= min_positions:
            idx = np.flatnonzero(free)
            points, i, j, drawn = _intersections(o[idx], a[idx], min_angle, max_range, rng)
            if len(points) == 0:
                break
            taken = _greedy_round(points, (idx[i], idx[j]), o, a, where, free, tol, min_positions)
            for support, rays in taken:
                point, std = _fit(o[rays], a[rays], floor)
                found.append((point, int(pair), std, support))
            # every pair of free rays was a candidate: none is left; drawn ones: draw again
            if not drawn or not taken:
                break
    if not found:
        none = np.zeros(0, np.int64)
        return LandmarkMap(np.zeros((0, 2)), none, np.zeros(0), none, n_colors, bands=bands)
    return LandmarkMap(
        np.array([f[0] for f in found], np.float64),
        np.array([f[1] for f in found], np.int64),
        np.array([f[2] for f in found], np.float64),
        np.array([f[3] for f in found], np.int64),
        n_colors,
        bands=bands,
    )
