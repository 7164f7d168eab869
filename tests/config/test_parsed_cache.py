"""config/parsed_cache.py: a config read again from the cache validates to the same Config, without PyYAML."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from rangebearing.config import load_config
from rangebearing.config.parsed_cache import _decode, _encode, parsed
from rangebearing.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("data", [
    None, {"a": 1, "b": 1.0, "c": True, "d": None, "e": "x"},
    {1: "int key", 2.5: "float key", False: "bool key", None: "null key"},
    [1, [2.0, [float("inf"), -0.0]], {"k": [False]}], "text",
])
def test_the_stored_form_keeps_every_value_and_its_type(data):
    back = _decode(_encode(data))
    assert repr(back) == repr(data) and type(back) is type(data)


def test_nan_survives():
    assert math.isnan(_decode(_encode(float("nan"))))


def test_a_cached_file_loads_the_same_config_and_a_changed_one_is_parsed_again(tmp_path, monkeypatch):
    monkeypatch.setenv("RANGEBEARING_CACHE", str(tmp_path / "cache"))
    path = ROOT / "config" / "rangebearing.yaml"
    first = load_config(path)
    assert len(list((tmp_path / "cache").glob("config-*.json"))) == 1
    calls = []
    assert parsed(path, lambda p: calls.append(p)) is not None and calls == []  # read back, not parsed
    assert load_config(path) == first
    edited = tmp_path / "edited.yaml"
    edited.write_text(path.read_text(encoding="utf-8").replace("status_interval_s: 5.0", "status_interval_s: 7.0"),
                      encoding="utf-8")
    assert load_config(edited).daemon.status_interval_s == 7.0
    bad = tmp_path / "bad.yaml"
    bad.write_text("daemon: {status_interval_s: -1, nonsense: 1}\n", encoding="utf-8")
    for _ in range(2):  # the second time from the cache: the same problems, every one named
        with pytest.raises(ConfigError, match=r"daemon\.status_interval_s.*\n.*daemon\.nonsense|daemon\.nonsense"):
            load_config(bad)


def test_a_cache_that_cannot_be_written_or_read_only_costs_the_parse(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("RANGEBEARING_CACHE", str(blocker / "cache"))
    assert load_config(ROOT / "config" / "rangebearing.yaml").daemon.status_interval_s == 5.0
    garbage = tmp_path / "garbage"
    monkeypatch.setenv("RANGEBEARING_CACHE", str(garbage))
    load_config(ROOT / "config" / "rangebearing.yaml")
    for entry in garbage.glob("config-*.json"):
        entry.write_text('{"v": 1, "data": {"m": [["daemon", {"m": [["status_interval_s", {"x": 1}]]}]]}}')
    assert load_config(ROOT / "config" / "rangebearing.yaml").daemon.status_interval_s == 5.0


def test_run_reads_a_cached_config_without_importing_pyyaml(tmp_path):
    env_cache = str(tmp_path / "cache")
    code = ("import sys; from rangebearing.config import load_config; "
            f"load_config({str(ROOT / 'config' / 'rangebearing.yaml')!r}); print('yaml' in sys.modules)")
    env = {"RANGEBEARING_CACHE": env_cache, "PATH": "/usr/bin:/bin"}
    runs = [subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
            for _ in range(2)]
    assert [r.stdout.strip() for r in runs] == ["True", "False"]
