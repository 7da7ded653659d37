"""The likelihood of a frame over candidate headings (paper eq. 5, 11, 15-16, 25-28).

Pure numpy functions on arrays; :class:`~vc_gym.compass.VisualCompass` and
:class:`~vc_gym.compass.CompassAtlas` call them with their maps' tables.

- :func:`sector_features`: the frame's transition counts per (heading phase, relative
  sector, class pair), from which the relative frequencies of eq. 11 follow;
- :func:`log_tables`: a map's smoothed histograms (eq. 2) as log-probability tables;
- :func:`log_likelihoods`: eq. 5 and 16 summed in the log domain, for every candidate
  heading, under one map or several that share a config and colour classes;
- :func:`remapped_log_likelihoods`: the same with each view sector scored against
  another map sector (parallax);
- :func:`heading_estimates`: best heading, spread (eq. 27, calibrated by a temperature:
  :mod:`~vc_gym.compass.calibration`) and goodness (eq. 28).

The log-likelihood is the log of the likelihood *ratio* against the map's
heading-independent model (its histograms pooled over all sectors): it differs from
``log p(image | φ)`` by a term that does not depend on the heading, and a sector the
map has never seen contributes exactly zero.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from vc_gym.angles import circular_std_rows, peak_headings
from vc_gym.compass.calibration import UNCALIBRATED, tempered_spreads
from vc_gym.compass.config import CompassConfig
from vc_gym.compass.features import (
    NOISE_CHANGE_RATIO,
    change_ratio,
    column_transition_counts,
    log2_bin,
)
from vc_gym.compass.scan_geometry import ScanGeometry

__all__ = [
    "POOL_PSEUDOCOUNT",
    "heading_estimates",
    "log_likelihoods",
    "log_tables",
    "remapped_log_likelihoods",
    "sector_features",
]

#: Pseudo-count per bin of the heading-independent (pooled) histogram.
POOL_PSEUDOCOUNT = 0.5
# Table rows gathered at once when scoring a frame against several maps: a few hundred
# kilobytes stay in the cache; one gather of every row (16 MB for 24 maps) makes the
# scoring memory-bound (see _group_sums).
_GATHER_BYTES = 1 << 19


def sector_features(
    classes: np.ndarray, geom: ScanGeometry, config: CompassConfig
) -> tuple[np.ndarray, np.ndarray]:
    """Transition counts per (heading phase, relative sector, class pair) of a frame.

    A frame without a single change of colour class above the horizon (a black,
    covered or overexposed frame, a blank wall) says nothing about the heading: it
    gives no counts at all, so it is treated like a frame that sees nothing above
    the horizon (a flat log-likelihood), not as a confident match of the maps'
    "no change" statistics. So does a frame of noise, whose classes change between
    neighbours as often as those of independent pixels
    (:data:`~vc_gym.compass.features.NOISE_CHANGE_RATIO`): its transitions are
    chance, and matched against the maps they would still pick some heading
    confidently.

    Parameters
    ----------
    classes : numpy.ndarray
        ``(R, U)`` class ids of the scanned pixels (row 0 at the top).
    geom : ScanGeometry
        The scan geometry of the frame's camera and size.
    config : CompassConfig
        Gives the number of classes and whether ``i -> i`` pairs count.

    Returns
    -------
    counts : numpy.ndarray
        ``(P * K, c²)`` float32 counts; row ``p * K + k`` sums the columns that fall
        into relative sector ``k`` at heading phase ``p`` (eq. 13).
    total : numpy.ndarray
        ``(P * K,)`` all transitions of each row (the denominator of eq. 11).
    """
    colcounts = column_transition_counts(classes, config.n_colors, config.count_same_class)
    ratio = change_ratio(classes, config.n_colors)
    if ratio == 0.0 or ratio >= NOISE_CHANGE_RATIO:  # no class change at all, or noise
        colcounts = np.zeros_like(colcounts)
    # integer counts in float32: the cumulative sums and their differences are exact
    cum = np.zeros((colcounts.shape[0] + 1, colcounts.shape[1]), dtype=colcounts.dtype)
    np.cumsum(colcounts, axis=0, out=cum[1:])
    counts = cum[geom.stop_col] - cum[geom.first_col]  # (P*K, c2)
    total = counts.sum(axis=1)
    return counts, total


def log_tables(
    config: CompassConfig, counts: np.ndarray, n_obs: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A map's smoothed histograms (eq. 2) as the tables the likelihood reads.

    Parameters
    ----------
    config : CompassConfig
        Gives the number of bins and the smoothing ``κ``.
    counts : numpy.ndarray
        ``(S, c², n)`` the map's counts (eq. 6).
    n_obs : numpy.ndarray
        ``(S,)`` frames that saw each sector.

    Returns
    -------
    delta_t : numpy.ndarray
        ``(c²·n, S)``: ``delta_t[ij * n + b, s]`` is the log-ratio of bin ``b`` minus
        that of the empty bin, so that only non-zero frequencies need a table read.
    base : numpy.ndarray
        ``(S,)``: the log-ratio of the empty bin summed over all pairs.
    log_abs : numpy.ndarray
        ``(S, c², n)``: the smoothed log-probability ``log p(bin | sector, i→j)``;
        the log-ratio is ``log_abs`` minus the log of the pooled histogram.
    """
    n = config.n_bins
    pooled = counts.sum(axis=0) + POOL_PSEUDOCOUNT  # (c2, n)
    p_pool = pooled / pooled.sum(axis=1, keepdims=True)
    kappa = config.smoothing
    # in place where the result replaces its input: a map-sized array costs
    # 8 bytes per count, and at most two live beside the counts and delta_t
    # (CompassConfig.memory_bytes)
    log_abs = counts + kappa * p_pool[None]
    log_abs /= n_obs[:, None, None] + kappa
    np.log(log_abs, out=log_abs)
    delta = log_abs - np.log(p_pool)[None]  # the log-ratio against the pooled model
    last = delta[:, :, n - 1 : n].copy()
    base = last[:, :, 0].sum(axis=1)  # (S,)
    delta -= last  # (S, c2, n)
    delta_t = np.ascontiguousarray(delta.reshape(delta.shape[0], -1).T)  # (c2*n, S)
    del delta
    return delta_t, base, log_abs


def log_likelihoods(
    config: CompassConfig,
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    delta_t: np.ndarray,
    base: np.ndarray,
    maps: np.ndarray | None = None,
) -> np.ndarray:
    """Log-likelihood over headings (eq. 5, 15-16) of one frame under several maps.

    The maps share ``config`` and colour classes, so the frame's sector features
    (``geom``, ``counts``, ``total``) and which table rows they read are computed once.

    Parameters
    ----------
    config : CompassConfig
        The maps' config.
    geom : ScanGeometry
        The frame's scan geometry.
    counts, total : numpy.ndarray
        The frame's :func:`sector_features`.
    delta_t, base : numpy.ndarray
        ``(c²·n, M, S)`` and ``(M, S)``: the maps' :func:`log_tables` stacked (rows
        first, so that one read brings a row of every map). Sums run in the same order
        for any ``M``, so each map's row equals its own single-map answer bit for bit.
    maps : numpy.ndarray, optional
        Indices into ``M``: score only those maps, reading only their tables.

    Returns
    -------
    numpy.ndarray
        ``(M, n_headings)`` (``(len(maps), n_headings)``), divided by
        ``config.temperature``; all zeros where nothing was seen.
    """
    m = base.shape[0] if maps is None else len(maps)
    per_group = _group_scores(config, geom, counts, total, delta_t, base, maps)
    if per_group is None:
        return np.zeros((m, geom.heading_phase.size))
    # score[p, m, s0] = sum_k per_group[p, k, m, s0 + k + kmin]; the advanced indices
    # come first: (K, S, P, M), summed over K
    by_start = per_group[:, np.arange(geom.n_rel)[:, None], :, geom.roll_index].sum(axis=0)
    return _by_heading(config, geom, by_start)


def remapped_log_likelihoods(
    config: CompassConfig,
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    delta_t: np.ndarray,
    base: np.ndarray,
    sector_maps: np.ndarray,
) -> np.ndarray:
    """Log-likelihood over headings of one frame under re-indexings of one map.

    Parameters
    ----------
    config, geom, counts, total
        As for :func:`log_likelihoods`.
    delta_t, base : numpy.ndarray
        ``(c²·n, S)`` and ``(S,)``: one map's :func:`log_tables`.
    sector_maps : numpy.ndarray
        ``(N, S)`` checked integers: row ``n`` says which map sector describes each
        direction sector; the identity row gives :func:`log_likelihoods` bit for bit.

    Returns
    -------
    numpy.ndarray
        ``(N, n_headings)``: row ``n`` is eq. 5, 16 with sector ``s`` of the view
        scored against map sector ``sector_maps[n, s]``.
    """
    per_group = _group_scores(config, geom, counts, total, delta_t[:, None, :], base[None])
    if per_group is None:
        return np.zeros((sector_maps.shape[0], geom.heading_phase.size))
    idx = sector_maps[:, geom.roll_index]  # (N, K, S): map sector of relative k at start s0
    k = np.arange(geom.n_rel)[None, :, None]
    by_start = per_group[:, k, 0, idx].sum(axis=2)  # (P, N, S)
    return _by_heading(config, geom, by_start.transpose(2, 0, 1))


def heading_estimates(
    config: CompassConfig,
    headings: np.ndarray,
    log_abs: Sequence[np.ndarray],
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    lls: np.ndarray,
    spread_calibrations: Sequence[tuple[float, float]] | None = None,
) -> tuple[np.ndarray, np.ndarray, list[float], list[int]]:
    """Best heading, spread and goodness of one frame under each of ``M`` maps.

    Parameters
    ----------
    config : CompassConfig
        The maps' config.
    headings : numpy.ndarray
        The candidate headings in degrees.
    log_abs : sequence of numpy.ndarray
        Each map's ``log_abs`` table (:func:`log_tables`).
    geom, counts, total
        The frame's scan geometry and :func:`sector_features`.
    lls : numpy.ndarray
        ``(M, n_headings)`` log-likelihoods (:func:`log_likelihoods`).
    spread_calibrations : sequence of (float, float), optional
        Each map's ``(temperature, floor_deg)`` (:mod:`~vc_gym.compass.calibration`);
        default :data:`~vc_gym.compass.calibration.UNCALIBRATED` for every map.

    Returns
    -------
    heading : numpy.ndarray
        ``(M,)`` the arg-max heading, refined by a parabola through the peak and its
        neighbours.
    spread : numpy.ndarray
        ``(M,)`` the circular standard deviation (eq. 27) of the posterior
        ``∝ exp(log-likelihood / temperature)``, at least ``floor_deg``; uncalibrated
        (temperature 1, no floor) the paper's. Infinite for a frame without evidence
        (no sector contributed): its posterior is uniform, whose mean resultant length
        is 0 and ``sqrt(-2 ln 0)`` infinite.
    scores : list of float
        The mean per-term log-probability at the best heading (eq. 28).
    n_sectors : list of int
        The sectors the frame contributed at the best heading.
    """
    m = lls.shape[0]
    heading, best = peak_headings(lls, config.heading_step_deg)
    cal = [UNCALIBRATED] * m if spread_calibrations is None else list(spread_calibrations)
    if len(cal) != m:
        raise ValueError(f"need one spread calibration per map ({m}), got {len(cal)}")
    if all(c == UNCALIBRATED for c in cal):
        spread = circular_std_rows(headings, np.exp(lls - lls[np.arange(m), best][:, None]))
    else:
        t, floor = (np.array(v, dtype=np.float64) for v in zip(*cal, strict=True))
        spread = tempered_spreads(lls, headings, t, floor)
    scores, n_sectors = _scores_at(config, log_abs, geom, counts, total, best)
    spread[np.asarray(n_sectors) == 0] = np.inf
    return heading, spread, scores, n_sectors


def _by_heading(config: CompassConfig, geom: ScanGeometry, by_start: np.ndarray) -> np.ndarray:
    """``(X, n_headings)`` log-likelihoods from the scores ``by_start[s0, p, x]`` of
    every starting sector and phase (``X`` maps, or re-indexings of one map)."""
    ll = by_start[geom.heading_sector, geom.heading_phase].T
    if config.temperature != 1.0:
        ll = ll / config.temperature
    return np.ascontiguousarray(ll)


def _group_scores(
    config: CompassConfig,
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    delta_t: np.ndarray,
    base: np.ndarray,
    maps: np.ndarray | None = None,
) -> np.ndarray | None:
    """``(P, K, M, S)``: the log-ratio of the frame's columns of phase ``p`` and relative
    sector ``k`` under sector ``s`` of map ``m`` (see :func:`log_likelihoods`);
    ``None`` if the frame saw nothing."""
    if maps is not None:
        base = base[maps]
    m = base.shape[0]
    n = config.n_bins
    seen = total > 0
    if not seen.any():
        return None
    nz_group, nz_code = np.nonzero(counts)
    z = counts[nz_group, nz_code] / total[nz_group]
    rows = nz_code * n + log2_bin(z, n)
    per_group = _group_sums(delta_t, rows, nz_group, counts.shape[0], maps)
    per_group[seen] += base[None, :, :]
    return per_group.reshape(-1, geom.n_rel, m, config.n_sectors)


def _group_sums(
    delta_t: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    n_groups: int,
    maps: np.ndarray | None,
) -> np.ndarray:
    """``out[g, m, s] = Σ delta_t[rows[e], maps[m], s]`` over the entries ``e`` of group
    ``g`` (``groups`` sorted, as :func:`numpy.nonzero` gives them); ``(n_groups, M, S)``.

    The rows are gathered a few whole groups at a time (:data:`_GATHER_BYTES`), so the
    gathered block stays in the cache. Each group is still one ``reduceat`` segment
    summed in order, so the sums are bit for bit those of a single gather, for any
    number of maps.
    """
    m = delta_t.shape[1] if maps is None else maps.size
    out = np.zeros((n_groups, m, delta_t.shape[2]))
    if rows.size == 0:
        return out
    starts = np.flatnonzero(np.r_[True, groups[1:] != groups[:-1]])
    bounds = np.r_[starts, rows.size]
    per_chunk = max(1, _GATHER_BYTES // (m * delta_t.shape[2] * delta_t.itemsize))
    i = 0
    while i < starts.size:
        # the groups that fit in per_chunk rows, at least one
        j = int(np.searchsorted(bounds, bounds[i] + per_chunk, side="right")) - 1
        j = min(max(j, i + 1), starts.size)
        a, b = bounds[i], bounds[j]
        if maps is None:
            gathered = np.take(delta_t, rows[a:b], axis=0)  # (E, M, S)
        else:
            gathered = delta_t[rows[a:b, None], maps[None, :]]
        out[groups[starts[i:j]]] = np.add.reduceat(gathered, starts[i:j] - a, axis=0)
        i = j
    return out


def _scores_at(
    config: CompassConfig,
    log_abs: Sequence[np.ndarray],
    geom: ScanGeometry,
    counts: np.ndarray,
    total: np.ndarray,
    best: np.ndarray,
) -> tuple[list[float], list[int]]:
    """Each map's goodness at its own best heading: the mean per-term log-probability
    of the frame's features (eq. 28) and the number of sectors used; the frame's bins
    are read once per heading phase."""
    k_rel = geom.n_rel
    scores, used = [0.0] * len(log_abs), [0] * len(log_abs)
    phases = geom.heading_phase[best]
    for p in np.unique(phases):
        t = total[p * k_rel : (p + 1) * k_rel]
        seen = np.flatnonzero(t > 0)
        if seen.size == 0:
            continue
        c = counts[p * k_rel : (p + 1) * k_rel]
        bins = log2_bin(c[seen] / t[seen, None], config.n_bins)  # (seen, c2)
        pairs = np.arange(c.shape[1])[None, :]
        for k in np.flatnonzero(phases == p):
            sectors = (geom.heading_sector[best[k]] + seen + geom.kmin) % config.n_sectors
            scores[k] = float(log_abs[k][sectors[:, None], pairs, bins].mean())
            used[k] = int(seen.size)
    return scores, used
