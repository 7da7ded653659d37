"""Results pages written by the commands: provenance, figures, plots, and bad paths."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

import vc_gym  # noqa: E402
from vc_gym.cli import main  # noqa: E402
from vc_gym.experiments.results_page import (  # noqa: E402
    WRITTEN_BY,
    PageInfo,
    check_page_path,
    seeds_text,
    source_commit,
    write_page,
)

INFO = PageInfo("Title", "vc-gym experiment x --seed 3", "what it measures", "base seed 3")


def _plot(path: Path) -> Path:
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    fig.savefig(path)
    plt.close(fig)
    return path


def test_page_holds_provenance_figures_and_plots(tmp_path: Path) -> None:
    plot = _plot(tmp_path / "errors.png")
    page = write_page(tmp_path / "docs" / "x.md", INFO, ["median 0.35°"], {"median": 0.35}, [plot])
    text = page.read_text()
    for expected in (
        "# Title", "What it measures", WRITTEN_BY, "`vc-gym experiment x --seed 3`",
        f"| vc_gym | {vc_gym.__version__}, commit ", "| machine | ", "| seeds | base seed 3 |",
        "median 0.35°", "![errors](x/errors.png)", "[`results.json`](x/results.json)",
    ):
        assert expected in text, expected
    assert json.loads((tmp_path / "docs" / "x" / "results.json").read_text()) == {"median": 0.35}
    assert (tmp_path / "docs" / "x" / "errors.png").read_bytes() == plot.read_bytes()


def test_rewriting_a_page_drops_old_plots(tmp_path: Path) -> None:
    write_page(tmp_path / "x.md", INFO, [], {}, [_plot(tmp_path / "old.png")])
    write_page(tmp_path / "x.md", INFO, [], {}, [])
    assert not (tmp_path / "x" / "old.png").exists() and "## Plots" not in (
        tmp_path / "x.md"
    ).read_text()


def test_rewriting_a_page_keeps_its_discussion(tmp_path: Path) -> None:
    page = write_page(tmp_path / "x.md", INFO, ["median 0.35°"], {}, [])
    page.write_text(page.read_text() + "\n## Discussion\n\nWhy it is so.\n")
    text = write_page(page, INFO, ["median 0.30°"], {}, []).read_text()
    assert "median 0.30°" in text and "median 0.35°" not in text
    assert text.endswith("## Discussion\n\nWhy it is so.\n")


@pytest.mark.parametrize("name", ["page.txt", "page"])
def test_a_page_must_be_markdown(tmp_path: Path, name: str) -> None:
    with pytest.raises(ValueError, match="--page must name a Markdown file"):
        check_page_path(tmp_path / name)


def test_seeds_are_named_from_the_results() -> None:
    assert seeds_text({"learning_seeds": [0, 1, 2]}, 5) == "learning seeds 0, 1, 2"
    assert seeds_text({"seeds": [4]}, 5) == "seeds 4"
    assert seeds_text({}, 5).startswith("base seed 5")


def test_commit_outside_git(tmp_path: Path) -> None:
    assert source_commit(tmp_path) == "not a git checkout"


@pytest.mark.slow
def test_experiment_writes_its_figures_plot_and_page(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    page = tmp_path / "docs" / "results" / "synthetic-compass.md"
    out = tmp_path / "run"
    argv = ["experiment", "synthetic-compass", "--out", str(out), "--seed", "3"]
    argv += ["--page", str(page)]
    assert main(argv) == 0
    summary = json.loads((out / "results.json").read_text())
    assert set(summary["results"]) == {
        f"{scene}/exposure={e}"
        for scene in ("room", "outdoor")
        for e in ("none", "mean", "map", "session")
    }
    normal = summary["results"]["room/exposure=none"]["illumination_1.0"]
    assert normal["median_error_deg"] < 5.0
    # every correction keeps the heading at half light, where the paper's compass loses it
    for e in ("mean", "map", "session"):
        assert summary["results"][f"room/exposure={e}"]["illumination_0.5"]["within_5deg"] >= 0.85
    session = summary["results"]["room/exposure=session"]
    assert session["illumination_1.0"]["session_gain"] == 1.0
    assert session["illumination_0.5"]["session_gain"] == 2.0
    assert session["illumination_1.0"]["median_error_deg"] == normal["median_error_deg"]
    assert "duration_s" not in summary  # results.json holds figures only
    png = (out / "synthetic_compass.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    # the page: the command as typed, the figures exactly as printed, a copy of the run
    text = page.read_text()
    assert f"`vc-gym experiment synthetic-compass --out {out} --seed 3 --page {page}`" in text
    first_figure = capsys.readouterr().out.splitlines()[0]
    assert first_figure in text
    assert json.loads((page.with_suffix("") / "results.json").read_text()) == summary
    assert any(p.suffix == ".png" for p in page.with_suffix("").iterdir())


def test_a_bad_page_fails_before_any_work(tmp_path: Path) -> None:
    argv = ["experiment", "synthetic-compass", "--out", str(tmp_path / "run"), "--page", "x.txt"]
    assert main(argv) == 2
    assert not (tmp_path / "run").exists()


def test_bench_writes_its_page(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    page = tmp_path / "bench-compass.md"
    argv = ["bench", "compass", "--frames", "2", "--repeats", "1", "--page", str(page)]
    assert main(argv) == 0
    printed = capsys.readouterr().out.splitlines()
    text = page.read_text()
    assert "# `vc-gym bench compass`" in text and "localize / floor" in text
    assert all(line in text for line in printed[:3])
    assert "learn_ms" in (tmp_path / "bench-compass" / "results.json").read_text()
