"""The homing modes: how a place is learned, which tracker homes on it, how the
scripted agent homes (``vc-gym experiment homing --mode``, ``vc-gym train --mode``).

A mode's learning settings and tracker are arguments of the tasks
(``vc_gym/LearnThenHome-v0``, ``vc_gym/Homing-v0``); its policy settings are plain
keyword arguments of :class:`~vc_gym.agents.ScriptedHomingPolicy`. They live with the
tasks so that a training run (:mod:`vc_gym.training`) can learn its places in a mode and
an evaluation can tell, from a learned agent's env arguments, which mode its places
were learned in (:func:`mode_of_task`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from vc_gym.deprecation import renamed
from vc_gym.localization import TrackerSpec

__all__ = [
    "DEFAULT_HOMING_MODE",
    "DEPRECATED_HOMING_MODES",
    "HOMING_MODES",
    "LEARNED_AGENT_MODE",
    "HomingMode",
    "canonical_homing_mode",
    "homing_mode",
    "mode_of_task",
]


@dataclass(frozen=True)
class HomingMode:
    """How the place is learned and how the scripted agent homes, by name.

    Attributes
    ----------
    learning : dict
        Task arguments of ``vc_gym/LearnThenHome-v0`` that shape the learned atlas
        (saved with it: ``normalise_at``).
    policy : dict
        Keyword arguments of :class:`~vc_gym.agents.ScriptedHomingPolicy`.
    tracker : str or dict
        The tracker the mode homes on unless another is given.
    """

    learning: dict[str, Any]
    policy: dict[str, Any]
    tracker: TrackerSpec = "grid"

    @property
    def task_learning(self) -> dict[str, Any]:
        """Every learning setting a mode may change, the task's own values where this
        mode keeps them: task arguments that override whatever learning an env was
        given (a learned agent's own), not only this mode's changes."""
        return {**_TASK_LEARNING_DEFAULTS, **self.learning}


#: Head pans of ``bearings-home`` while standing (the paper's scan reaches ±40°).
WIDE_HEAD_SCAN_DEG = (-80.0, -40.0, 0.0, 40.0, 80.0, 40.0, 0.0, -40.0)
#: Head pans of ``bearings-home`` while walking.
WALK_HEAD_SCAN_DEG = (-60.0, -30.0, 0.0, 30.0, 60.0, 30.0, 0.0, -30.0)

#: The homing modes. ``paper``: the paper's procedure (5.2), normalising the spots
#: after walking back home by odometry, whose drift (15-20 cm in the simulated robolab)
#: becomes the stops' systematic offset, and stopping wherever the estimate says home.
#: ``check-home`` (the default): normalising with every frame of the first turn, taken at
#: the true home before the robot moved, and checking with a full turn that the place is
#: home before stopping (``verify_home``; a single view can alias with home 1-2 m away).
#: ``pose-home``: check-home's normalisation, with turns learned 0.5 m around home and
#: every spot (``around_m``) so that the ``pose`` tracker can re-draw the maps for a
#: position; the robot homes on the ``pose-grid`` tracker (the pose belief away from
#: home, which does not get stuck where a view aliases with home; the paper's filters
#: within 0.5 m of it, which answer home exactly there) and checks home with a full turn
#: as check-home does, walking the checked offset itself (``verify_gain`` 1: the pose
#: belief's offset does not shrink with distance as eq. 30's does). It settles for 1 s
#: instead of 2 s and turns its checks as fast as the robot turns (86°/s) instead of at
#: 60°/s, so that a homing that needs several checks ends within the time limit.
#: ``bearings-home``: pose-home's learning with the learned turns' colour changes kept
#: as landmarks (``landmarks``), homing on the ``bearings`` tracker, whose position is
#: good to centimetres, with its field search on (``search_every``: a kidnapping far
#: from the learned spots is placed from the landmarks in a second or two instead of
#: ten or more). The robot scans with its head while it walks (``walk_scan_deg``) and,
#: wider than the paper's scan, while it stands (``head_scan_deg``), so that the
#: bearings see both sides of the room; while its position belief is wider than 0.3 m
#: it turns on the spot, looking (``look_std_m``); it stops within 4 cm of home by its
#: estimate, without a checking turn.
HOMING_MODES: dict[str, HomingMode] = {
    "paper": HomingMode(learning={}, policy={}),
    "check-home": HomingMode(learning={"normalise_at": "start"}, policy={"verify_home": True}),
    "pose-home": HomingMode(
        learning={"normalise_at": "start", "around_m": 0.5},
        policy={
            "verify_home": True,
            "verify_gain": 1.0,
            "verify_turn_deg_s": 90.0,
            "settle_time_s": 1.0,
        },
        tracker="pose-grid",
    ),
    "bearings-home": HomingMode(
        learning={"normalise_at": "start", "around_m": 0.5, "landmarks": True},
        policy={
            "home_tolerance_m": 0.04,
            "head_scan_deg": WIDE_HEAD_SCAN_DEG,
            "walk_scan_deg": WALK_HEAD_SCAN_DEG,
            "look_std_m": 0.3,
            "settle_time_s": 1.0,
        },
        tracker={"type": "bearings", "search_every": 1},
    ),
}
#: The homing mode of the demo, ``vc-gym evaluate`` and every experiment unless told.
DEFAULT_HOMING_MODE = "check-home"
#: Deprecated names of homing modes, accepted with a ``DeprecationWarning``.
DEPRECATED_HOMING_MODES = {"improved": "check-home"}


def canonical_homing_mode(mode: object) -> str:
    """The name of homing mode ``mode`` (a deprecated name warns and gives the new one).

    Raises
    ------
    ValueError
        Naming the modes, for anything else.
    """
    mode = renamed("homing mode", mode, DEPRECATED_HOMING_MODES, stacklevel=3)
    if not isinstance(mode, str) or mode not in HOMING_MODES:
        raise ValueError(f"mode must be one of {list(HOMING_MODES)}, got {mode!r}")
    return mode


def homing_mode(mode: str) -> HomingMode:
    """The :class:`HomingMode` called ``mode``, or a ``ValueError`` naming the modes."""
    return HOMING_MODES[canonical_homing_mode(mode)]


#: The mode ``vc-gym train`` learns its places in unless told: the tracker with a
#: position belief on places learned with turns around the spots. A learned agent is
#: evaluated in the mode its places were learned in (:func:`mode_of_task`).
LEARNED_AGENT_MODE = "pose-home"
#: The task's own values of the settings a mode may change (what a task argument
#: left out means).
_TASK_LEARNING_DEFAULTS = {"normalise_at": "return", "around_m": 0.0, "landmarks": False}


def mode_of_task(task_kwargs: Mapping[str, Any]) -> str | None:
    """The homing mode whose places the task arguments ``task_kwargs`` learn (a learned
    agent's env arguments: ``normalise_at``, ``around_m``), or ``None`` when they match
    no mode. Arguments left out take the task's defaults, so ``{}`` is ``"paper"``."""
    settings = {k: task_kwargs.get(k, v) for k, v in _TASK_LEARNING_DEFAULTS.items()}
    for name, mode in HOMING_MODES.items():
        if mode.task_learning == settings:
            return name
    return None
