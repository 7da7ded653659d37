"""``vc_gym.deprecation``: old names keep working for one release, with a warning."""

from __future__ import annotations

import warnings

import pytest

from vc_gym.deprecation import renamed


def test_a_deprecated_name_warns_at_the_caller_and_gives_the_new_one():
    with pytest.warns(DeprecationWarning, match="mode 'old' is deprecated; use 'new'") as w:
        assert renamed("mode", "old", {"old": "new"}, stacklevel=1) == "new"
    assert w[0].filename == __file__


@pytest.mark.parametrize("name", ["new", "other", 3, None])
def test_any_other_name_passes_through_silently(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert renamed("mode", name, {"old": "new"}) == name
