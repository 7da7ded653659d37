"""Views from poses on the field: the core of the orientation experiment (paper 5.1, fig. 4).

The paper's robot learned the panorama at a single spot (the centre of the rear field
half) and was then moved by hand over a 3 × 3 m grid at about 33 cm resolution; at
every grid point its heading estimate was recorded (fig. 4 left: the estimates point
to one place on the far wall; fig. 4 right: the mean error exceeds 10° only beyond
2 m from the training spot, where the mean spread reaches about 50°). Figure 5 (right)
shows, on a 50 cm grid, the goodness ``L_i`` (eq. 28) of one spot's map.

This module holds the pieces an experiment runner combines into jobs, each pure per
call (its result depends on its arguments, seeds included, never on what the same
process computed before):

* :func:`field_grid` and :func:`view_poses`: where the robot is put;
* :func:`look`: reset an :class:`~vc_gym.sim.aibo_room.AiboRoomEnv` at a pose and let
  the robot stand there, scanning with its head, for some frames;
* :func:`evaluate_view`: feed the frames to every tracker and record what each
  believed (and the single-frame compass of the atlas' first spot);
* :func:`spot_goodness`: the mean normalised goodness ``L̂_i`` of every spot;
* :func:`distance_table`: errors and spreads per distance from the training spot;
* :func:`plot_error_vs_distance`, :func:`plot_arrow_field`, :func:`plot_goodness_field`:
  figures 4 right, 4 left and 5 right.

Typical use (one spot learned with :class:`~vc_gym.envs.learning.SpotLearning`)::

    room.reset(seed=0)
    atlas = SpotLearning((-1.5, 0.0))(room, LearningConfig()).atlas
    for i, pose in enumerate(view_poses(field_grid(bounds, 0.33), 1, rng)):
        frames = look(room, pose, frames=15, seed=i)
        figures, timing = evaluate_view(frames, atlas, camera, room.control_dt,
                                        pose[2], {"grid": "grid"})
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.patches import Circle, Rectangle

from vc_gym.angles import wrap180, wrap360
from vc_gym.compass import Camera, CompassAtlas
from vc_gym.envs.learning import HEAD_SCAN_DEG, RobotFell
from vc_gym.jobs.output import new_figure, save_figure
from vc_gym.localization import TrackerSpec, make_tracker
from vc_gym.poses import check_pose
from vc_gym.sim.aibo_room import AiboRoomEnv
from vc_gym.validation import finite_float, positive_float

__all__ = [
    "COMPASS",
    "PAPER_ERROR_DEG",
    "PAPER_RANGE_M",
    "Frame",
    "distance_table",
    "evaluate_view",
    "field_grid",
    "learning_turn",
    "look",
    "plot_arrow_field",
    "plot_error_vs_distance",
    "plot_goodness_field",
    "spot_goodness",
    "view_poses",
]

#: One frame of :func:`look`: ``(image, measured head pan in degrees, odometry
#: (forward m, left m, turn deg) since the previous frame)``.
Frame = tuple[np.ndarray, float, tuple[float, float, float]]

#: Name under which :func:`evaluate_view` reports the single-frame compass.
COMPASS = "compass"
#: The paper's claim (5.1): the mean heading error stays below 10° ...
PAPER_ERROR_DEG = 10.0
#: ... within 2 m of the training spot.
PAPER_RANGE_M = 2.0
#: Most positions :func:`field_grid` makes (a guard against a mistyped spacing).
_MAX_GRID_POINTS = 1_000_000


# ---------------------------------------------------------------------- validation
def _bounds(bounds: object, name: str = "bounds") -> tuple[float, float, float, float]:
    try:
        vals = tuple(float(v) for v in bounds)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (xmin, xmax, ymin, ymax), got {bounds!r}") from None
    if len(vals) != 4 or not all(math.isfinite(v) for v in vals):
        raise ValueError(
            f"{name} must be 4 finite numbers (xmin, xmax, ymin, ymax), got {bounds!r}"
        )
    x0, x1, y0, y1 = vals
    if not (x0 < x1 and y0 < y1):
        raise ValueError(f"{name} must have xmin < xmax and ymin < ymax, got {bounds!r}")
    return vals  # type: ignore[return-value]


def _int_at_least(name: str, value: object, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an int >= {low}, got {value!r}")
    return int(value)


def _positions(positions: object) -> np.ndarray:
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"positions must have shape (N, 2), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("positions must be finite")
    return p


def _frames(frames: object) -> list[Frame]:
    if isinstance(frames, np.ndarray) or not isinstance(frames, Sequence) or len(frames) == 0:
        raise ValueError("frames must be a non-empty sequence of (image, head_pan_deg, odometry)")
    out = []
    for i, frame in enumerate(frames):
        try:
            image, pan, odo = frame
        except (TypeError, ValueError):
            raise ValueError(
                f"frame {i} must be (image, head_pan_deg, odometry), got {type(frame).__name__}"
            ) from None
        out.append((image, finite_float(f"frame {i} head_pan_deg", pan), odo))
    return out


def _spot(spot: object) -> tuple[float, float]:
    spots = spots_array(spot)
    if len(spots) != 1:
        raise ValueError(f"spot must be (x, y), got {spot!r}")
    return float(spots[0, 0]), float(spots[0, 1])


def spots_array(spot: object) -> np.ndarray:
    """One spot ``(x, y)`` or several ``[(x, y), ...]`` as a finite ``(N, 2)`` array."""
    try:
        a = np.asarray(spot, dtype=np.float64)
    except (TypeError, ValueError):
        a = np.zeros(0)
    if a.shape == (2,):
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 2 or len(a) == 0 or not np.all(np.isfinite(a)):
        raise ValueError(f"spot must be (x, y) or a list of (x, y), got {spot!r}")
    return a


# ---------------------------------------------------------------------- poses
def field_grid(
    bounds: tuple[float, float, float, float], spacing_m: float, margin_m: float = 0.25
) -> np.ndarray:
    """Positions on a regular grid over a field (paper 5.1: ~33 cm; fig. 5 right: 50 cm).

    The grid covers ``bounds`` shrunk by ``margin_m`` on every side, ``spacing_m``
    apart, and is centred in it (the spare length left by the spacing is split
    evenly between both ends of each axis).

    Parameters
    ----------
    bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field, world metres.
    spacing_m : float
        Distance between neighbouring grid points, > 0.
    margin_m : float
        Distance kept from the field's edges, >= 0; must leave a non-empty area.

    Returns
    -------
    numpy.ndarray
        ``(N, 2)`` float64 positions ``(x, y)``, ordered by ``x`` then ``y``.

    Raises
    ------
    ValueError
        Bounds that are not 4 finite numbers with ``xmin < xmax``, ``ymin < ymax``;
        a non-positive or non-finite spacing; a negative margin or one that leaves no
        area; more than a million points.
    """
    x0, x1, y0, y1 = _bounds(bounds)
    spacing = positive_float("spacing_m", spacing_m)
    margin = finite_float("margin_m", margin_m)
    if margin < 0:
        raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
    axes = []
    for lo, hi, name in ((x0, x1, "x"), (y0, y1, "y")):
        span = (hi - lo) - 2.0 * margin
        if span < 0:
            raise ValueError(
                f"margin_m={margin} leaves nothing of the field's {name} extent {hi - lo:g} m"
            )
        n = int(math.floor(span / spacing + 1e-9)) + 1
        if n > _MAX_GRID_POINTS:
            raise ValueError(f"spacing_m={spacing} gives too many grid points ({n} along {name})")
        start = lo + margin + 0.5 * (span - (n - 1) * spacing)
        axes.append(start + spacing * np.arange(n))
    if axes[0].size * axes[1].size > _MAX_GRID_POINTS:
        raise ValueError(
            f"spacing_m={spacing} gives too many grid points ({axes[0].size * axes[1].size})"
        )
    xx, yy = np.meshgrid(axes[0], axes[1], indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def view_poses(
    positions: np.ndarray | Sequence[tuple[float, float]],
    headings_per_position: int,
    rng: np.random.Generator,
) -> np.ndarray:
    """Poses at every position with random headings (the robot placed by hand, 5.1).

    Parameters
    ----------
    positions : array_like
        ``(N, 2)`` positions ``(x, y)``, world metres (e.g. :func:`field_grid`).
    headings_per_position : int
        How many poses per position, >= 1.
    rng : numpy.random.Generator
        Draws the headings, uniform in ``[0, 360)``.

    Returns
    -------
    numpy.ndarray
        ``(N * headings_per_position, 3)`` poses ``(x, y, yaw_deg)``; the poses of one
        position are consecutive.

    Raises
    ------
    ValueError
        Positions not of shape ``(N, 2)`` or not finite, a count that is not an int
        >= 1, or ``rng`` not a Generator.
    """
    p = _positions(positions)
    k = _int_at_least("headings_per_position", headings_per_position, 1)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    xy = np.repeat(p, k, axis=0)
    yaw = rng.uniform(0.0, 360.0, size=xy.shape[0])
    return np.column_stack([xy, yaw])


# ---------------------------------------------------------------------- frames
def look(
    room: AiboRoomEnv,
    pose: tuple[float, float, float] | np.ndarray,
    frames: int,
    seed: int,
    head_scan_deg: Sequence[float] = HEAD_SCAN_DEG,
) -> list[Frame]:
    """Put the robot at ``pose`` and let it stand there scanning with its head (5.1).

    The room is reset with ``seed`` at ``pose`` (``options={"pose": pose}``); the
    reset's frame is the first one. For every further frame ``k = 1, 2, ...`` the
    robot stands still (zero velocities) and commands the head pan
    ``head_scan_deg[k % len(head_scan_deg)]``; the head moves at its bounded speed, so
    the *measured* pan (``obs["head"][0]``) is what is returned. With the default scan
    the head moves 0° → -20° → 0° → 20° → 40° → 20° → ...

    The result depends only on the arguments: the reset re-seeds the room and puts the
    robot and its head in a fixed state, so a reused room gives the same frames as a
    fresh one.

    Parameters
    ----------
    room : AiboRoomEnv
        The room env; a wrapped env is unwrapped.
    pose : tuple of float
        ``(x, y, yaw_deg)`` of the robot, world frame.
    frames : int
        Number of frames, >= 1 (the reset frame included).
    seed : int
        Seed of the reset (odometry errors; the scene when randomised).
    head_scan_deg : sequence of float
        Head pans cycled while standing (within ±90°).

    Returns
    -------
    list of tuple
        ``(image, head_pan_deg, odometry)`` per frame: the ``(H, W, 3)`` uint8 RGB
        image, the measured head pan in degrees (float) and the odometry since the
        previous frame ``(forward m, left m, turn deg)`` as floats (zeros for the
        reset frame).

    Raises
    ------
    ValueError
        On a room that is not an ``AiboRoomEnv``, a bad pose, frame count, seed or scan.
    RobotFell
        If the robot falls (only with ``locomotion="dynamic"``).
    """
    env = getattr(room, "unwrapped", room)
    if not isinstance(env, AiboRoomEnv):
        raise ValueError(f"room must be an AiboRoomEnv, got {type(room).__name__}")
    x, y, yaw = check_pose(pose)
    n = _int_at_least("frames", frames, 1)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    pans = tuple(float(p) for p in head_scan_deg)
    if not pans or not all(math.isfinite(p) and abs(p) <= 90.0 for p in pans):
        raise ValueError(f"head_scan_deg must be non-empty pans within ±90°, got {head_scan_deg!r}")

    def frame(obs: dict[str, np.ndarray]) -> Frame:
        odo = tuple(float(v) for v in obs["odometry"])
        return obs["image"], float(obs["head"][0]), odo  # type: ignore[return-value]

    obs, _ = env.reset(seed=int(seed), options={"pose": (x, y, yaw)})
    out = [frame(obs)]
    for k in range(1, n):
        action = env.velocity_action(pan_deg=pans[k % len(pans)])
        obs, _, terminated, _, _ = env.step(action)
        if terminated:
            raise RobotFell(f"the robot fell while standing at {(x, y, yaw)} (frame {k})")
        out.append(frame(obs))
    return out


def learning_turn(
    room: AiboRoomEnv, spot: Sequence[float], frames_per_direction: int, seed: int
) -> list[tuple[np.ndarray, Camera]]:
    """The frames of a learning turn at ``spot`` with their true camera yaws.

    The robot stands facing 0°, 45°, ..., 315° in turn (paper 4.3), scanning with its
    head for ``frames_per_direction`` frames each (:func:`look`, seeds ``seed + k``);
    every frame comes with the camera that took it (its yaw the body's plus the
    measured pan). The truth, not odometry: every sensor taught with it gets the
    same, exact headings.
    """
    env = getattr(room, "unwrapped", room)
    camera = Camera(hfov_deg=env.camera.hfov_deg)
    out = []
    for k in range(8):
        for image, pan, _ in look(room, (*spot, 45.0 * k), frames_per_direction, seed=seed + k):
            out.append((image, camera.replace(yaw_deg=45.0 * k + pan)))
    return out


# ---------------------------------------------------------------------- evaluation
def evaluate_view(
    frames: Sequence[Frame],
    atlas: CompassAtlas,
    camera: Camera,
    dt_s: float,
    true_heading_deg: float,
    trackers: Mapping[str, TrackerSpec],
) -> tuple[dict[str, dict[str, float]], dict[str, float]]:
    """What every tracker believes after a view's frames (the heading of paper 5.1).

    Each tracker is built with :func:`~vc_gym.localization.make_tracker` (a tracker
    instance is used as is), reset with ``atlas``, ``camera`` and ``dt_s``, and fed
    every frame in order; its final heading (eq. 25-26), spread (eq. 27) and error are
    recorded. The single-frame compass is added under the name ``"compass"``
    (:data:`COMPASS`): the estimate of the last frame alone (eq. 16, no filter) by the
    atlas' one spot, or by the spot that fits the frame best (eq. 28) when there are
    several, turned from the camera's heading into the body's by subtracting the head
    pan.

    Parameters
    ----------
    frames : sequence of tuple
        ``(image, head_pan_deg, odometry)`` per frame, e.g. from :func:`look`.
    atlas : CompassAtlas
        The learned, normalised atlas.
    camera : Camera
        Intrinsics and pitch of the head camera (its yaw is ignored).
    dt_s : float
        Time between frames (the room's ``control_dt``).
    true_heading_deg : float
        The robot's true body heading.
    trackers : mapping
        ``{name: spec}`` of trackers (any :data:`~vc_gym.localization.TrackerSpec`).
        ``"compass"`` is reserved.

    Returns
    -------
    figures : dict
        ``{name: {"heading_deg", "heading_error_deg", "heading_spread_deg"}}`` as
        plain floats: heading in ``[0, 360)``, error = estimate − truth wrapped to
        ``[-180, 180)``, spread the circular standard deviation (clipped to
        ``[0, 180]``°).
    timing : dict
        ``{name: milliseconds per frame}`` (tracker update, or one compass estimate):
        kept apart from ``figures`` because it depends on the machine.

    Raises
    ------
    ValueError
        On empty or malformed frames, a bad atlas, camera, ``dt_s`` or heading, a
        tracker named ``"compass"`` or a bad tracker spec.
    """
    fr = _frames(frames)
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    dt = positive_float("dt_s", dt_s)
    truth = finite_float("true_heading_deg", true_heading_deg)
    if not isinstance(trackers, Mapping):
        raise ValueError(f"trackers must be a mapping {{name: spec}}, got {trackers!r}")
    if COMPASS in trackers:
        raise ValueError(f"the tracker name {COMPASS!r} is reserved for the single-frame compass")

    def record(heading: float, spread: float) -> dict[str, float]:
        heading = float(wrap360(heading))
        return {
            "heading_deg": heading,
            "heading_error_deg": float(wrap180(heading - truth)),
            "heading_spread_deg": float(min(max(spread, 0.0), 180.0)),
        }

    figures: dict[str, dict[str, float]] = {}
    timing: dict[str, float] = {}
    for name, spec in trackers.items():
        tracker = make_tracker(spec)
        tracker.reset(atlas, camera, dt)
        state = None
        t0 = time.perf_counter()
        for image, pan, odo in fr:
            state = tracker.update(image, pan, np.asarray(odo, dtype=np.float64))
        elapsed = time.perf_counter() - t0
        figures[str(name)] = record(state.heading_deg, state.heading_spread_deg)
        timing[str(name)] = 1e3 * elapsed / len(fr)
    image, pan, _ = fr[-1]
    t0 = time.perf_counter()
    if len(atlas) == 1:
        est = atlas.compasses[0].estimate(image, camera)
    else:  # the map that fits the frame best (eq. 28)
        found = atlas.estimate_position(image, camera)
        est = found.estimates[max(found.goodness, key=found.goodness.get)]
    timing[COMPASS] = 1e3 * (time.perf_counter() - t0)
    figures[COMPASS] = record(est.heading_deg - pan, est.spread_deg)
    return figures, timing


def spot_goodness(frames: Sequence[Frame], atlas: CompassAtlas, camera: Camera) -> dict[str, float]:
    """Mean normalised goodness ``L̂_i`` of every spot over the frames (eq. 28, fig. 5 right).

    ``L̂_i = exp(score_i − home_score_i)`` (see
    :meth:`~vc_gym.compass.CompassAtlas.estimate_position`): the geometric-mean
    likelihood per term of the frame under spot ``i``'s map at its best heading,
    relative to frames taken at home; 1 at home after normalisation, smaller where the
    frame fits the spot worse. The head pan plays no part (each spot takes its best
    heading).

    Parameters
    ----------
    frames : sequence of tuple
        ``(image, head_pan_deg, odometry)`` per frame, e.g. from :func:`look`.
    atlas : CompassAtlas
        The learned atlas (normalised, or the goodness is ``exp(score)``).
    camera : Camera
        Intrinsics and pitch of the head camera.

    Returns
    -------
    dict
        ``{spot name: mean L̂_i}`` in ``atlas.names`` order, plain floats.
    """
    fr = _frames(frames)
    if not isinstance(atlas, CompassAtlas):
        raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    total = np.zeros(len(atlas.names))
    for image, _, _ in fr:
        g = atlas.estimate_position(image, camera).goodness
        total += [g[n] for n in atlas.names]
    return {n: float(v / len(fr)) for n, v in zip(atlas.names, total, strict=True)}


def distance_table(
    distances: Sequence[float] | np.ndarray,
    errors: Sequence[float] | np.ndarray,
    spreads: Sequence[float] | np.ndarray,
    bin_m: float = 0.5,
) -> list[dict[str, float]]:
    """Heading error and spread per distance from the training spot (fig. 4 right).

    Bin ``k`` holds the views with ``k · bin_m <= distance < (k + 1) · bin_m``; only
    bins with views are listed.

    Parameters
    ----------
    distances : array_like
        Distance of each view from the training spot, metres, >= 0.
    errors : array_like
        Signed heading error of each view, degrees (wrapped to ±180° here).
    spreads : array_like
        Reported heading spread of each view, degrees.
    bin_m : float
        Width of a distance bin.

    Returns
    -------
    list of dict
        Per non-empty bin, in order of distance: ``bin_start_m``, ``bin_end_m``,
        ``distance_m`` (mean distance of its views), ``n``, ``mean_abs_error_deg``,
        ``median_abs_error_deg``, ``mean_spread_deg`` (plain numbers).

    Raises
    ------
    ValueError
        Arrays that are not 1-D of one length or not finite, negative distances, or a
        bad ``bin_m``.
    """
    d = np.asarray(distances, dtype=np.float64)
    e = np.asarray(errors, dtype=np.float64)
    s = np.asarray(spreads, dtype=np.float64)
    if d.ndim != 1 or e.shape != d.shape or s.shape != d.shape:
        raise ValueError(
            f"distances, errors and spreads must be 1-D of one length, got shapes "
            f"{d.shape}, {e.shape}, {s.shape}"
        )
    for name, a in (("distances", d), ("errors", e), ("spreads", s)):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite")
    if np.any(d < 0):
        raise ValueError("distances must be >= 0")
    width = positive_float("bin_m", bin_m)
    abs_err = np.abs(np.asarray(wrap180(e), dtype=np.float64))
    index = np.floor(d / width).astype(np.int64)
    rows = []
    for k in np.unique(index):
        sel = index == k
        rows.append(
            {
                "bin_start_m": float(k * width),
                "bin_end_m": float((k + 1) * width),
                "distance_m": float(d[sel].mean()),
                "n": int(sel.sum()),
                "mean_abs_error_deg": float(abs_err[sel].mean()),
                "median_abs_error_deg": float(np.median(abs_err[sel])),
                "mean_spread_deg": float(s[sel].mean()),
            }
        )
    return rows


# ---------------------------------------------------------------------- plots
def _field_axes(ax: Any, field_bounds: tuple[float, float, float, float]) -> None:
    x0, x1, y0, y1 = field_bounds
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="0.3", lw=1.2))
    pad = 0.3
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def plot_error_vs_distance(
    path: str | os.PathLike,
    table_by_tracker: Mapping[str, Sequence[Mapping[str, float]]],
    paper_line_deg: float = PAPER_ERROR_DEG,
) -> None:
    """Mean |heading error| and mean spread vs distance from the spot (fig. 4 right).

    One line per tracker in each of two panels (error left, spread right), plotted at
    each bin's mean distance. Dashed lines mark the paper's claim (5.1): the mean error
    stays below ``paper_line_deg`` (10°) within :data:`PAPER_RANGE_M` (2 m).

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    table_by_tracker : mapping
        ``{tracker name: distance_table(...)}``.
    paper_line_deg : float
        Height of the paper's error line.
    """
    if not isinstance(table_by_tracker, Mapping) or not table_by_tracker:
        raise ValueError("table_by_tracker must be a non-empty {name: distance table} mapping")
    line = finite_float("paper_line_deg", paper_line_deg)
    fig = new_figure(figsize=(11, 4.2))
    ax_e, ax_s = fig.subplots(1, 2, sharex=True)
    for name, rows in table_by_tracker.items():
        if not rows:
            continue
        dist = [r["distance_m"] for r in rows]
        ax_e.plot(dist, [r["mean_abs_error_deg"] for r in rows], "o-", label=str(name))
        ax_s.plot(dist, [r["mean_spread_deg"] for r in rows], "o-", label=str(name))
    ax_e.axhline(line, ls="--", c="k", lw=1, label=f"paper: < {line:g}° within {PAPER_RANGE_M:g} m")
    for ax in (ax_e, ax_s):
        ax.axvline(PAPER_RANGE_M, ls="--", c="0.4", lw=1)
        ax.set_xlabel("distance from the training spot (m)")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    ax_e.set_ylabel("mean |heading error| (deg)")
    ax_s.set_ylabel("mean heading spread (deg)")
    ax_e.set_title("heading error vs distance")
    ax_s.set_title("reported spread vs distance")
    ax_e.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)


def plot_arrow_field(
    path: str | os.PathLike,
    poses: np.ndarray,
    estimated_headings: Sequence[float] | np.ndarray,
    spot: tuple[float, float],
    field_bounds: tuple[float, float, float, float],
    title: str,
    reference_deg: float | None = None,
) -> None:
    """An arrow per view in the estimated heading, coloured by its error (fig. 4 left).

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    poses : numpy.ndarray
        ``(N, 3)`` true poses ``(x, y, yaw_deg)`` of the views.
    estimated_headings : array_like
        ``(N,)`` estimated body headings, degrees.
    spot : tuple of float or sequence of them
        The training spot ``(x, y)`` (marked with a star, with the paper's 2 m circle),
        or several spots (marked with stars).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field (drawn as its outline).
    title : str
        Figure title.
    reference_deg : float, optional
        Draw each arrow at ``reference_deg + error`` instead of the estimate: as if
        every robot had faced ``reference_deg``, so right estimates all point one way
        (the paper's figure: every arrow towards the opponent goal).
    """
    p = np.asarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ValueError(f"poses must be a finite (N, 3) array, got shape {p.shape}")
    est = np.asarray(estimated_headings, dtype=np.float64)
    if est.shape != (p.shape[0],) or not np.all(np.isfinite(est)):
        raise ValueError(f"estimated_headings must be {p.shape[0]} finite numbers")
    spots = spots_array(spot)
    bounds = _bounds(field_bounds, "field_bounds")
    err = np.asarray(wrap180(est - p[:, 2]), dtype=np.float64)
    if reference_deg is None:
        direction = est
    else:
        direction = finite_float("reference_deg", reference_deg) + err
    th = np.radians(direction)
    fig = new_figure(figsize=(8, 6))
    ax = fig.subplots()
    _field_axes(ax, bounds)
    length = 0.25
    q = ax.quiver(
        p[:, 0],
        p[:, 1],
        length * np.cos(th),
        length * np.sin(th),
        np.abs(err),
        cmap="viridis_r",
        clim=(0.0, 90.0),
        angles="xy",
        scale_units="xy",
        scale=1.0,
        width=0.004,
        pivot="tail",
    )
    fig.colorbar(q, ax=ax, label="|heading error| (deg, clipped at 90)", shrink=0.8)
    ax.plot(
        spots[:, 0],
        spots[:, 1],
        marker="*",
        ms=16 if len(spots) == 1 else 11,
        c="red",
        mec="k",
        ls="none",
        label="training spot" if len(spots) == 1 else "training spots",
    )
    if len(spots) == 1:
        ax.add_patch(
            Circle(
                tuple(spots[0]),
                PAPER_RANGE_M,
                fill=False,
                ls=":",
                ec="red",
                lw=1,
                label=f"{PAPER_RANGE_M:g} m (paper: error < {PAPER_ERROR_DEG:g}° inside)",
            )
        )
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(str(title))
    fig.tight_layout()
    save_figure(fig, path)


def plot_goodness_field(
    path: str | os.PathLike,
    positions: np.ndarray,
    goodness: Sequence[float] | np.ndarray,
    spot: tuple[float, float],
    field_bounds: tuple[float, float, float, float],
) -> None:
    """The normalised goodness ``L̂`` of one spot over a grid of positions (fig. 5 right).

    Values at equal positions (several headings) are averaged. A regular grid (e.g.
    :func:`field_grid`) is drawn as a heat map with the value written in each cell,
    other positions as coloured squares.

    Parameters
    ----------
    path : path-like
        PNG to write (atomically).
    positions : numpy.ndarray
        ``(N, 2)`` positions ``(x, y)``.
    goodness : array_like
        ``(N,)`` goodness of the spot at each position (:func:`spot_goodness`).
    spot : tuple of float
        The training spot (marked with a star).
    field_bounds : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the field (drawn as its outline).
    """
    p = _positions(positions)
    g = np.asarray(goodness, dtype=np.float64)
    if g.shape != (p.shape[0],) or not np.all(np.isfinite(g)):
        raise ValueError(f"goodness must be {p.shape[0]} finite numbers")
    if p.shape[0] == 0:
        raise ValueError("positions must not be empty")
    sx, sy = _spot(spot)
    bounds = _bounds(field_bounds, "field_bounds")
    key = np.round(p, 6)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    mean = np.bincount(inverse, weights=g) / np.bincount(inverse)
    xs, ys = np.unique(uniq[:, 0]), np.unique(uniq[:, 1])
    fig = new_figure(figsize=(8, 6))
    ax = fig.subplots()
    regular = xs.size * ys.size == uniq.shape[0] and xs.size > 1 and ys.size > 1
    if regular:
        grid = np.full((ys.size, xs.size), np.nan)
        grid[np.searchsorted(ys, uniq[:, 1]), np.searchsorted(xs, uniq[:, 0])] = mean

        def edges(c: np.ndarray) -> np.ndarray:
            mid = 0.5 * (c[1:] + c[:-1])
            return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])

        im = ax.pcolormesh(edges(xs), edges(ys), grid, cmap="magma", shading="flat")
        if uniq.shape[0] <= 400:
            mid = 0.5 * (np.nanmin(grid) + np.nanmax(grid))
            for (x, y), v in zip(uniq, mean, strict=True):
                ax.text(
                    x,
                    y,
                    f"{v:.2f}",
                    ha="center",
                    va="center",
                    fontsize=6,
                    color="k" if v > mid else "w",
                )
    else:
        im = ax.scatter(uniq[:, 0], uniq[:, 1], c=mean, cmap="magma", marker="s", s=60)
    _field_axes(ax, bounds)
    fig.colorbar(im, ax=ax, label="normalised goodness L̂ (eq. 28)", shrink=0.8)
    ax.plot([sx], [sy], marker="*", ms=16, c="cyan", mec="k", ls="none", label="training spot")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("goodness of the spot's map over the field (paper fig. 5 right)")
    fig.tight_layout()
    save_figure(fig, path)
