"""The paper's illumination study (5.3): learn at full light, localise in dimmer light.

The training spot of the orientation experiment is learned at full light, once with the
paper's compass (``exposure="none"``) and once with vc_gym's exposure normalisation
(``exposure="mean"``); the robot is then put at a grid of poses with the room's light
at 1.0, 0.75, 0.5 and 0.25 of the learning level. The paper: the compass "still
performs well with only half of the illumination as while learning".
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from vc_gym.experiments.atlases import atlas_key, atlas_spec, ensure_atlases
from vc_gym.experiments.studies.common import (
    ExperimentOptions,
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

__all__ = ["LEVELS", "MODES", "run_illumination", "summary_lines"]

LEVELS = (1.0, 0.75, 0.5, 0.25)
#: ``paper``: the compass as published; ``exposure``: exposure normalisation on.
MODES = {"paper": "none", "exposure": "mean"}
SIZES = {
    "quick": {"spacing_m": 2.0, "headings": 1, "frames": 3, "learn_time_s": 0.5},
    "paper": {"spacing_m": 1.0, "headings": 2, "frames": 8, "learn_time_s": 5.0},
    "full": {"spacing_m": 0.5, "headings": 2, "frames": 10, "learn_time_s": 5.0},
}
TRACKERS = {"grid": "grid"}


def run_illumination(
    out_dir: str | os.PathLike,
    opts: ExperimentOptions | None = None,
    scenes: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Run the illumination study; write ``results.json``, ``run.json``, ``illumination.png``.

    Parameters
    ----------
    out_dir : path-like
        The run folder (resumable).
    opts : ExperimentOptions
        Seed, size, backend, ...
    scenes : sequence of str, optional
        One scene (default ``["robolab"]``).

    Returns
    -------
    dict
        Per mode and light level: |heading error| of the compass and the grid filter.
    """
    opts = opts or ExperimentOptions()
    size = pick_size(SIZES, opts.size)
    scene = one_scene(scenes, "illumination study")
    run = open_run(out_dir, "illumination", opts, {"scene": scene, "levels": list(LEVELS), **size})
    bounds = scene_field_bounds(scene)
    spot = rear_half_centre(bounds)
    specs = {
        mode: atlas_spec(
            scene, opts.seed, "spot", size["learn_time_s"], {"exposure": exp}, spot=spot
        )
        for mode, exp in MODES.items()
    }
    paths = ensure_atlases(run, list(specs.values()), opts.atlas_dir)
    results: dict[str, Any] = {
        "paper": {"claim": "performs well with half of the learning illumination"},
        "training_spot": list(spot),
        "modes": {},
    }
    for mode, spec in specs.items():
        rows = []
        for level in LEVELS:
            jobs = view_jobs(
                "pos-",
                scene,
                paths[atlas_key(spec)],
                spot,
                bounds,
                size,
                opts.seed,
                TRACKERS,
                room={"illumination": level},
            )
            s = views_summary(run.run(f"views-{mode}-{level}", jobs), list(TRACKERS))
            row = {"illumination": level, "views": s["views"]}
            row.update(headline_errors(s, list(TRACKERS)))
            rows.append(row)
        results["modes"][mode] = rows
    _plot(run.out / "illumination.png", results["modes"])
    return run.finish(results)


def _plot(path: Path, modes: Mapping[str, Any]) -> None:
    fig = new_figure(figsize=(6, 4), layout="constrained")
    ax = fig.subplots()
    styles = {"paper": "-", "exposure": "--"}
    for mode, rows in modes.items():
        x = [r["illumination"] for r in rows]
        for name, color in ((COMPASS, "tab:red"), ("grid", "tab:blue")):
            y = [r[name]["median_abs_error_deg"] for r in rows]
            ax.plot(x, y, "o" + styles.get(mode, "-"), color=color, label=f"{name}, {mode} mode")
    ax.axvline(0.5, ls=":", color="0.5", lw=1)
    ax.set_xlabel("illumination while localising (learned at 1.0)")
    ax.set_ylabel("median |heading error| (°)")
    ax.set_title("illumination study (paper 5.3: works at half light)", fontsize=10)
    ax.invert_xaxis()
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """One line per mode: median errors at each light level."""
    lines = []
    for mode, rows in results.get("modes", {}).items():
        parts = [
            f"{r['illumination']}: {r[COMPASS]['median_abs_error_deg']}° / "
            f"{r['grid']['median_abs_error_deg']}°"
            for r in rows
        ]
        lines.append(
            f"{mode:9s} (median |error| compass / grid at light level) " + ", ".join(parts)
        )
    for f in results.get("failed_jobs", []):
        lines.append(f"FAILED {f['stage']}/{f['key']}: {f['error']}")
    return lines
