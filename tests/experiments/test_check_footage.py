"""vc-gym check's footage suite: each case is a regression test of ``vc-gym compass
learn/track`` and of the envs' time limits, run here one by one."""

from __future__ import annotations

import pytest

from vc_gym.cli import main
from vc_gym.experiments.check_footage import footage_cases

CASES = footage_cases(main)


@pytest.mark.timeout(120)
@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_footage_case(case, tmp_path):
    case.run(tmp_path)


def test_the_suite_covers_each_promise():
    names = " | ".join(c.name for c in CASES)
    for promise in ("INPUT", "--overwrite", "--width", "truncated", "SIGTERM", "1e12", "--focal"):
        assert promise in names
