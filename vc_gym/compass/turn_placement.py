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
from dataclasses import dataclass, replace

import numpy as np

from vc_gym.angles import wrap_pi
from vc_gym.compass.bearings import FrameBearings
from vc_gym.compass.landmarks import LandmarkMap, LearnedView, eye_positions, learn_landmarks
from vc_gym.exposure import SessionLight
from vc_gym.poses import body_to_world
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
#: Spread of the odometry's count of a walk between turns: ``WALK_SIGMA_M`` plus
#: ``WALK_SIGMA_SHARE`` of its length, and ``WALK_SIGMA_DEG`` plus ``WALK_SIGMA_TURN_SHARE``
#: of its turn.
WALK_SIGMA_M = 0.03
WALK_SIGMA_SHARE = 0.05
WALK_SIGMA_DEG = 1.5
WALK_SIGMA_TURN_SHARE = 0.03
#: Prior spread of the gain the odometry's lengths are off by (the same for every walk).
WALK_GAIN_SIGMA = 0.1
#: How stiffly the first turn's position (m) and first heading (rad) are held.
_PIN = 1e-5
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
    walk : tuple of float, optional
        ``(forward m, left m, turn deg)``: how far the odometry says the body moved from
        the previous turn's last frame to this turn's first, in the body's frame at that
        last frame. It ties the turns in a chain (``None``: placed on its own).
    frame_gains : tuple of float
        The frames' gains to the colour classes' reference level
        (:meth:`~vc_gym.compass.VisualCompass.frame_gain`; empty when not read): the
        light the changes were seen at.
    """

    x: float
    y: float
    frames: tuple[tuple[FrameBearings, float, float], ...]
    walk: tuple[float, float, float] | None = None
    frame_gains: tuple[float, ...] = ()

    def body_yaws(self, correction: Correction = NO_CORRECTION) -> np.ndarray:
        """``(len(frames),)`` body headings (deg) under ``correction``
        ``(dx m, dy m, dyaw deg, turn scale)``: the first frame's heading moved by
        ``dyaw`` and the turn since it scaled by ``turn scale``."""
        _, _, dyaw, scale = correction
        yaws = np.array([yaw for _, yaw, _ in self.frames], np.float64)
        if yaws.size == 0:
            return yaws
        return yaws[0] + dyaw + (yaws - yaws[0]) * scale

    def last_pose(self, correction: Correction = NO_CORRECTION) -> tuple[float, float, float]:
        """``(x m, y m, heading deg)`` of the body at the last frame, corrected."""
        return (
            self.x + correction[0],
            self.y + correction[1],
            float(self.body_yaws(correction)[-1]),
        )

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
    # symmetric about the centre, which is always a node
    axes = [
        np.arange(-math.floor(r / st + 1e-9), math.floor(r / st + 1e-9) + 1) * st
        if st > 0
        else np.zeros(1)
        for r, st in zip(reach, step, strict=True)
    ]
    ax, ay, ayaw, ascale = np.meshgrid(axes[0], axes[0], axes[1], axes[2], indexing="ij")
    offsets = np.stack([ax.ravel(), ay.ravel(), ayaw.ravel(), ascale.ravel()], axis=1)
    return np.asarray(centre, np.float64) + offsets


def _walk_sigmas(walk: tuple[float, float, float]) -> tuple[float, float]:
    """σ of a walk's end position (m) and heading (deg)."""
    return (
        WALK_SIGMA_M + WALK_SIGMA_SHARE * math.hypot(walk[0], walk[1]),
        WALK_SIGMA_DEG + WALK_SIGMA_TURN_SHARE * abs(walk[2]),
    )


def _chained(
    previous: LearnedTurn, correction: np.ndarray, walk: tuple[float, float, float]
) -> tuple[float, float, float]:
    """Where the odometry's ``walk`` puts the body, from ``previous``'s last frame."""
    x, y, yaw = previous.last_pose(tuple(float(e) for e in correction))
    dx, dy = body_to_world(walk[0], walk[1], yaw)
    return x + dx, y + dy, yaw + walk[2]


@dataclass(frozen=True)
class _Walks:
    """The walks that chain a turn to the one before it (radians)."""

    turn: np.ndarray  # (W,) the turn the walk ends at (>= 1)
    prev_first: np.ndarray  # (W,) the previous turn's first believed heading
    prev_rel: np.ndarray  # (W,) its last frame's turn since then
    first: np.ndarray  # (W,) the turn's first believed heading
    walk: np.ndarray  # (W, 3) forward, left (m), turn (rad)
    sigma: np.ndarray  # (W, 2) position (m), heading (rad)

    @classmethod
    def of(cls, turns: list[LearnedTurn]) -> _Walks:
        rows = []
        for k in range(1, len(turns)):
            t, prev = turns[k], turns[k - 1]
            if t.walk is None or not t.frames or not prev.frames:
                continue
            s_m, s_deg = _walk_sigmas(t.walk)
            rows.append(
                (k, prev.frames[0][1], prev.frames[-1][1] - prev.frames[0][1], t.frames[0][1],
                 t.walk[0], t.walk[1], t.walk[2], s_m, s_deg)
            )  # fmt: skip
        a = np.array(rows, np.float64).reshape(-1, 9)
        rad = np.radians
        return cls(
            a[:, 0].astype(np.int64), rad(a[:, 1]), rad(a[:, 2]), rad(a[:, 3]),
            np.stack([a[:, 4], a[:, 5], rad(a[:, 6])], axis=1),
            np.stack([a[:, 7], rad(a[:, 8])], axis=1),
        )  # fmt: skip

    def residuals(
        self, where: np.ndarray, cor: np.ndarray, gain: float, n: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Residuals ``(3W,)`` (in σ) of where each walk, its length times ``gain``,
        ends against its turn's first frame, and their dense Jacobian ``(3W, n)`` over
        the turns' parameters of :func:`_levenberg_marquardt` (4 each, headings in
        radians) and the gain, column ``n - 1`` (the walks touch no landmark)."""
        w_n = len(self.turn)
        r = np.zeros(3 * w_n)
        jac = np.zeros((3 * w_n, n))
        for i, k in enumerate(self.turn):
            p = k - 1
            psi = self.prev_first[i] + cor[p, 2] + self.prev_rel[i] * cor[p, 3]
            c, s = math.cos(psi), math.sin(psi)
            fx, fy, fyaw = self.walk[i]
            sp, sy = self.sigma[i]
            along = np.array([c * fx - s * fy, s * fx + c * fy])
            end = where[p] + cor[p, :2] + gain * along
            jac[3 * i : 3 * i + 2, n - 1] = along / sp
            fx, fy = gain * fx, gain * fy
            r[3 * i : 3 * i + 2] = (end - where[k] - cor[k, :2]) / sp
            r[3 * i + 2] = wrap_pi(psi + fyaw - self.first[i] - cor[k, 2]) / sy
            turn_cols = 4 * k
            jac[3 * i, turn_cols] = jac[3 * i + 1, turn_cols + 1] = -1.0 / sp
            jac[3 * i + 2, turn_cols + 2] = -1.0 / sy
            d_psi = np.array([-s * fx - c * fy, c * fx - s * fy]) / sp
            prev_cols = 4 * p
            jac[3 * i, prev_cols] = jac[3 * i + 1, prev_cols + 1] = 1.0 / sp
            jac[3 * i : 3 * i + 2, prev_cols + 2] = d_psi
            jac[3 * i : 3 * i + 2, prev_cols + 3] = d_psi * self.prev_rel[i]
            jac[3 * i + 2, prev_cols + 2] = 1.0 / sy
            jac[3 * i + 2, prev_cols + 3] = self.prev_rel[i] / sy
        return r, jac


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
    eye = eye_positions(where[c.turn] + cor[:, :2], body_yaw, eye_forward_m)
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
    within ``gate_rad`` and in view; -1 for none (pair by pair, in chunks of changes)."""
    out = np.full(len(c.pair), -1, np.int64)
    if len(positions) == 0:
        return out
    by_pair = np.argsort(pairs, kind="stable")
    sorted_pairs = pairs[by_pair]
    changes = np.argsort(c.pair, kind="stable")
    codes, starts = np.unique(c.pair[changes], return_index=True)
    ends = np.r_[starts[1:], len(changes)]
    for code, first, last in zip(codes, starts, ends, strict=True):
        lo, hi = np.searchsorted(sorted_pairs, [code, code + 1])
        if lo == hi:
            continue
        cand = by_pair[lo:hi]  # ascending: ties go to the lowest index
        chunk = max(1, 4_000_000 // len(cand))
        for s in range(first, last, chunk):
            sl = changes[s : min(s + chunk, last)]
            d = positions[cand][None] - eye[sl, None]
            predicted = wrap_pi(np.arctan2(d[..., 1], d[..., 0]) - camera_yaw[sl, None])
            miss = np.abs(wrap_pi(c.offset[sl, None] - predicted))
            miss = np.where(np.abs(predicted) <= half_fov, miss, np.inf)
            j = np.argmin(miss, axis=1)
            hit = miss[np.arange(len(j)), j] < gate_rad
            out[sl] = np.where(hit, cand[j], -1)
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
    known: object = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Adjust the turns' corrections and the landmarks' positions together (a bundle
    adjustment of the bearings).

    Every change of every frame is matched to the landmark of its colour pair whose
    predicted bearing is nearest within ``gate_deg``; then the corrections of every turn
    (of a ``known`` turn only its turn scale: its position and first heading are the
    map's frame) and the positions of the matched landmarks minimise the Huber cost (3σ)
    of the bearing residuals, ``observed - predicted`` over
    ``noise_deg``, with a Gaussian prior of ``scale_sigma`` on each turn scale around 1
    and, for a turn with a ``walk``, a Gaussian of the walk's spread on where that walk
    from the turn before ends (its length times one gain for all walks, itself adjusted
    with a prior of :data:`WALK_GAIN_SIGMA`: the odometry counts lengths a few per cent
    off), by Levenberg-Marquardt on the normal equations. The matching is redone
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
    known : sequence of bool, optional
        Which turns stood where given (position and first heading); default the first
        only (home), which must be known.

    Returns
    -------
    corrections : numpy.ndarray
        ``(len(turns), 4)``; the known turns' positions and headings unchanged.
    positions : numpy.ndarray
        ``(len(landmarks), 2)`` the landmarks' adjusted positions (those never matched,
        or beyond :data:`MAX_ADJUSTED_LANDMARKS`, where they were).
    """
    if not turns:
        raise ValueError("no turns to adjust")
    pinned = _known_turns(known, len(turns))
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
    walks = _Walks.of(turns)
    walk_gain = 1.0
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
        cor, positions[moved], walk_gain = _levenberg_marquardt(
            where, cor, positions[moved], walk_gain, c, lm, walks, pinned, eye_forward_m,
            noise, scale_sigma, max_steps,
        )  # fmt: skip
    cor[:, 2] = np.degrees(cor[:, 2])
    cor[pinned, :3] = np.asarray(corrections)[pinned, :3]  # held stiffly; exactly as given
    return cor, positions


def _known_turns(known: object, n: int) -> np.ndarray:
    """Indices of the known turns (default: the first), checked."""
    if known is None:
        return np.zeros(1, np.int64)
    mask = np.asarray(known)
    if mask.shape != (n,) or mask.dtype != bool:
        raise ValueError(f"known must be {n} booleans, one per turn, got {known!r}")
    if not mask[0]:
        raise ValueError("the first turn must be known: it is the map's frame")
    return np.flatnonzero(mask)


def _levenberg_marquardt(
    where: np.ndarray,
    cor: np.ndarray,
    points: np.ndarray,
    walk_gain: float,
    c: _Changes,
    lm: np.ndarray,
    walks: _Walks,
    pinned: np.ndarray,
    eye_forward_m: float,
    noise: float,
    scale_sigma: float,
    max_steps: int,
) -> tuple[np.ndarray, np.ndarray, float]:
    """The steps of :func:`adjust_turns` for one matching. The parameters are the turns'
    corrections (4 each, heading in radians; the ``pinned`` turns' positions and first
    headings held by a stiff prior, :data:`_PIN`: the map's frame), the gain of the
    odometry's walk lengths (column ``4 T``: with the turns', the turn side of the
    normal equations) and the points (2 each, eliminated: :func:`_schur_step`)."""
    n_turns = len(cor)
    n_turn = 4 * n_turns
    n_t = n_turn + 1  # the turn side: the turns' columns, then the gain's
    t_cols = 4 * c.turn[:, None] + np.arange(4)  # the turn columns each residual touches
    scale_cols = 4 * np.arange(n_turns) + 3

    def residuals(cr: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        eye, body_yaw, cam = _camera(where, cr, c, eye_forward_m)
        d = pts[lm] - eye
        q = np.maximum(np.sum(d**2, axis=1), 1e-4)
        r = wrap_pi(c.offset - np.arctan2(d[:, 1], d[:, 0]) + cam) / noise
        d_yaw = 1.0 + eye_forward_m * (d[:, 0] * np.cos(body_yaw) + d[:, 1] * np.sin(body_yaw)) / q
        jac = np.stack(
            [-d[:, 1] / q, d[:, 0] / q, d_yaw, c.rel * d_yaw, d[:, 1] / q, -d[:, 0] / q], axis=1
        )
        return r, jac / noise

    held = cor[pinned, :3].copy()

    def priors(cr: np.ndarray, gain: float) -> np.ndarray:
        return np.concatenate(
            [
                (cr[:, 3] - 1.0) / scale_sigma,
                ((cr[pinned, :3] - held) / _PIN).ravel(),
                [(gain - 1.0) / WALK_GAIN_SIGMA],
            ]
        )

    def total_cost(cr: np.ndarray, pts: np.ndarray, gain: float) -> float:
        chain = walks.residuals(where, cr, gain, n_t)[0]
        prior = priors(cr, gain)
        return (
            _huber(residuals(cr, pts)[0], 3.0)[0]
            + 0.5 * float(prior @ prior)
            + 0.5 * float(chain @ chain)
        )

    pin_cols = (4 * pinned[:, None] + np.arange(3)).ravel()
    prior_cols = np.concatenate([scale_cols, pin_cols, [n_turn]])
    prior_w = np.concatenate(
        [
            np.full(n_turns, 1.0 / scale_sigma),
            np.full(pin_cols.size, 1.0 / _PIN),
            [1.0 / WALK_GAIN_SIGMA],
        ]
    )
    damping = 1e-3
    cost = total_cost(cor, points, walk_gain)
    for _ in range(max_steps):
        r, jac = residuals(cor, points)
        _, w = _huber(r, 3.0)
        a, b, d, g_t, g_p = _normal_equations(t_cols, lm, jac, w, r, n_t, len(points))
        a[prior_cols, prior_cols] += prior_w**2
        g_t[prior_cols] += priors(cor, walk_gain) * prior_w
        chain, chain_jac = walks.residuals(where, cor, walk_gain, n_t)
        a += chain_jac.T @ chain_jac
        g_t += chain_jac.T @ chain
        accepted = False
        while damping < 1e8:
            step_t, step_p = _schur_step(a, b, d, g_t, g_p, damping)
            new_cor = cor + step_t[:n_turn].reshape(-1, 4)
            new_points = points + step_p.reshape(-1, 2)
            new_gain = walk_gain + float(step_t[-1])
            new_cost = total_cost(new_cor, new_points, new_gain)
            if new_cost < cost:
                accepted = True
                damping = max(damping / 3.0, 1e-9)
                break
            damping *= 4.0
        if not accepted:
            break
        drop = cost - new_cost
        cor, points, walk_gain, cost = new_cor, new_points, new_gain, new_cost
        if drop < 1e-6 * max(cost, 1.0):
            break
    return cor, points, walk_gain


def _normal_equations(
    t_cols: np.ndarray,
    lm: np.ndarray,
    jac: np.ndarray,
    w: np.ndarray,
    r: np.ndarray,
    n_t: int,
    n_points: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The bearings' weighted normal equations in blocks. A residual touches one turn's
    4 columns (of the ``n_t`` turn-side ones) and one point's 2 (``jac`` ``(K, 6)``
    in that order): the turn block ``a`` ``(n_t, n_t)``, the turn-point block ``b``
    ``(n_t, 2 P)``, the points' own ``(P, 2, 2)`` blocks ``d`` (points do not share a
    residual), and the gradients of both sides."""
    jt, jp = jac[:, :4], jac[:, 4:]
    wt = w[:, None] * jt
    p_cols = 2 * lm[:, None] + np.arange(2)
    a = np.bincount(
        (t_cols[:, :, None] * n_t + t_cols[:, None, :]).ravel(),
        (wt[:, :, None] * jt[:, None, :]).ravel(),
        minlength=n_t * n_t,
    ).reshape(n_t, n_t)
    b = np.bincount(
        (t_cols[:, :, None] * (2 * n_points) + p_cols[:, None, :]).ravel(),
        (wt[:, :, None] * jp[:, None, :]).ravel(),
        minlength=n_t * 2 * n_points,
    ).reshape(n_t, 2 * n_points)
    d = np.bincount(
        (4 * lm[:, None] + np.arange(4)).ravel(),  # row-major 2 x 2 blocks
        (w[:, None, None] * jp[:, :, None] * jp[:, None, :]).ravel(),
        minlength=4 * n_points,
    ).reshape(n_points, 2, 2)
    g_t = np.bincount(t_cols.ravel(), (wt * r[:, None]).ravel(), minlength=n_t)
    g_p = np.bincount(
        p_cols.ravel(), (w[:, None] * jp * r[:, None]).ravel(), minlength=2 * n_points
    )
    return a, b, d, g_t, g_p


def _schur_step(
    a: np.ndarray, b: np.ndarray, d: np.ndarray, g_t: np.ndarray, g_p: np.ndarray, damping: float
) -> tuple[np.ndarray, np.ndarray]:
    """The damped Gauss-Newton step ``(H + damping diag(H)) x = -g`` of the blocks of
    :func:`_normal_equations`, by eliminating the points (their 2 x 2 blocks invert in
    closed form): the turn side solves a system of its own size only."""
    a = a + damping * np.diag(np.diag(a) + 1e-9)
    d = d.copy()
    d[:, 0, 0] += damping * (d[:, 0, 0] + 1e-9)
    d[:, 1, 1] += damping * (d[:, 1, 1] + 1e-9)
    det = d[:, 0, 0] * d[:, 1, 1] - d[:, 0, 1] * d[:, 1, 0]
    inv = np.stack([d[:, 1, 1], -d[:, 0, 1], -d[:, 1, 0], d[:, 0, 0]], 1).reshape(-1, 2, 2)
    inv /= det[:, None, None]
    bp = b.reshape(len(a), -1, 2)
    b_inv = np.einsum("ipk,pkl->ipl", bp, inv).reshape(len(a), -1)
    x_t = np.linalg.solve(a - b_inv @ b.T, -g_t + b_inv @ g_p)
    rhs = (g_p + b.T @ x_t).reshape(-1, 2)
    return x_t, -np.einsum("pkl,pl->pk", inv, rhs).ravel()


def place_turns(
    turns: list[LearnedTurn],
    eye_forward_m: float = 0.0,
    search_m: float = 0.6,
    search_deg: float = 20.0,
    noise_deg: float = 0.3,
    outlier: float = 0.05,
    max_frames: int = 24,
    adjust: bool = True,
    relearn: bool = True,
    known: object = None,
) -> tuple[LandmarkMap, np.ndarray]:
    """Landmarks from turns whose believed poses drifted, with each turn placed anew.

    The first turn (home, where the robot starts: the frame of the map), and any other
    ``known`` turn, is taken as believed. Their frames alone place the first landmarks
    (the camera, ahead of the body, circles as the body turns, which gives the rays a
    baseline). Every other turn, in order, is then placed where its frames' changes fit
    the landmarks best: a search
    (10 cm and 2° steps, then 2 cm and 0.4°, then 1 cm and 0.2° around the best) with the
    likelihood of :meth:`LandmarkMap.log_likelihood`. A turn with a ``walk`` is searched
    around where that walk from the placed turn before puts it (within 3σ of the walk's
    spread, :data:`WALK_SIGMA_M` ..., which also weighs the search); one without, within
    ``search_m`` and ``search_deg`` of its belief. With ``relearn`` the landmarks are
    learned again from every turn placed so far after each one. With ``adjust``, every
    turn (with its turn scale) and landmark is then adjusted together
    (:func:`adjust_turns`, the walks included). The landmarks are learned from every
    turn at its corrected pose.

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
    relearn : bool
        Learn the landmarks again after each turn is placed (else from the known turns'
        alone).
    known : sequence of bool, optional
        Which turns stood where believed (position and first heading: e.g. a robot
        placed at known spots); default the first only, which must be known.

    Returns
    -------
    landmarks : LandmarkMap
        From every turn at its corrected pose, with the light of the turns' frames
        (:class:`~vc_gym.exposure.SessionLight` of their ``frame_gains``; 1 if none
        were read).
    corrections : numpy.ndarray
        ``(len(turns), 4)``: the :data:`Correction` ``(dx m, dy m, dyaw deg, turn scale)``
        of each turn (home's position and first heading unchanged: the map's frame).
    """
    if not turns:
        raise ValueError("no turns to place")
    eye_forward_m = finite_float("eye_forward_m", eye_forward_m)
    reach = positive_float("search_m", search_m)
    reach_deg = positive_float("search_deg", search_deg)
    noise = math.radians(positive_float("noise_deg", noise_deg))
    int_at_least("max_frames", max_frames, 1)
    corrections = np.tile(np.asarray(NO_CORRECTION, np.float64), (len(turns), 1))
    # the known turns alone (home: each edge seen from two or three camera positions a
    # few decimetres apart; rough, but enough to place the other turns near their truth)
    pinned = _known_turns(known, len(turns))
    searched = sorted(set(range(1, len(turns))) - set(pinned.tolist()))
    if searched:
        known_views = _views([turns[k] for k in pinned], corrections[pinned], eye_forward_m)
        landmarks = learn_landmarks(known_views, min_positions=2)
    for k in searched:
        t = turns[k]
        scored = LearnedTurn(
            t.x, t.y, tuple(t.frames[i] for i in _spread(len(t.frames), max_frames))
        )
        best, first_reach, first_deg = corrections[k], reach, reach_deg
        prior = None
        if t.walk is not None and t.frames and turns[k - 1].frames:
            # where the walk from the placed turn before puts it, give or take the walk's
            # spread (3 sigma searched)
            x, y, yaw = _chained(turns[k - 1], corrections[k - 1], t.walk)
            best = np.array([x - t.x, y - t.y, yaw - t.frames[0][1], 1.0])
            s_m, s_deg = _walk_sigmas(t.walk)
            first_reach, first_deg = min(reach, 3 * s_m), min(reach_deg, 3 * s_deg)
            prior = (best.copy(), s_m, s_deg)
        for reach_k, step in ((first_reach, 0.1), (0.1, 0.02), (0.02, 0.01)):
            deg = first_deg if step == 0.1 else 20.0 * reach_k
            grid = _grid(best, (reach_k, deg, 0.0), (step, 20.0 * step, 0.0))
            ll = _turn_scores(landmarks, scored, grid, eye_forward_m, noise, outlier)
            if prior is not None:
                centre, s_m, s_deg = prior
                ll = ll - 0.5 * (
                    np.sum((grid[:, :2] - centre[:2]) ** 2, axis=1) / s_m**2
                    + ((grid[:, 2] - centre[2]) / s_deg) ** 2
                )
            best = grid[np.argmax(ll)]
        corrections[k] = best
        if relearn:  # from the known turns and those placed so far
            placed = sorted(set(pinned.tolist()) | set(range(k + 1)))
            views = _views([turns[j] for j in placed], corrections[placed], eye_forward_m)
            landmarks = learn_landmarks(views, min_positions=2)
    if adjust:
        first = learn_landmarks(_views(turns, corrections, eye_forward_m))
        corrections, _ = adjust_turns(
            turns, first, corrections, eye_forward_m, noise_deg=noise_deg, known=known
        )
    landmarks = learn_landmarks(_views(turns, corrections, eye_forward_m))
    light = SessionLight.of(g for t in turns for g in t.frame_gains)
    return replace(landmarks, eye_forward_m=eye_forward_m, light_gain=light), corrections


def _views(turns: list[LearnedTurn], corrections: np.ndarray, eye_forward_m: float) -> list:
    """Every frame of every turn as a view, each turn corrected."""
    return [
        v
        for turn, c in zip(turns, corrections, strict=True)
        for v in turn.views(eye_forward_m, tuple(float(e) for e in c))
    ]
