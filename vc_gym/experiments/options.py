"""The options an experiment declares: one flag each, parsed and checked the same way.

An :class:`~vc_gym.experiments.studies.Experiment` lists the :class:`Option` objects it
takes (as gymnasium's ``EnvSpec`` carries its kwargs), so ``vc-gym experiment NAME
--help`` shows exactly that experiment's flags and one dispatch path runs them all.
Each option is a keyword argument of the experiment's runner (``parameter``) or a field
of :class:`~vc_gym.experiments.studies.common.ExperimentOptions` (``to_options``).

The parsers here turn one command-line word into a value and raise ``ValueError`` with
a message that says what was expected; the checks take ``(flag, value)`` and raise
``ValueError`` naming the flag. Both run before any work starts.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from vc_gym.validation import (
    MAX_EPISODES,
    MAX_HOMING_S,
    MAX_LEARN_TIME_S,
    MAX_SEEDS,
    check_seed,
    int_in_range,
    positive_float_at_most,
)

__all__ = [
    "HOMING_MODE_CHOICES",
    "HOMING_MODE_HELP",
    "MAX_LIGHTS",
    "MAX_VIDEOS",
    "OPTIONS",
    "Option",
    "check_folder",
    "check_light_list",
    "check_seed_list",
    "parse_float_list",
    "parse_float_pair",
    "parse_int_list",
    "parse_str_list",
    "parse_tracker_spec",
]

#: Most homing episodes written as MP4 (``--video``).
MAX_VIDEOS = 1_000
#: Most light levels one run compares (``--lights``).
MAX_LIGHTS = 10
#: The values ``--mode`` takes: the homing modes and a deprecated name.
HOMING_MODE_CHOICES = ("check-home", "paper", "pose-home", "bearings-home", "improved")
HOMING_MODE_HELP = (
    "check-home: the spots normalised with the frames of the first turn at "
    "the true home, and home checked with a full turn before stopping; paper: the "
    "paper's procedure (normalised after walking back home by odometry, stop where "
    "the estimate says home); pose-home: check-home's learning plus turns 0.5 m around "
    "home and every spot, homing on the pose-grid tracker (the pose belief away from home, "
    "the paper's filters near it) and checking home with a full turn; bearings-home: "
    "pose-home's learning with the colour changes kept as landmarks, homing on the "
    "bearings tracker with its field search, the head scanning while walking, turning "
    "to look while unsure, stopping within 4 cm by its estimate without a checking turn; "
    "improved: deprecated name of check-home"
)


def parse_tracker_spec(text: str) -> object:
    """``--tracker``: a registered name, ``package.module:factory`` or a JSON object
    ``{"type": NAME, ...}`` (the object is returned as a dict, the rest as text)."""
    if text.lstrip().startswith("{"):
        try:
            spec = json.loads(text)
        except ValueError as exc:
            raise ValueError(f"not a JSON object: {exc}") from None
        if not isinstance(spec, dict):
            raise ValueError("a JSON tracker spec must be an object")
        return spec
    return text


def parse_int_list(text: str) -> list[int]:
    """``"1,2,3"`` -> ``[1, 2, 3]`` (empty items are skipped)."""
    try:
        return [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"expected integers separated by commas: {text!r}") from None


def parse_float_list(text: str) -> list[float]:
    """``"1,0.5"`` -> ``[1.0, 0.5]`` (empty items are skipped)."""
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"expected numbers separated by commas: {text!r}") from None


def parse_float_pair(text: str) -> list[float]:
    """``"X,Y"`` -> ``[X, Y]``."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 2:
        raise ValueError(f"expected two numbers X,Y: {text!r}")
    return values


def parse_str_list(text: str) -> list[str]:
    """``"a, b,"`` -> ``["a", "b"]``."""
    return [v.strip() for v in text.split(",") if v.strip()]


def check_seed_list(flag: str, seeds: Sequence[int]) -> None:
    """1 to :data:`~vc_gym.validation.MAX_SEEDS` seeds, each a valid seed."""
    if not 1 <= len(seeds) <= MAX_SEEDS:
        raise ValueError(f"{flag} must name 1..{MAX_SEEDS} seeds, got {len(seeds)}")
    for seed in seeds:
        check_seed(flag, seed)


def check_folder(flag: str, folder: str | os.PathLike) -> None:
    """``folder`` exists and is a folder."""
    if not os.path.isdir(folder):
        raise ValueError(f"{flag} {folder}: not a folder")


@dataclass(frozen=True)
class Option:
    """One flag of ``vc-gym experiment NAME``.

    Attributes
    ----------
    parameter : str
        The runner's keyword argument it sets (or, with ``to_options``, the field of
        ``ExperimentOptions``).
    flag : str
        The command-line flag, e.g. ``"--learn-time"``.
    help : str
        What it does, for ``--help``.
    parse : callable, optional
        ``str -> value``; raises ``ValueError`` on bad text. Default: the text itself.
    metavar : str, optional
        The value's name in ``--help``.
    choices : tuple of str, optional
        The values allowed.
    switch : bool
        A flag without a value (``True`` when given).
    repeat : bool
        The flag may be given several times; the value is the list.
    check : callable, optional
        ``(flag, value) -> None``; raises ``ValueError`` for a value out of bounds.
    to_options : bool
        The value goes to ``ExperimentOptions`` rather than to the runner.
    """

    parameter: str
    flag: str
    help: str
    parse: Callable[[str], Any] | None = None
    metavar: str | None = None
    choices: tuple[str, ...] | None = None
    switch: bool = False
    repeat: bool = False
    check: Callable[[str, Any], None] | None = None
    to_options: bool = False

    def described(self, help: str) -> Option:
        """The same option with another help text (for an experiment's own wording)."""
        return dataclasses.replace(self, help=help)


def _episodes(flag: str, value: int) -> None:
    int_in_range(flag, value, 1, MAX_EPISODES)


def _learn_time(flag: str, value: float) -> None:
    positive_float_at_most(flag, value, MAX_LEARN_TIME_S)


def _max_homing(flag: str, value: float) -> None:
    positive_float_at_most(flag, value, MAX_HOMING_S)


def _videos(flag: str, value: int) -> None:
    int_in_range(flag, value, 0, MAX_VIDEOS)


def check_light_list(flag: str, values: Sequence[float]) -> None:
    """1 to :data:`MAX_LIGHTS` distinct light levels, each in ``(0, 1]``."""
    if not 1 <= len(values) <= MAX_LIGHTS or len(set(values)) != len(values):
        raise ValueError(f"{flag} must name 1..{MAX_LIGHTS} distinct light levels, got {values}")
    for v in values:
        if not 0.0 < v <= 1.0:
            raise ValueError(f"{flag}: every light level must be in (0, 1], got {v:g}")


_TRACKER_KINDS = (
    "grid, particle, kalman, pose, pose-grid, 'package.module:factory' or a JSON object"
)

#: Every option an experiment can declare, by the name experiments use for it.
OPTIONS: dict[str, Option] = {
    "agent": Option(
        "agent",
        "--agent",
        "the agent: scripted (default), pretrained (the shipped policy) or DIR/model.zip",
        metavar="scripted|pretrained|DIR/model.zip",
    ),
    "agents": Option(
        "agent",
        "--agent",
        "the agents to compare, comma-separated, scripted among them (default scripted,pretrained)",
        metavar="AGENT,...",
    ),
    "allow_imports": Option(
        "allow_imports",
        "--allow-imports",
        "let a learned agent's config.json name plug-ins by import path "
        "('package.module:factory'), which imports and runs that code; without it a file "
        "may name only registered plug-ins. Only for files you trust",
        switch=True,
    ),
    "tracker": Option(
        "tracker",
        "--tracker",
        f"the tracker: {_TRACKER_KINDS} (default grid; pose-grid with --mode pose-home)",
        parse=parse_tracker_spec,
        metavar="SPEC",
    ),
    "trackers": Option(
        "trackers",
        "--tracker",
        f"a tracker to compare (repeat the flag): {_TRACKER_KINDS}",
        parse=parse_tracker_spec,
        metavar="SPEC",
        repeat=True,
    ),
    "sensor": Option(
        "sensor",
        "--sensor",
        "the grid tracker's heading sensor, learned in a turn at home for every learning "
        "seed (position still from the atlas): feature, image_difference, sector_color, "
        "visual_compass, or magnetic (a magnetometer in the head; see `vc-gym experiment "
        "sensors`)",
        metavar="NAME",
    ),
    "home_offset_m": Option(
        "home_offset_m",
        "--home-offset",
        "the scripted agent's goal relative to the tracker's home, in metres (world "
        "frame), e.g. a learned agent's measured home_offset_m from its config.json; write "
        "--home-offset=-0.07,0.10 when X is negative (default 0,0: the paper's)",
        parse=parse_float_pair,
        metavar="X,Y",
    ),
    "episodes": Option(
        "episodes",
        "--episodes",
        "kidnappings per learning seed (paper: 33)",
        parse=int,
        check=_episodes,
    ),
    "seeds": Option(
        "seeds",
        "--seeds",
        "learning seeds (default: --seed)",
        parse=parse_int_list,
        metavar="S,S,...",
        check=check_seed_list,
    ),
    "scenes": Option(
        "scenes",
        "--scenes",
        "scenes (default by experiment)",
        parse=parse_str_list,
        metavar="NAME,...",
    ),
    "learn_time_s": Option(
        "learn_time_s",
        "--learn-time",
        "seconds per learning direction (paper: 5)",
        parse=float,
        metavar="S",
        check=_learn_time,
    ),
    "max_homing_s": Option(
        "max_homing_s",
        "--max-homing",
        "homing seconds before an episode ends as timed out",
        parse=float,
        metavar="S",
        check=_max_homing,
    ),
    "relearn": Option(
        "relearn",
        "--relearn",
        "learn once per learning seed (scene, the paper's) or before every kidnapping (episode)",
        choices=("scene", "episode"),
    ),
    "mode": Option(
        "mode",
        "--mode",
        "how the place is learned and the scripted agent homes (default: check-home; "
        "for a learned agent the mode its training places were learned in, from its "
        "config.json: pose-home for the shipped one): " + HOMING_MODE_HELP,
        choices=HOMING_MODE_CHOICES,
    ),
    "modes": Option(
        "modes",
        "--modes",
        "paper (one spot, default) and/or spot-grid (the same learning at every spot of a "
        "1.0 m grid with exposure-normalised colours; heading from the best-fitting map), "
        "e.g. --modes paper,spot-grid",
        parse=parse_str_list,
        metavar="MODE,...",
    ),
    "light": Option(
        "light",
        "--light",
        "room illumination for the views, in (0, 1] (maps learned at full light; the "
        "paper's 5.3: 0.5)",
        parse=float,
        metavar="L",
    ),
    "lights": Option(
        "lights",
        "--lights",
        "room illuminations to compare, each in (0, 1] (maps learned at full light; the "
        "paper's 5.3: 0.5), e.g. --lights 1,0.5",
        parse=parse_float_list,
        metavar="L,L,...",
        check=check_light_list,
    ),
    "data_dir": Option(
        "data_dir",
        "--data",
        "folder of the real photo sets (default: $VC_GYM_REAL_DATA or ../shared/data/real)",
        metavar="DIR",
        check=check_folder,
    ),
    "atlas_dir": Option(
        "atlas_dir",
        "--atlas",
        "reuse the saved atlases in DIR",
        metavar="DIR",
        check=check_folder,
        to_options=True,
    ),
    "video": Option(
        "video",
        "--video",
        "write the first N homing episodes as MP4",
        parse=int,
        metavar="N",
        check=_videos,
        to_options=True,
    ),
}
