"""Result files: names checked against the file system before any work, JSON synced to
the disk before it is renamed into place, JSON read within bounds."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from vc_gym.jobs import output
from vc_gym.jobs.output import (
    TEMP_NAME_EXTRA,
    check_out_dir,
    check_out_file,
    new_out_dir,
    read_json,
    write_json,
)


def _name_max(folder: Path) -> int:
    return os.pathconf(folder, "PC_NAME_MAX")


def test_a_name_whose_temporary_file_does_not_fit_is_refused(tmp_path):
    """A 245-byte name fits the file system, but the atomic writer's temporary name for
    it (``.{name}.XXXXXXXX.tmp.json``) does not: refused before the work, not after."""
    limit = _name_max(tmp_path)
    name = "a" * (limit - 10) + ".json"
    with pytest.raises(ValueError, match=r"--out .*temporary file.* at most"):
        check_out_file(tmp_path / name)
    assert list(tmp_path.iterdir()) == []


def test_the_longest_accepted_name_can_be_written(tmp_path):
    limit = _name_max(tmp_path)
    name = "b" * (limit - TEMP_NAME_EXTRA - len(".json") - len(".json")) + ".json"
    path = check_out_file(tmp_path / name)
    write_json(path, {"ok": True})  # the result and its temporary file both fit
    assert read_json(path) == {"ok": True}
    with pytest.raises(ValueError, match="temporary file"):
        check_out_file(tmp_path / ("b" + name))


def test_a_refused_file_name_leaves_no_folders_behind(tmp_path):
    target = tmp_path / "new" / "deeper" / ("c" * 250 + ".json")
    with pytest.raises(ValueError, match="--out"):
        check_out_file(target)
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("make", ["name", "parent"])
def test_a_folder_name_too_long_is_refused_without_a_trace(tmp_path, make):
    long = "d" * 300
    target = tmp_path / long if make == "name" else tmp_path / "new" / long / "run"
    with pytest.raises(ValueError, match="--out .*folder name.*byte limit"):
        check_out_dir(target)
    assert list(tmp_path.iterdir()) == []


def test_the_flag_is_named_in_the_error(tmp_path):
    with pytest.raises(ValueError, match="^--plot "):
        check_out_file(tmp_path / ("e" * 300 + ".png"), "--plot")


def test_a_folder_is_not_a_result_file(tmp_path):
    with pytest.raises(ValueError, match="is a folder"):
        check_out_file(tmp_path)


def test_new_out_dir_removes_the_folders_it_made_when_the_run_fails(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with new_out_dir(tmp_path / "a" / "b" / "run"):
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept").mkdir()
    with pytest.raises(RuntimeError):
        with new_out_dir(tmp_path / "kept" / "run") as out:
            (out / "partial.json").write_text("{}")
            raise RuntimeError("failed after writing")
    assert (tmp_path / "kept" / "run" / "partial.json").is_file()  # nothing written is lost


def test_write_json_syncs_the_file_before_it_is_renamed(tmp_path, monkeypatch):
    path = tmp_path / "result.json"
    synced: list[bool] = []
    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        synced.append(path.exists())  # False: the temporary file, before the rename
        real_fsync(fd)

    monkeypatch.setattr(output.os, "fsync", fsync)
    write_json(path, {"a": 1})
    assert synced and synced[0] is False
    assert read_json(path) == {"a": 1}


def test_read_json_is_bounded(tmp_path):
    big = tmp_path / "big.json"
    big.write_text('"' + "x" * 100 + '"')
    with pytest.raises(ValueError, match="larger than 50 bytes"):
        read_json(big, max_bytes=50)
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match="nested too deeply"):
        read_json(deep)
    torn = tmp_path / "torn.json"
    torn.write_text('{"a": ')
    with pytest.raises(ValueError, match="not valid JSON"):
        read_json(torn)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_read_json_never_opens_a_fifo(tmp_path):
    fifo = tmp_path / "results.json"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        read_json(fifo)
