"""Learned turns placed anew: where the learning phase's turns really stood.

The learning phase walks by odometry and a compass whose headings bend with parallax
away from home, so the turns it learns stand decimetres and degrees from where it
believes. Within one turn on the spot the odometry counts the turn well, but a little
long or short (a scale of 1-2 %). :func:`place_turns` puts every turn where its frames'
colour changes fit the landmarks of the home turn (a grid search), then adjusts all
turns and landmarks together (:func:`adjust_turns`: a bundle adjustment of the bearings,
Gauss-Newton with a robust loss), and learns the landmarks from every turn at its
corrected pose (:func:`~vc_gym.compass.landmarks.learn_landmarks`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vc_gym.compass.bearings import FrameBearings
from vc_gym.compass.landmarks import LandmarkMap, LearnedView, eye_positions, learn_landmarks
from vc_gym.validation import finite_float, int_at_least, positive_float

__all__ = [
    "MAX_ADJUSTED_LANDMARKS",
    "NO_CORRECTION",
    "Correction",
    "LearnedTurn",
    "adjust_turns",
    "place_turns",
]

#: A learned turn's correction: ``(dx m, dy m, dyaw deg, turn scale)``.
Correction = tuple[float, float, float, float]
#: The correction that leaves a turn as believed.
NO_CORRECTION: Correction = (0.0, 0.0, 0.0, 1.0)
#: Most landmarks :func:`adjust_turns` moves (the best observed; the rest stay where they
#: are and their changes are left out): bounds its normal equations.
MAX_ADJUSTED_LANDMARKS = 2000


@dataclass(frozen=True)
class LearnedTurn:
    """One turn on the spot of the learning phase, as the robot believed it went.

    Attributes
    ----------
    x, y : float
        Where the robot believed its body stood (m).
    frames : tuple
        ``(bearings, body_yaw_deg, pan_deg)`` of every frame: its changes, the believed
        body heading and the head pan. The headings run on without wrapping (a full turn
        ends near 360° from where it began), as the odometry counts them: a correction
        scales the turn since the first frame.
    """

    x: float
    y: float
    frames: tuple[tuple[FrameBearings, float, float], ...]

    def body_yaws(self, correction: Correction = NO_CORRECTION) -> np.ndarray:
        """``(len(frames),)`` body headings (deg) under ``correction``
        ``(dx m, dy m, dyaw deg, turn scale)``: the first frame's heading moved by
        ``dyaw`` and the turn since it scaled by ``turn scale``."""
        _, _, dyaw, scale = correction
        yaws = np.array([yaw for _, yaw, _ in self.frames], np.float64)
        if yaws.size == 0:
            return yaws
        return yaws[0] + dyaw + (yaws - yaws[0]) * scale

    def views(
        self, eye_forward_m: float, correction: Correction = NO_CORRECTION
    ) -> list[LearnedView]:
        """The frames as views from the camera, the turn corrected by ``correction``
        ``(dx m, dy m, dyaw deg, turn scale)`` (see :meth:`body_yaws`); the camera sits
        ``eye_forward_m`` ahead of the body."""
        dx, dy = correction[0], correction[1]
        yaws = self.body_yaws(correction)
        body = np.broadcast_to([self.x + dx, self.y + dy], (len(yaws), 2))
        eyes = eye_positions(body, np.radians(yaws), eye_forward_m)
        return [
            LearnedView(found, float(yaw + pan), float(ex), float(ey))
            for (found, _, pan), yaw, (ex, ey) in zip(self.frames, yaws, eyes, strict=True)
        ]


def _turn_scores(
    landmarks: LandmarkMap,
    turn: LearnedTurn,
    hypotheses: np.ndarray,
    eye_forward_m: float,
    noise_rad: float,
    outlier: float,
) -> np.ndarray:
    """Log-likelihood of every ``(dx, dy, dyaw deg, turn scale)`` correction of
    ``turn``: the sum over its frames of :meth:`LandmarkMap.log_likelihood`."""
    total = np.zeros(len(hypotheses))
    if not turn.frames:
        return total
    body = np.array([turn.x, turn.y]) + hypotheses[:, :2]
    first = turn.frames[0][1]
    for found, yaw, pan in turn.frames:
        t = np.radians(first + hypotheses[:, 2] + (yaw - first) * hypotheses[:, 3])
        eye = eye_positions(body, t, eye_forward_m)
        total += landmarks.log_likelihood(found, eye, t + math.radians(pan), noise_rad, outlier)
    return total


def _spread(n: int, most: int) -> np.ndarray:
    """At most ``most`` of ``range(n)``, evenly spread."""
    if n == 0:
        return np.zeros(0, int)
    return np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))


def _grid(
    centre: np.ndarray,
    reach: tuple[float, float, float],
    step: tuple[float, float, float],
) -> np.ndarray:
    """Corrections on a grid around ``centre`` ``(dx, dy, dyaw, turn scale)``:
    ``reach`` and ``step`` give the position (m), heading (deg) and turn scale's
    half-widths and steps (a step of 0 keeps the centre's value)."""
    axes = [
        np.arange(-r, r + 1e-9, st) if st > 0 else np.zeros(1)
        for r, st in zip(reach, step, strict=True)
    ]
    ax, ay, ayaw, ascale = np.meshgrid(axes[0], axes[0], axes[1], axes[2], indexing="ij")
    offsets = np.stack([ax.ravel(), ay.ravel(), ayaw.ravel(), ascale.ravel()], axis=1)
    return np.asarray(centre, np.float64) + offsets


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2.0 * np.pi) - np.pi


@dataclass(frozen=True)
class _Changes:
    """Every change of every frame of the turns, flattened."""

    turn: np.ndarray  # (K,) which turn
    first: np.ndarray  # (K,) the turn's first believed body heading (rad)
    rel: np.ndarray  # (K,) the frame's believed turn since then (rad)
    pan: np.ndarray  # (K,) head pan (rad)
    offset: np.ndarray  # (K,) observed bearing relative to the camera's yaw (rad)
    pair: np.ndarray  # (K,) colour-pair code

    @classmethod
    def of(cls, turns: list[LearnedTurn]) -> _Changes:
        cols: list[list] = [[], [], [], [], [], []]
        for k, turn in enumerate(turns):
            if not turn.frames:
                continue
            first = turn.frames[0][1]
            for found, yaw, pan in turn.frames:
                n = len(found)
                for col, value in zip(cols[:4], (k, first, yaw - first, pan), strict=True):
                    col.append(np.full(n, value, np.float64))
                cols[4].append(found.offsets_deg.astype(np.float64))
                cols[5].append(found.pairs)
        if not cols[0]:
            empty = np.zeros(0)
            return cls(empty.astype(np.int64), empty, empty, empty, empty, empty.astype(np.int64))
        turn, first, rel, pan, offset = (np.concatenate(c) for c in cols[:5])
        return cls(
            turn.astype(np.int64), np.radians(first), np.radians(rel), np.radians(pan),
            np.radians(offset), np.concatenate(cols[5]).astype(np.int64),
        )  # fmt: skip

    def subset(self, keep: np.ndarray) -> _Changes:
        return _Changes(*(getattr(self, f)[keep] for f in _Changes.__dataclass_fields__))


def _camera(
    where: np.ndarray, corrections: np.ndarray, c: _Changes, eye_forward_m: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per change: camera position ``(K, 2)``, body heading and camera yaw (rad), the
    turns at believed positions ``where`` ``(T, 2)`` moved by ``corrections``
    ``(T, 4)`` with headings in radians."""
    cor = corrections[c.turn]
    body_yaw = c.first + cor[:, 2] + c.rel * cor[:, 3]
    eye = (
        where[c.turn]
        + cor[:, :2]
        + eye_forward_m * np.stack([np.cos(body_yaw), np.sin(body_yaw)], axis=1)
    )
    return eye, body_yaw, body_yaw + c.pan


def _associate(
    positions: np.ndarray,
    pairs: np.ndarray,
    eye: np.ndarray,
    camera_yaw: np.ndarray,
    c: _Changes,
    gate_rad: float,
    half_fov: float,
) -> np.ndarray:
    """Per change, the landmark of its colour pair whose predicted bearing is nearest,
    within ``gate_rad`` and in view; -1 for none (in chunks of changes)."""
    out = np.full(len(c.pair), -1, np.int64)
    if len(positions) == 0:
        return out
    chunk = max(1, 4_000_000 // len(positions))
    for s in range(0, len(out), chunk):
        sl = slice(s, s + chunk)
        d = positions[None] - eye[sl, None]
        predicted = _wrap(np.arctan2(d[..., 1], d[..., 0]) - camera_yaw[sl, None])
        miss = np.abs(_wrap(c.offset[sl, None] - predicted))
        ok = (pairs[None] == c.pair[sl, None]) & (np.abs(predicted) <= half_fov)
        miss = np.where(ok, miss, np.inf)
        j = np.argmin(miss, axis=1)
        hit = miss[np.arange(len(j)), j] < gate_rad
        out[sl] = np.where(hit, j, -1)
    return out


def _huber(r: np.ndarray, c: float) -> tuple[float, np.ndarray]:
    """Huber cost of residuals ``r`` (in σ) and the IRLS weights."""
    a = np.abs(r)
    cost = float(np.sum(np.where(a <= c, 0.5 * r**2, c * a - 0.5 * c**2)))
    return cost, np.where(a <= c, 1.0, c / np.maximum(a, 1e-12))


def adjust_turns(
    turns: list[LearnedTurn],
    landmarks: LandmarkMap,
    corrections: np.ndarray,
    eye_forward_m: float = 0.0,
    noise_deg: float = 0.3,
    gate_deg: float = 1.5,
    scale_sigma: float = 0.02,
    associations: int = 3,
    max_steps: int = 20,
) -> tuple[np.ndarray, np.ndarray]:
    """Adjust the turns' corrections and the landmarks' positions together (a bundle
    adjustment of the bearings).

    Every change of every frame is matched to the landmark of its colour pair whose
    predicted bearing is nearest within ``gate_deg``; then the corrections of every turn
    but the first (home: the map's frame) and the positions of the matched landmarks
    minimise the Huber cost (3σ) of the bearing residuals, ``observed - predicted`` over
    ``noise_deg``, with a Gaussian prior of ``scale_sigma`` on each turn scale around 1,
    by Levenberg-Marquardt on the normal equations. The matching is redone
    ``associations`` times.

    Parameters
    ----------
    turns : list of LearnedTurn
        Home first.
    landmarks : LandmarkMap
        Where the adjustment starts (e.g. from :func:`place_turns`' grid search).
    corrections : numpy.ndarray
        ``(len(turns), 4)`` starting :data:`Correction` of each turn.
    eye_forward_m : float
        How far ahead of the body's centre the camera sits.
    noise_deg, gate_deg : float
        σ of an observed bearing, and the farthest a match may be from its prediction.
    scale_sigma : float
        Prior spread of the odometry's turn scale.
    associations : int
        Rounds of matching and adjusting (at least 1).
    max_steps : int
        Levenberg-Marquardt steps per round (at least 1).

    Returns
    -------
    corrections : numpy.ndarray
        ``(len(turns), 4)``, the first turn's unchanged.
    positions : numpy.ndarray
        ``(len(landmarks), 2)`` the landmarks' adjusted positions (those never matched,
        or beyond :data:`MAX_ADJUSTED_LANDMARKS`, where they were).
    """
    if not turns:
        raise ValueError("no turns to adjust")
    cor = np.array(corrections, dtype=np.float64)
    if cor.shape != (len(turns), 4) or not np.all(np.isfinite(cor)):
        raise ValueError(f"corrections must be finite, ({len(turns)}, 4), got {cor.shape}")
    eye_forward_m = finite_float("eye_forward_m", eye_forward_m)
    noise = math.radians(positive_float("noise_deg", noise_deg))
    gate = math.radians(positive_float("gate_deg", gate_deg))
    scale_sigma = positive_float("scale_sigma", scale_sigma)
    int_at_least("associations", associations, 1)
    int_at_least("max_steps", max_steps, 1)
    changes = _Changes.of(turns)
    positions = np.array(landmarks.positions, dtype=np.float64)
    if len(changes.pair) == 0 or len(positions) == 0 or len(turns) < 2:
        return cor, positions
    where = np.array([(t.x, t.y) for t in turns], np.float64)
    cor[:, 2] = np.radians(cor[:, 2])
    hfov = next(f[0].hfov_deg for t in turns for f in t.frames)
    half_fov = math.radians(hfov) / 2.0
    for _ in range(associations):
        eye, _, cam = _camera(where, cor, changes, eye_forward_m)
        match = _associate(positions, landmarks.pairs, eye, cam, changes, gate, half_fov)
        counts = np.bincount(match[match >= 0], minlength=len(positions))
        moved = np.argsort(-counts, kind="stable")[:MAX_ADJUSTED_LANDMARKS]
        moved = moved[counts[moved] > 0]
        slot = np.full(len(positions), -1, np.int64)
        slot[moved] = np.arange(len(moved))
        keep = (match >= 0) & (slot[np.maximum(match, 0)] >= 0)
        if not keep.any():
            break
        c = changes.subset(keep)
        lm = slot[match[keep]]
        cor, positions[moved] = _levenberg_marquardt(
            where, cor, positions[moved], c, lm, eye_forward_m, noise, scale_sigma, max_steps
        )
    cor[:, 2] = np.degrees(cor[:, 2])
    return cor, positions


def _levenberg_marquardt(
    where: np.ndarray,
    cor: np.ndarray,
    points: np.ndarray,
    c: _Changes,
    lm: np.ndarray,
    eye_forward_m: float,
    noise: float,
    scale_sigma: float,
    max_steps: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The steps of :func:`adjust_turns` for one matching: parameters are the turns'
    corrections but the first (4 each, heading in radians) then the points (2 each)."""
    n_turns = len(cor) - 1
    n_turn, n = 4 * n_turns, 4 * n_turns + 2 * len(points)
    # the columns each residual touches; the first turn's go to a dummy column n
    t_cols = np.where(c.turn[:, None] > 0, 4 * (c.turn[:, None] - 1) + np.arange(4), n)
    cols = np.concatenate([t_cols, n_turn + 2 * lm[:, None] + np.arange(2)], axis=1)
    scale_cols = 4 * np.arange(n_turns) + 3

    def residuals(cr: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        eye, body_yaw, cam = _camera(where, cr, c, eye_forward_m)
        d = pts[lm] - eye
        q = np.maximum(np.sum(d**2, axis=1), 1e-4)
        r = _wrap(c.offset - np.arctan2(d[:, 1], d[:, 0]) + cam) / noise
        d_yaw = 1.0 + eye_forward_m * (d[:, 0] * np.cos(body_yaw) + d[:, 1] * np.sin(body_yaw)) / q
        jac = (
            np.stack(
                [-d[:, 1] / q, d[:, 0] / q, d_yaw, c.rel * d_yaw, d[:, 1] / q, -d[:, 0] / q], axis=1
            )
            / noise
        )
        return r, jac

    def total_cost(cr: np.ndarray, pts: np.ndarray) -> float:
        r, _ = residuals(cr, pts)
        prior = (cr[1:, 3] - 1.0) / scale_sigma
        return _huber(r, 3.0)[0] + 0.5 * float(prior @ prior)

    damping = 1e-3
    cost = total_cost(cor, points)
    for _ in range(max_steps):
        r, jac = residuals(cor, points)
        _, w = _huber(r, 3.0)
        flat = (np.repeat(cols, 6, axis=1) * (n + 1) + np.tile(cols, (1, 6))).ravel()
        outer = (w[:, None, None] * jac[:, :, None] * jac[:, None, :]).ravel()
        h = np.bincount(flat, outer, minlength=(n + 1) ** 2).reshape(n + 1, n + 1)[:n, :n]
        g = np.bincount(cols.ravel(), (w[:, None] * r[:, None] * jac).ravel(), minlength=n + 1)
        h, g = h.copy(), g[:n].copy()
        h[scale_cols, scale_cols] += 1.0 / scale_sigma**2
        g[scale_cols] += (cor[1:, 3] - 1.0) / scale_sigma**2
        accepted = False
        while damping < 1e8:
            a = h + damping * np.diag(np.diag(h) + 1e-9)
            step = np.linalg.solve(a, -g)
            new_cor = cor.copy()
            new_cor[1:] += step[:n_turn].reshape(-1, 4)
            new_points = points + step[n_turn:].reshape(-1, 2)
            new_cost = total_cost(new_cor, new_points)
            if new_cost < cost:
                accepted = True
                damping = max(damping / 3.0, 1e-9)
                break
            damping *= 4.0
        if not accepted:
            break
        gain = cost - new_cost
        cor, points, cost = new_cor, new_points, new_cost
        if gain < 1e-6 * max(cost, 1.0):
            break
    return cor, points


def place_turns(
    turns: list[LearnedTurn],
    eye_forward_m: float = 0.0,
    search_m: float = 0.6,
    search_deg: float = 20.0,
    noise_deg: float = 0.3,
    outlier: float = 0.05,
    max_frames: int = 24,
    adjust: bool = True,
) -> tuple[LandmarkMap, np.ndarray]:
    """Landmarks from turns whose believed poses drifted, with each turn placed anew.

    The first turn (home, where the robot starts: the frame of the map) is taken as
    believed. Its frames alone place the first landmarks (the camera, ahead of the body,
    circles as the body turns, which gives the rays a baseline). Every other turn is
    then placed where its frames' changes fit those landmarks best: a search of body
    shifts within ``search_m`` and first headings within ``search_deg`` (10 cm and 2°
    steps, then 2 cm and 0.4°, then 1 cm and 0.2° around the best), the likelihood of
    :meth:`LandmarkMap.log_likelihood`. With ``adjust``, every turn (with its turn
    scale) and landmark is then adjusted together (:func:`adjust_turns`). The landmarks
    are learned from every turn at its corrected pose.

    Parameters
    ----------
    turns : list of LearnedTurn
        Home first; each turn's headings as the odometry counted them, unwrapped.
    eye_forward_m : float
        How far ahead of the body's centre the camera sits.
    search_m, search_deg : float
        How far a turn's believed position and first heading may be off.
    noise_deg, outlier : float
        The likelihood's bearing noise and outlier floor.
    max_frames : int
        Frames of a turn (evenly spread over it) its search is scored on; the adjustment
        and the landmarks use every frame.
    adjust : bool
        Adjust turns and landmarks together after the search.

    Returns
    -------
    landmarks : LandmarkMap
        From every turn at its corrected pose.
    corrections : numpy.ndarray
        ``(len(turns), 4)``: the :data:`Correction` ``(dx m, dy m, dyaw deg, turn scale)``
        of each turn (:data:`NO_CORRECTION` for home).
    """
    if not turns:
        raise ValueError("no turns to place")
    eye_forward_m = finite_float("eye_forward_m", eye_forward_m)
    reach = positive_float("search_m", search_m)
    reach_deg = positive_float("search_deg", search_deg)
    noise = math.radians(positive_float("noise_deg", noise_deg))
    int_at_least("max_frames", max_frames, 1)
    corrections = np.tile(np.asarray(NO_CORRECTION, np.float64), (len(turns), 1))
    # home alone: each edge is seen from two or three camera positions a few decimetres
    # apart (rough, but enough to place the other turns near their truth)
    landmarks = learn_landmarks(turns[0].views(eye_forward_m), min_positions=2)
    for k in range(1, len(turns)):
        t = turns[k]
        scored = LearnedTurn(
            t.x, t.y, tuple(t.frames[i] for i in _spread(len(t.frames), max_frames))
        )
        best = corrections[k]
        for reach_k, step in ((reach, 0.1), (0.1, 0.02), (0.02, 0.01)):
            deg = reach_deg if step == 0.1 else 20.0 * reach_k
            grid = _grid(best, (reach_k, deg, 0.0), (step, 20.0 * step, 0.0))
            ll = _turn_scores(landmarks, scored, grid, eye_forward_m, noise, outlier)
            best = grid[np.argmax(ll)]
        corrections[k] = best
    if adjust:
        first = learn_landmarks(_views(turns, corrections, eye_forward_m))
        corrections, _ = adjust_turns(turns, first, corrections, eye_forward_m, noise_deg=noise_deg)
    return learn_landmarks(_views(turns, corrections, eye_forward_m)), corrections


def _views(turns: list[LearnedTurn], corrections: np.ndarray, eye_forward_m: float) -> list:
    """Every frame of every turn as a view, each turn corrected."""
    return [
        v
        for turn, c in zip(turns, corrections, strict=True)
        for v in turn.views(eye_forward_m, tuple(float(e) for e in c))
    ]
