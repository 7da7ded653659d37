"""``vc_gym.cli.main``: Ctrl-C at any point is one line, and moved constants still work."""

from __future__ import annotations

import pytest

import vc_gym.cli as cli


def _interrupted(*args, **kwargs):
    raise KeyboardInterrupt


def test_ctrl_c_while_the_commands_load_is_one_line(monkeypatch, capsys):
    monkeypatch.setattr(cli, "build_parser", _interrupted)
    assert cli.main(["demo"]) == cli.EXIT_INTERRUPTED
    assert capsys.readouterr().err == "vc-gym: interrupted\n"


def test_importing_the_package_loads_no_command():
    import subprocess
    import sys

    code = (
        "import sys, vc_gym.cli as c; "
        "print(any(f'vc_gym.cli.{n}' in sys.modules for n in c.COMMANDS))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize(
    ("name", "where"),
    [("MAX_BENCH_REPEATS", "vc_gym.cli.bench"), ("MAX_VIDEOS", "vc_gym.experiments.options")],
)
def test_moved_constants_warn_and_are_the_same(name, where):
    import importlib

    with pytest.warns(DeprecationWarning, match=f"moved to {where}.{name}"):
        value = getattr(cli, name)
    assert value == getattr(importlib.import_module(where), name)


@pytest.mark.parametrize("command", ["demo", "evaluate", "bench", "train", "soak", "check"])
def test_help_shows_the_defaults(command, capsys):
    with pytest.raises(SystemExit):
        cli.main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: " in text
    assert "(default: None)" not in text and "(default: False)" not in text


def test_a_zero_default_is_shown():
    parser = cli.build_parser()
    demo = parser._subparsers._group_actions[0].choices["demo"]
    assert "(default: 0)" in " ".join(demo.format_help().split())


def test_sigterm_runs_the_ctrl_c_cleanup_and_is_one_line(monkeypatch, capsys, tmp_path):
    import os
    import signal

    from vc_gym.jobs.output import new_out_dir

    def terminated_while_working(args):
        with new_out_dir(tmp_path / "run"):
            os.kill(os.getpid(), signal.SIGTERM)
            raise AssertionError("SIGTERM was not heard")

    def parser():
        import argparse

        p = argparse.ArgumentParser()
        p.set_defaults(func=terminated_while_working, command="demo")
        return p

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(cli, "build_parser", parser)
    assert cli.main([]) == cli.EXIT_TERMINATED == 143
    assert capsys.readouterr().err == "vc-gym demo: terminated (SIGTERM)\n"
    assert not (tmp_path / "run").exists()  # the folder it made is gone again
    assert signal.getsignal(signal.SIGTERM) is before  # the caller's handler is back
