"""The homing modes: what each learns, and which mode a task's arguments learn in."""

from __future__ import annotations

import inspect

import pytest

from vc_gym.envs import LearnThenHomeEnv
from vc_gym.envs.homing_modes import (
    _TASK_LEARNING_DEFAULTS,
    HOMING_MODES,
    LEARNED_AGENT_MODE,
    mode_of_task,
)


def test_the_task_defaults_are_the_tasks_own():
    params = inspect.signature(LearnThenHomeEnv).parameters
    for name, value in _TASK_LEARNING_DEFAULTS.items():
        assert params[name].default == value
    for mode in HOMING_MODES.values():  # a mode changes nothing else of the learning
        assert set(mode.learning) <= set(_TASK_LEARNING_DEFAULTS)


@pytest.mark.parametrize("name", list(HOMING_MODES))
def test_every_mode_is_found_from_its_own_task_arguments(name):
    assert mode_of_task(HOMING_MODES[name].learning) == name
    # other task arguments (a learned agent's env) do not change the answer
    assert mode_of_task({**HOMING_MODES[name].learning, "tracker": "x", "scene": "office"}) == name


def test_arguments_of_no_mode():
    assert mode_of_task({}) == "paper"  # the task's defaults are the paper's procedure
    assert mode_of_task({"around_m": 0.5}) is None  # turns around, normalised after the walk
    assert mode_of_task({"normalise_at": "start", "around_m": 0.3}) is None
    assert LEARNED_AGENT_MODE in HOMING_MODES


@pytest.mark.parametrize("name", list(HOMING_MODES))
def test_a_modes_task_learning_sets_every_setting_a_mode_may_change(name):
    learning = HOMING_MODES[name].task_learning
    assert set(learning) == set(_TASK_LEARNING_DEFAULTS)
    assert mode_of_task(learning) == name
    # it overrides another mode's settings, e.g. a learned agent's env arguments
    for other in HOMING_MODES.values():
        assert mode_of_task({**other.learning, **learning}) == name
