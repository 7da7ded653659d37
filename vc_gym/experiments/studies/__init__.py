"""The registry of experiments: ``vc-gym experiment NAME`` runs ``EXPERIMENTS[NAME]``.

Each experiment is a function ``run_<name>(out_dir, opts, **options) -> results``
that writes ``DIR/results.json`` (figures only) and its PNGs; the job-based ones split
their work into jobs (:mod:`vc_gym.jobs`) and also write ``DIR/run.json``
(timings, backend, versions). Its module has a function ``summary_lines(results)``
that says the result in a few lines (and may have ``cost_lines(run_info)``). The
registry entry declares the options the experiment takes
(:class:`~vc_gym.experiments.options.Option`), which is all the command line needs to
offer them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from vc_gym.experiments.options import HOMING_MODE_HELP, OPTIONS, Option
from vc_gym.experiments.studies.common import SIZES, ExperimentOptions

__all__ = ["EXPERIMENTS", "SIZES", "Experiment", "ExperimentOptions", "get_experiment"]


@dataclass(frozen=True)
class Experiment:
    """A registered experiment: where its functions live, what it does, what it takes.

    Attributes
    ----------
    name : str
        The name of ``vc-gym experiment NAME``.
    module : str
        The module holding the runner and ``summary_lines``.
    help : str
        One paragraph for ``--help``.
    options : tuple of Option
        The experiment's own options (beyond ``--out``, ``--seed`` and ``--json``).
    jobs : bool
        Whether it runs as jobs on a backend (then it also takes ``--size``,
        ``--quick``, ``--backend``, ``--workers`` and ``--address``).
    function : str
        The runner's name in ``module`` (default ``run_<name>``).
    """

    name: str
    module: str
    help: str
    options: tuple[Option, ...] = ()
    jobs: bool = True
    function: str = ""

    def runner(self) -> Callable[..., dict[str, Any]]:
        """``run(out_dir, opts, **options) -> results``."""
        function = self.function or f"run_{self.name.replace('-', '_')}"
        return getattr(importlib.import_module(self.module), function)

    def summary_lines(self, results: dict[str, Any]) -> list[str]:
        """What the experiment found, in a few lines."""
        return list(importlib.import_module(self.module).summary_lines(results))

    def cost_lines(self, run_info: dict[str, Any]) -> list[str]:
        """What the experiment says about cost, from its ``run.json`` (may be none)."""
        lines = getattr(importlib.import_module(self.module), "cost_lines", None)
        return list(lines(run_info)) if lines is not None else []


def _options(*names: str, **worded: str) -> tuple[Option, ...]:
    """The catalogue's options ``names``, and ``worded`` ones with the experiment's own
    help text."""
    return tuple(OPTIONS[n] for n in names) + tuple(
        OPTIONS[n].described(text) for n, text in worded.items()
    )


_HOMING = ("tracker", "episodes", "seeds", "learn_time_s", "max_homing_s", "mode")
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
            _options(
                *_HOMING,
                "agent",
                "allow_imports",
                "sensor",
                "home_offset_m",
                "relearn",
                "atlas_dir",
                "video",
            ),
        ),
        Experiment(
            "agents",
            _P + "agents",
            "learned agents against the scripted one: the homing experiment for every "
            "--agent scripted,DIR/model.zip,... on the same learning seeds and kidnappings; "
            "each agent's figures, the learned agents' mean ± std and a paired comparison",
            _options(
                *[n for n in _HOMING if n != "mode"],
                "agents",
                "allow_imports",
                "atlas_dir",
                "video",
                mode="the places every agent homes in are learned this way, and the scripted "
                "agent homes so, on the mode's tracker (default: the mode the learned agents' "
                "training places were learned in, from their config.json: pose-home for "
                "the shipped one): " + HOMING_MODE_HELP,
            ),
        ),
        Experiment(
            "orientation",
            _P + "orientation",
            "5.1, fig. 4: learn one spot (centre of the rear field half), heading error and "
            "spread of every tracker over a grid of poses vs distance from the spot, and "
            "the arrow field of the estimates (--modes paper,spot-grid: also maps on a "
            "1.0 m grid of spots; --light: dimmer views)",
            _options("trackers", "scenes", "modes", "light", "atlas_dir"),
        ),
        Experiment(
            "environments",
            _P + "orientation",
            "5.3: the orientation experiment in every registered scene",
            _options("trackers", "scenes", "modes", "light", "atlas_dir"),
        ),
        Experiment(
            "params",
            _P + "params",
            "5.3: colour classes 2-16, scanning coverage 100 %-0.5 %, sector width, histogram "
            "bins: heading error (results.json) and ms per frame (run.json) for each value",
            _options("scenes", "atlas_dir"),
        ),
        Experiment(
            "illumination",
            _P + "illumination",
            "5.3: learn at full light, localise at 1.0, 0.75, 0.5 and 0.25, paper mode and "
            "with exposure normalisation",
            _options("scenes", "atlas_dir"),
        ),
        Experiment(
            "trackers",
            _P + "trackers",
            "the filter benchmark: every tracker (and any --tracker package.module:factory) x "
            "scenes x seeds on the homing task and the orientation grid, as a leaderboard",
            _options("trackers", "scenes", "seeds", "episodes", "mode", "atlas_dir", "video"),
        ),
        Experiment(
            "tracking",
            _P + "tracking",
            "beyond the paper: a robot walking 60 s routes across the whole field (turns on "
            "the spot, head scanning, kidnapped once mid-route) in every scene at full and "
            "half light, maps on a grid of spots; each tracker's heading and position error "
            "after 10 s, time to re-localise after the kidnapping, 2σ coverage of its stated "
            "uncertainty, errors against time and the belief on the top view",
            _options(
                "lights",
                "learn_time_s",
                "atlas_dir",
                trackers="a tracker to compare (repeat the flag; default pose, grid and "
                "particle): a registered name, 'package.module:factory' or a JSON object",
                scenes="scenes (default: every registered scene)",
                seeds="learning seeds (default: three from --seed on, 0,1,2)",
                episodes="routes per learning seed, each with one kidnapping (default 2)",
                video="write the first N routes as MP4 (head camera beside the top view, "
                "true and believed pose, a particle tracker's particles)",
            ),
        ),
        Experiment(
            "localization",
            _P + "localization",
            "beyond the paper (5.2's open problem): maps on a grid of spots, position "
            "error over the whole field from one view (eq. 30; a likelihood calibrated on "
            "goodness against distance) and from a full turn (the same; nearest goodness "
            "signatures)",
            _options("scenes"),
        ),
        Experiment(
            "sensors",
            _P + "sensors",
            "the baselines of section 6 under one protocol: the visual compass (paper and "
            "with mean exposure), image difference, sector colours, ORB features and a disturbed "
            "magnetometer learn the same frames; median/p90 heading error at 0, 1, 2 and "
            "4 m, full and half light, every scene, and on the real photos; homing with "
            "each as the tracker's heading sensor; ms per frame and the accuracy/cost "
            "front (sensors.png)",
            _options("scenes", "data_dir", "atlas_dir"),
        ),
        Experiment(
            "paper",
            _P + "paper",
            "all of the above at the report's size (< 20 min on 2 cores), writing "
            "DIR/report.md: our figures next to the paper's claims, with the plots",
            _options("mode", "atlas_dir", "video"),
        ),
        Experiment(
            "real-rotation",
            "vc_gym.experiments.real_rotation",
            "learn from 9 alternate photos of a camera turning in place and estimate the "
            "yaw of crops of the other 9 (indoor and outdoor sets, 10 and 3 colour classes, "
            "exposure none/mean/map/session, crops at full and half light)",
            _options("data_dir"),
            jobs=False,
        ),
        Experiment(
            "calibration",
            _P + "calibration",
            "is the compass' heading spread calibrated? share of true headings within ±1σ "
            "and ±2σ, median |error| and spread, uncalibrated and with the temperature "
            "fitted at map time (leave-one-out over the learning turn): views at 0, 1 and "
            "2 m from the spot in every scene over learning seeds, and crops of the real "
            "rotation sets (cross-fitted)",
            _options("scenes", "seeds", "data_dir"),
        ),
        Experiment(
            "synthetic-compass",
            "vc_gym.experiments.synthetic_compass",
            "synthetic room and outdoor panoramas at normal and half illumination",
            jobs=False,
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
