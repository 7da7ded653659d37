"""The specs that identify a learned atlas (vc_gym.experiments.atlases)."""

from __future__ import annotations

import pytest

from vc_gym.experiments.atlases import atlas_key, atlas_spec

SPOTS = [(0.0, 0.0), (1.0, 0.0)]


def test_grid_options_enter_the_spec_only_when_set():
    plain = atlas_spec("robolab", 0, "grid", spots=SPOTS)
    around = atlas_spec("robolab", 0, "grid", spots=SPOTS, around_m=0.5)
    kept = atlas_spec("robolab", 0, "grid", spots=SPOTS, around_m=0.5, keep_around=True)
    assert "around_m" not in plain and "keep_around" not in plain
    assert around["around_m"] == 0.5 and "keep_around" not in around
    assert kept["keep_around"] is True
    assert len({atlas_key(plain), atlas_key(around), atlas_key(kept)}) == 3


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"learner": "scripted", "keep_around": True}, "grid"),
        ({"learner": "scripted", "around_m": 0.5}, "grid"),
        ({"learner": "grid", "spots": SPOTS, "keep_around": True}, "around_m"),
    ],
)
def test_grid_options_are_checked(kwargs, match):
    with pytest.raises(ValueError, match=match):
        atlas_spec("robolab", 0, **kwargs)
