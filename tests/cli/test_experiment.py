"""``vc-gym experiment NAME``: each experiment offers exactly the options it declares."""

from __future__ import annotations

import re

import pytest

from vc_gym.cli import build_parser, main
from vc_gym.experiments.options import OPTIONS
from vc_gym.experiments.studies import EXPERIMENTS

ALL_FLAGS = {o.flag for o in OPTIONS.values()}
JOB_FLAGS = {"--quick", "--size", "--backend", "--workers", "--address"}


@pytest.mark.parametrize("name", list(EXPERIMENTS))
def test_help_shows_the_experiments_own_flags_and_no_other(name, capsys):
    with pytest.raises(SystemExit) as e:
        main(["experiment", name, "--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    experiment = EXPERIMENTS[name]
    own = {o.flag for o in experiment.options}

    def offered(flag: str) -> bool:
        return re.search(rf"{flag}(?![\w-])", text) is not None

    for flag in own | {"--out", "--seed", "--json"}:
        assert offered(flag), flag
    for flag in ALL_FLAGS - own:
        assert not offered(flag), flag
    for flag in JOB_FLAGS:
        assert offered(flag) == experiment.jobs, flag


@pytest.mark.parametrize("name", list(EXPERIMENTS))
def test_every_declared_option_is_a_parameter_of_the_runner(name):
    import inspect

    experiment = EXPERIMENTS[name]
    accepted = inspect.signature(experiment.runner()).parameters
    for option in experiment.options:
        if not option.to_options:
            assert option.parameter in accepted, (name, option.parameter)


def test_an_option_not_given_leaves_the_experiments_default():
    args = build_parser().parse_args(["experiment", "homing"])
    assert args.mode is None and args.tracker is None and args.episodes is None


def test_a_bad_value_is_a_usage_error_that_says_what_was_expected(capsys):
    with pytest.raises(SystemExit) as e:
        main(["experiment", "homing", "--seeds", "1,x"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "usage: vc-gym experiment homing" in err
    assert "expected integers separated by commas" in err


def test_a_value_out_of_bounds_is_refused_before_any_folder_is_made(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["experiment", "homing", "--episodes", "0", "--out", str(out)]
    assert main(argv) == 2
    assert "--episodes" in capsys.readouterr().err
    assert not out.exists()


def test_an_unknown_flag_of_a_command_shows_that_commands_usage(capsys):
    with pytest.raises(SystemExit):
        main(["demo", "--no-such-flag"])
    err = capsys.readouterr().err
    assert "usage: vc-gym demo" in err and "unrecognized arguments: --no-such-flag" in err
