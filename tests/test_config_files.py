"""Settings files: plain data only, bounded size and depth, clear errors naming the file."""

from __future__ import annotations

import json

import pytest

from vc_gym.config_files import MAX_SETTINGS_BYTES, MAX_SETTINGS_DEPTH, read_settings
from vc_gym.experiments.check_security import alias_bomb


@pytest.mark.parametrize("name", ["s.json", "s.yml", "s.yaml"])
def test_json_and_yaml_give_the_same_mapping(tmp_path, name):
    data = {"algo": "ppo", "net_arch": [64, 64], "gamma": 0.99}
    path = tmp_path / name
    if name.endswith(".json"):
        path.write_text(json.dumps(data))
    else:
        path.write_text("algo: ppo\nnet_arch: [64, 64]\ngamma: 0.99\n")
    assert read_settings(path) == data


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("s.txt", "{}", "must be .json"),
        ("s.json", "{not json", "not valid JSON"),
        ("s.yml", "a: [1, 2", "not valid YML"),
        ("s.json", "[1, 2]", "one mapping"),
        ("s.yml", "- 1\n- 2\n", "one mapping"),
        ("s.json", "[" * 100_000 + "]" * 100_000, "nested"),
        ("s.json", '{"a":' * 30 + "1" + "}" * 30, "nested deeper"),
        ("s.yml", "a: !!python/object/apply:os.system ['echo hacked']\n", "not valid YML"),
        ("s.json", "", "not valid JSON"),
    ],
)
def test_bad_settings_files_are_refused_naming_the_file(tmp_path, name, text, message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as err:
        read_settings(path)
    assert str(path) in str(err.value)


def test_huge_missing_and_binary_files_are_refused(tmp_path):
    big = tmp_path / "big.json"
    big.write_text(" " * (MAX_SETTINGS_BYTES + 1))
    with pytest.raises(ValueError, match="more than"):
        read_settings(big)
    with pytest.raises(ValueError, match="cannot read"):
        read_settings(tmp_path / "missing.yaml")
    binary = tmp_path / "b.json"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match="cannot read"):
        read_settings(binary)
    assert MAX_SETTINGS_DEPTH >= 5


def test_a_yaml_alias_bomb_is_refused_at_once(tmp_path):
    path = tmp_path / "bomb.yml"
    path.write_text(alias_bomb())
    assert path.stat().st_size < 1000
    with pytest.raises(ValueError, match="aliases") as err:
        read_settings(path)
    assert str(path) in str(err.value)


def test_one_yaml_alias_is_refused_too(tmp_path):
    path = tmp_path / "s.yml"
    path.write_text("base: &b {gamma: 0.9}\nrun: *b\n")
    with pytest.raises(ValueError, match="aliases"):
        read_settings(path)


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("s.yml", "gamma: 0.9\nalgo: ppo\ngamma: 0.5\n"),
        ("s.yml", "env:\n  scene: robolab\n  scene: office\n"),
        ("s.json", '{"gamma": 0.9, "gamma": 0.5}'),
        ("s.json", '{"env": {"scene": "robolab", "scene": "office"}}'),
    ],
)
def test_a_key_given_twice_is_refused(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ValueError, match="appears twice") as err:
        read_settings(path)
    assert str(path) in str(err.value)
