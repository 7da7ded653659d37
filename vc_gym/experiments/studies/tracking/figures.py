"""The tracking experiment's measures: the time to re-localise after a kidnapping
(:func:`relocalisation_time`), the 2σ coverage of a stated uncertainty
(:func:`two_sigma_coverage`), one route's figures from its recorded frames
(:func:`route_figures`), and the figures of a set of routes pooled frame by frame, per
learning seed and as mean ± std over seeds (:func:`summary`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vc_gym.angles import wrap180
from vc_gym.experiments.studies.kidnapping import mean_std

__all__ = [
    "BIN_S",
    "OVER_SEEDS",
    "RELOCALISED_HEADING_DEG",
    "RELOCALISED_HOLD_S",
    "RELOCALISED_POSITION_M",
    "RELOCALISED_WITHIN_S",
    "frame_errors",
    "relocalisation_time",
    "route_figures",
    "tracker_summary",
    "two_sigma_coverage",
]

#: Re-localised: the position error stays within this (m) ...
RELOCALISED_POSITION_M = 0.3
#: ... and the heading error within this (degrees) ...
RELOCALISED_HEADING_DEG = 10.0
#: ... for at least this long (s).
RELOCALISED_HOLD_S = 2.0
#: The share of kidnappings re-localised within this many seconds is reported.
RELOCALISED_WITHIN_S = 10.0
#: Errors against time are averaged in bins this long (s) in ``results.json``.
BIN_S = 1.0
#: The error figures of a set of routes, averaged over learning seeds.
OVER_SEEDS = (
    "mean_heading_error_deg",
    "mean_position_error_m",
    "mean_heading_error_with_relocalisation_deg",
    "mean_position_error_with_relocalisation_m",
    "relocalised_within_10s",
    "heading_coverage_2sigma",
    "position_coverage_2sigma",
)


def relocalisation_time(
    t_s: Sequence[float],
    position_error_m: Sequence[float],
    heading_error_deg: Sequence[float],
    kidnap_s: float,
    position_m: float = RELOCALISED_POSITION_M,
    heading_deg: float = RELOCALISED_HEADING_DEG,
    hold_s: float = RELOCALISED_HOLD_S,
) -> float | None:
    """Seconds from the kidnapping until the tracker has the robot again, or ``None``.

    The first frame at or after ``kidnap_s`` from which on the position error stays
    within ``position_m`` and the absolute heading error within ``heading_deg`` for at
    least ``hold_s`` (every frame up to ``hold_s`` later, and the route lasts that
    long); its time minus ``kidnap_s``. ``None`` when there is no such frame within the
    route.

    Parameters
    ----------
    t_s : sequence of float
        Frame times, increasing.
    position_error_m, heading_error_deg : sequence of float
        The errors at those frames (the heading error's sign is ignored).
    kidnap_s : float
        Time of the kidnapping.
    position_m, heading_deg, hold_s : float
        The criteria.
    """
    t = np.asarray(t_s, np.float64)
    pos = np.asarray(position_error_m, np.float64)
    head = np.asarray(heading_error_deg, np.float64)
    if not (t.ndim == 1 and t.size and t.shape == pos.shape == head.shape):
        raise ValueError("t_s and the errors must be non-empty 1-D sequences of one length")
    ok = (pos <= position_m) & (np.abs(head) <= heading_deg)
    eps = 1e-9
    # bad[j]: frames up to j that break the criteria; a window [i, end] is clean when
    # none break it between i and end
    broken = np.concatenate([[0], np.cumsum(~ok)])
    for i in np.flatnonzero((t >= kidnap_s - eps) & ok):
        end_t = t[i] + hold_s
        if t[-1] < end_t - eps:
            return None  # the route ends before the hold could be seen
        j = int(np.searchsorted(t, end_t + eps, side="right"))  # frames in [t_i, t_i + hold]
        if broken[j] - broken[i] == 0:
            return round(float(t[i] - kidnap_s), 6)
    return None


def two_sigma_coverage(error: Sequence[float], sigma: Sequence[float]) -> float | None:
    """Share of the entries where ``|error| <= 2 sigma`` (``None`` for none).

    For the heading pass the frames' heading errors and spreads; for the position the
    ``(frames, 2)`` per-axis errors and standard deviations (a share of (frame, axis)
    pairs). A calibrated Gaussian belief covers about 95 %.
    """
    e = np.abs(np.asarray(error, np.float64))
    s = np.asarray(sigma, np.float64)
    if e.shape != s.shape:
        raise ValueError(f"error and sigma differ in shape: {e.shape} vs {s.shape}")
    if e.size == 0:
        return None
    return float(np.mean(e <= 2.0 * s))


def frame_errors(frames: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Per frame: heading error (wrapped, deg), per-axis and total position error (m)."""
    true = np.asarray(frames["true"], np.float64).reshape(-1, 3)
    est = np.asarray(frames["estimate"], np.float64).reshape(-1, 3)
    axes = est[:, :2] - true[:, :2]
    return {
        "t": np.asarray(frames["t_s"], np.float64),
        "heading": np.asarray(wrap180(est[:, 2] - true[:, 2]), np.float64),
        "axes": axes,
        "position": np.hypot(axes[:, 0], axes[:, 1]),
        "spread": np.asarray(frames["heading_spread_deg"], np.float64),
        "std": np.asarray(frames["position_std_m"], np.float64).reshape(-1, 2),
    }


def _windows(e: Mapping[str, np.ndarray], kidnap_s: float, settle_s: float, reloc: float | None):
    """``(settled, evaluated)`` frame masks: from ``settle_s`` on; the same without the
    re-localisation window (from the kidnapping until re-localised, or the end)."""
    t = e["t"]
    settled = t >= settle_s - 1e-9
    end = math.inf if reloc is None else kidnap_s + reloc
    lost = (t >= kidnap_s - 1e-9) & (t < end - 1e-9)
    return settled, settled & ~lost


def _r(v: float | None, digits: int = 4) -> float | None:
    return None if v is None or not math.isfinite(v) else round(float(v), digits)


def _pooled(parts: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The figures of routes pooled frame by frame (``parts``: :func:`_route_parts`)."""

    def cat(key: str, mask: str) -> np.ndarray:
        arrays = [p["errors"][key][p[mask]] for p in parts]
        return np.concatenate(arrays) if arrays else np.zeros(0)

    def mean_abs(key: str, mask: str) -> float | None:
        v = np.abs(cat(key, mask))
        return float(v.mean()) if v.size else None

    relocs = [p["relocalisation_s"] for p in parts]
    found = [r for r in relocs if r is not None]
    return {
        "routes": len(parts),
        "mean_heading_error_deg": _r(mean_abs("heading", "evaluated"), 2),
        "mean_position_error_m": _r(mean_abs("position", "evaluated")),
        "mean_heading_error_with_relocalisation_deg": _r(mean_abs("heading", "settled"), 2),
        "mean_position_error_with_relocalisation_m": _r(mean_abs("position", "settled")),
        "relocalised": len(found),
        "relocalised_within_10s": _r(
            float(np.mean([r is not None and r <= RELOCALISED_WITHIN_S for r in relocs]))
        )
        if relocs
        else None,
        "median_relocalisation_s": _r(float(np.median(found)), 2) if found else None,
        "heading_coverage_2sigma": _r(
            two_sigma_coverage(cat("heading", "evaluated"), cat("spread", "evaluated"))
        ),
        "position_coverage_2sigma": _r(
            two_sigma_coverage(cat("axes", "evaluated"), cat("std", "evaluated"))
        ),
    }


def _route_parts(frames: Mapping[str, Any], kidnap_s: float, settle_s: float) -> dict[str, Any]:
    e = frame_errors(frames)
    reloc = relocalisation_time(e["t"], e["position"], e["heading"], kidnap_s)
    settled, evaluated = _windows(e, kidnap_s, settle_s, reloc)
    return {"errors": e, "relocalisation_s": reloc, "settled": settled, "evaluated": evaluated}


def route_figures(
    frames: Mapping[str, Any], kidnap_s: float, settle_s: float = 10.0
) -> dict[str, Any]:
    """One route's figures: errors after ``settle_s`` (without and with the
    re-localisation window), the re-localisation time, the 2σ coverage, and the mean
    absolute errors in :data:`BIN_S` bins (``error_over_time``: bin ``k`` holds the
    frames of ``[k, k + 1)`` s, the last one also the route's last frame).

    ``frames`` is a
    :func:`~vc_gym.experiments.studies.tracking.job.route_job`'s ``frames``.
    """
    parts = _route_parts(frames, kidnap_s, settle_s)
    e = parts["errors"]
    out = _pooled([parts])
    del out["routes"], out["relocalised"], out["median_relocalisation_s"]
    out["relocalisation_s"] = _r(parts["relocalisation_s"], 2)
    last = max(int(math.ceil(e["t"][-1] / BIN_S - 1e-9)) - 1, 0)  # the end in the last bin
    k = np.minimum(np.floor(e["t"] / BIN_S + 1e-9).astype(int), last)
    bins = np.unique(k)
    out["error_over_time"] = {
        "bin_s": BIN_S,
        "heading_deg": [round(float(np.abs(e["heading"][k == b]).mean()), 2) for b in bins],
        "position_m": [round(float(e["position"][k == b].mean()), 4) for b in bins],
    }
    return out


def tracker_summary(entries: Sequence[Mapping[str, Any]], settle_s: float) -> dict[str, Any]:
    """Figures of one (scene, light, tracker): pooled, per seed, over seeds, per route."""
    parts = [_route_parts(e["frames"], e["route"]["kidnap_s"], settle_s) for e in entries]
    seeds = sorted({e["seed"] for e in entries})
    per_seed = {
        str(s): _pooled([p for p, e in zip(parts, entries, strict=True) if e["seed"] == s])
        for s in seeds
    }
    over = {}
    for key in OVER_SEEDS:
        values = [v[key] for v in per_seed.values() if v[key] is not None]
        over[key] = mean_std(values) if values else None
    routes = []
    for e in entries:
        r = e["route"]
        true = np.asarray(e["frames"]["true"], np.float64)
        k = int(round(r["kidnap_s"] / (e["frames"]["t_s"][1] - e["frames"]["t_s"][0])))
        routes.append(
            {
                "seed": e["seed"],
                "route": e["index"],
                "start_pose": r["start"],
                "kidnap_s": r["kidnap_s"],
                "kidnap_pose": r["kidnap_pose"],
                "kidnap_distance_m": round(float(np.hypot(*(true[k, :2] - true[k - 1, :2]))), 4),
                **route_figures(e["frames"], r["kidnap_s"], settle_s),
            }
        )
    return {**_pooled(parts), "per_seed": per_seed, "over_seeds": over, "per_route": routes}
