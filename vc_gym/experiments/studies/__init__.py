"""The paper's experiments and the tracker benchmark, as resumable job-based commands.

Each experiment is a function ``run_<name>(out_dir, opts, **options) -> results`` that
splits its work into jobs (:mod:`vc_gym.jobs.runner`), writes
``DIR/results.json`` (figures only), ``DIR/run.json`` (timings, backend, versions) and
its PNGs, and a function ``summary_lines(results)`` that says the result in a few
lines. :data:`EXPERIMENTS` maps the names of ``vc-gym experiment NAME`` to them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from vc_gym.experiments.studies.common import SIZES, ExperimentOptions

__all__ = ["EXPERIMENTS", "SIZES", "Experiment", "ExperimentOptions", "get_experiment"]


@dataclass(frozen=True)
class Experiment:
    """A registered experiment: where its functions live and what it does."""

    name: str
    module: str
    help: str

    def runner(self) -> Callable[..., dict[str, Any]]:
        return getattr(importlib.import_module(self.module), f"run_{self.name}")

    def summary_lines(self, results: dict[str, Any]) -> list[str]:
        return list(importlib.import_module(self.module).summary_lines(results))

    def cost_lines(self, run_info: dict[str, Any]) -> list[str]:
        """What the experiment says about cost, from its ``run.json`` (may be none)."""
        lines = getattr(importlib.import_module(self.module), "cost_lines", None)
        return list(lines(run_info)) if lines is not None else []


_P = "vc_gym.experiments.studies."
EXPERIMENTS: dict[str, Experiment] = {
    e.name: e
    for e in (
        Experiment(
            "homing",
            _P + "homing",
            "5.2, fig. 5: learn 4 spots 1 m around home, 33 kidnappings per learning seed, "
            "stop positions (mean, std per axis, success within 30 cm, stops > 50 cm) and "
            "the likelihood field of one spot over a 50 cm grid",
        ),
        Experiment(
            "agents",
            _P + "agents",
            "learned agents against the scripted one: the homing experiment for every "
            "--agent scripted,DIR/model.zip,... on the same learning seeds and kidnappings; "
            "each agent's figures, the learned agents' mean ± std and a paired comparison",
        ),
        Experiment(
            "orientation",
            _P + "orientation",
            "5.1, fig. 4: learn one spot (centre of the rear field half), heading error and "
            "spread of every tracker over a grid of poses vs distance from the spot, and "
            "the arrow field of the estimates (--modes paper,improved: also maps on a "
            "1.0 m grid of spots; --light: dimmer views)",
        ),
        Experiment(
            "environments",
            _P + "orientation",
            "5.3: the orientation experiment in every registered scene",
        ),
        Experiment(
            "params",
            _P + "params",
            "5.3: colour classes 2-16, scanning coverage 100 %-0.5 %, sector width, histogram "
            "bins: heading error (results.json) and ms per frame (run.json) for each value",
        ),
        Experiment(
            "illumination",
            _P + "illumination",
            "5.3: learn at full light, localise at 1.0, 0.75, 0.5 and 0.25, paper mode and "
            "with exposure normalisation",
        ),
        Experiment(
            "trackers",
            _P + "trackers",
            "the filter benchmark: every tracker (and any --tracker package.module:factory) x "
            "scenes x seeds on the homing task and the orientation grid, as a leaderboard",
        ),
        Experiment(
            "localization",
            _P + "localization",
            "beyond the paper (5.2's open problem): maps on a grid of spots, position "
            "error over the whole field from one view (eq. 30; a likelihood calibrated on "
            "goodness against distance) and from a full turn (the same; nearest goodness "
            "signatures)",
        ),
        Experiment(
            "sensors",
            _P + "sensors",
            "the baselines of section 6 under one protocol: the visual compass (paper and "
            "improved), image difference, sector colours, ORB features and a disturbed "
            "magnetometer learn the same frames; median/p90 heading error at 0, 1, 2 and "
            "4 m, full and half light, every scene, and on the real photos; homing with "
            "each as the tracker's heading sensor; ms per frame and the accuracy/cost "
            "front (sensors.png)",
        ),
        Experiment(
            "paper",
            _P + "paper",
            "all of the above at the report's size (< 20 min on 2 cores), writing "
            "DIR/report.md: our figures next to the paper's claims, with the plots",
        ),
    )
}


def get_experiment(name: str) -> Experiment:
    """The registered experiment ``name`` (a clear error listing the others)."""
    try:
        return EXPERIMENTS[name]
    except KeyError:
        raise ValueError(
            f"unknown experiment {name!r}; choose from {', '.join(EXPERIMENTS)}"
        ) from None
