"""The paper's parameter studies (5.3): colour classes, scanning coverage, sectors, bins.

One compass parameter is varied at a time around the paper's configuration (10 colour
classes, 25 % coverage, 4.5° sectors, 8 histogram bins). For every value the robot
learns the training spot of the orientation experiment with that configuration (one
saved atlas per configuration; the paper's configuration is learned once and shared
by all four sweeps) and is put at a grid of poses; the heading error of the
single-frame compass and of the paper's grid filter is recorded, and the time per
frame to learn and to localise goes to ``run.json``. The paper: three colour classes
suffice, and a coverage below 1 % does not substantially hurt; learning takes < 4 ms
and localisation 13 ms per frame on the Aibo.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vc_gym.compass import CompassConfig
from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
    median_timings,
    one_scene,
    open_run,
    pick_size,
    scene_field_bounds,
)
from vc_gym.experiments.studies.orientation_grid import (
    headline_errors,
    rear_half_centre,
    view_jobs,
    views_summary,
)
from vc_gym.experiments.views import COMPASS
from vc_gym.jobs.output import new_figure, save_figure

__all__ = ["PARAMETERS", "run_params", "summary_lines"]

#: The values of every parameter study (the paper's configuration is among them).
PARAMETERS: dict[str, tuple[float, ...]] = {
    "n_colors": (2, 3, 4, 6, 8, 10, 12, 16),
    "coverage": (1.0, 0.25, 0.1, 0.04, 0.01, 0.005),
    "sector_deg": (2.25, 4.5, 9.0, 18.0),
    "n_bins": (2, 4, 8, 16),
}
QUICK_PARAMETERS: dict[str, tuple[float, ...]] = {
    "n_colors": (3, 10),
    "coverage": (0.25, 0.01),
    "sector_deg": (4.5,),
    "n_bins": (8,),
}
SIZES = {
    "quick": {"spacing_m": 2.0, "headings": 1, "frames": 3, "learn_time_s": 0.5},
    "paper": {"spacing_m": 1.0, "headings": 1, "frames": 6, "learn_time_s": 5.0},
    "full": {"spacing_m": 0.5, "headings": 2, "frames": 10, "learn_time_s": 5.0},
}
TRACKERS = {"grid": "grid"}


def _config_label(config: Mapping[str, Any]) -> str:
    defaults = CompassConfig().to_dict()
    diff = {k: v for k, v in config.items() if defaults.get(k) != v}
    return ",".join(f"{k}={v}" for k, v in sorted(diff.items())) or "paper"


def run_params(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    scenes: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Run the parameter studies and write ``results.json``, ``run.json`` and ``params.png``.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size (``quick`` sweeps two values of two parameters), backend, ...
    scenes : sequence of str, optional
        One scene (default ``["robolab"]``).

    Returns
    -------
    dict
        Per parameter and value: mean and median |heading error| of the compass and
        the grid filter, within 2 m and overall.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    sweeps = QUICK_PARAMETERS if opts.size == "quick" else PARAMETERS
    scene = one_scene(scenes, "parameter studies")
    run = open_run(
        out_dir,
        "params",
        opts,
        {"scene": scene, "values": {k: list(v) for k, v in sweeps.items()}, **size},
    )
    bounds = scene_field_bounds(scene)
    spot = rear_half_centre(bounds)
    configs: dict[str, dict[str, Any]] = {}  # label -> config fields
    for param, values in sweeps.items():
        for v in values:
            cfg = CompassConfig(**{param: v}).to_dict()
            configs[_config_label(cfg)] = cfg
    specs = {
        label: atlas_spec(scene, opts.seed, "spot", size["learn_time_s"], cfg, spot=spot)
        for label, cfg in configs.items()
    }
    paths = ensure_atlases(run, list(specs.values()), opts.atlas_dir)
    summaries: dict[str, dict[str, Any]] = {}
    for label, spec in specs.items():
        jobs = view_jobs(
            "pos-",
            scene,
            paths[atlas_key(spec)],
            spot,
            bounds,
            size,
            opts.seed,
            TRACKERS,
            time_learning=True,
        )
        outputs = run.run(f"views-{label}", jobs)
        summaries[label] = views_summary(outputs, list(TRACKERS))
    results: dict[str, Any] = {
        "paper": {
            "claims": [
                "three colour classes are sufficient",
                "coverage below 1 % without substantial impact",
                "learn < 4 ms, localise 13 ms per frame (Aibo, paper configuration)",
            ],
            "configuration": CompassConfig().to_dict(),
        },
        "training_spot": list(spot),
        "studies": {},
    }
    costs = _costs(run, list(configs))
    for param, values in sweeps.items():
        rows = []
        for v in values:
            label = _config_label(CompassConfig(**{param: v}).to_dict())
            s = summaries[label]
            row = {"value": v, "views": s["views"]}
            row.update(headline_errors(s, list(TRACKERS)))
            rows.append(row)
        results["studies"][param] = rows
    _plot(run.out / "params.png", results["studies"], costs)
    return run.finish(results, {"ms_per_frame": costs})


def _costs(run, labels: Sequence[str]) -> dict[str, dict[str, float]]:
    """Median ms per frame (learn, compass, grid) per configuration, from the jobs."""
    return {
        label: median_timings(run.timings.get(f"views-{label}", {}).values()) for label in labels
    }


def _plot(path: Path, studies: Mapping[str, Any], costs: Mapping[str, Any]) -> None:
    studies = {k: v for k, v in studies.items() if len(v) > 1}
    if not studies:
        return
    fig = new_figure(figsize=(4.2 * len(studies), 3.8), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(studies)))
    for ax, (param, rows) in zip(axes, studies.items(), strict=True):
        x = [r["value"] for r in rows]
        for name, color in ((COMPASS, "tab:red"), ("grid", "tab:blue")):
            y = [r[name]["median_abs_error_deg"] for r in rows]
            ax.plot(x, y, "o-", color=color, label=f"{name}: median |error|")
        ax.set_xlabel(param)
        ax.set_ylabel("heading error (°)")
        if param == "coverage":
            ax.set_xscale("log")
            ax.axvline(0.01, ls=":", color="0.5", lw=1)
        if param == "n_colors":
            ax.axvline(3, ls=":", color="0.5", lw=1)
        ax.grid(alpha=0.3)
        cost = ax.twinx()
        labels = [_config_label(CompassConfig(**{param: v}).to_dict()) for v in x]
        ms = [costs.get(lb, {}).get(COMPASS) for lb in labels]
        cost.plot(x, ms, "s--", color="0.45", ms=4, label="localise ms/frame")
        cost.set_ylabel("ms per frame (localise)", color="0.45")
        ax.set_title(param, fontsize=10)
        ax.legend(fontsize=7, loc="upper left")
    fig.suptitle("parameter studies (paper 5.3): heading error and cost", fontsize=11)
    save_figure(fig, path)


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """One line per parameter value: compass and grid-filter median errors."""
    lines = []
    for param, rows in results.get("studies", {}).items():
        parts = [
            f"{r['value']}: {r[COMPASS]['median_abs_error_deg']}° / "
            f"{r['grid']['median_abs_error_deg']}°"
            for r in rows
        ]
        lines.append(f"{param:10s} (median |error| compass / grid) " + ", ".join(parts))
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
