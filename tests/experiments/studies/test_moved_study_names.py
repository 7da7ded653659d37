"""Public names that moved out of a study still import from their old place for one
release, with a DeprecationWarning naming the new one, and are the very same objects."""

from __future__ import annotations

import importlib

import pytest

from vc_gym.deprecation import moved_names

S = "vc_gym.experiments.studies."
MOVED = [
    *[
        (S + "homing", name, S + "kidnapping", name)
        for name in (
            "PAPER_MEAN_CM",
            "PAPER_STD_CM",
            "episode_job",
            "mean_std",
            "spread_over_seeds",
            "summarise_stops",
        )
    ],
    *[
        (S + "orientation", name, S + "orientation_grid", name)
        for name in (
            "DEFAULT_TRACKERS",
            "HEADLINE",
            "MODE_TRACKER_OPTIONS",
            "VIEW_MODES",
            "headline_errors",
            "mode_trackers",
            "rear_half_centre",
            "training_spots",
            "view_job",
            "view_jobs",
            "views_stage",
            "views_summary",
        )
    ],
    (S + "orientation", "check_scenes", S + "common", "check_scenes"),
    (S + "orientation", "one_scene", S + "common", "one_scene"),
    (S + "localization", "calibrate", "vc_gym.localization", "calibrate_goodness"),
    (S + "localization", "calibration_points", "vc_gym.localization", "calibration_points"),
    (S + "localization", "locate_calibrated", "vc_gym.localization", "locate_by_goodness"),
    (S + "localization", "locate_nearest", "vc_gym.localization", "locate_by_turn_signature"),
    *[
        (S + "localization", name, "vc_gym.localization.goodness_calibration", name)
        for name in ("BORDER_MARGIN_M", "GRID_STEP_M", "LENGTH_SCALES_M")
    ],
]


@pytest.mark.parametrize(("old", "name", "new", "new_name"), MOVED, ids=lambda v: str(v))
def test_a_moved_name_warns_and_is_the_same_object(old, name, new, new_name):
    module = importlib.import_module(old)
    with pytest.warns(DeprecationWarning, match=f"{new}.{new_name}".replace(".", r"\.")):
        value = getattr(module, name)
    assert value is getattr(importlib.import_module(new), new_name)


def test_from_import_of_a_moved_name_warns_too():
    with pytest.warns(DeprecationWarning, match="kidnapping.summarise_stops"):
        from vc_gym.experiments.studies.homing import summarise_stops
    from vc_gym.experiments.studies.kidnapping import summarise_stops as new

    assert summarise_stops is new


def test_an_unknown_name_is_still_an_attribute_error():
    import vc_gym.experiments.studies.orientation as orientation

    with pytest.raises(AttributeError, match="no_such_name"):
        orientation.no_such_name  # noqa: B018
    with pytest.raises(ImportError):
        from vc_gym.experiments.studies.homing import no_such_name  # noqa: F401


def test_moved_names_serves_only_what_it_was_given():
    import types

    new = types.ModuleType("new_home")
    new.thing = object()
    getter = moved_names("old_home", {"old_thing": (new, "thing")})
    with pytest.warns(DeprecationWarning, match="old_home.old_thing moved to new_home.thing"):
        assert getter("old_thing") is new.thing
    with pytest.raises(AttributeError, match="'old_home' has no attribute 'thing'"):
        getter("thing")
