"""libyaml's parser (the default where PyYAML has it) and PyYAML's pure-Python one read configs alike."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from rangebearing.config import yaml_safe
from rangebearing.config.yaml_safe import load_yaml
from rangebearing.errors import ConfigError

from .test_fuzz import SHIPPED, _mutate
from .test_hostile import BOMB, HOSTILE

needs_libyaml = pytest.mark.skipif(yaml_safe._CLoader is None, reason="PyYAML without libyaml: one parser only")


def _outcome(path: Path, c_parser: bool) -> object:
    try:
        return ("data", repr(load_yaml(path, c_parser=c_parser)))
    except ConfigError as exc:
        return ("refused", str(exc))


@needs_libyaml
def test_the_shipped_config_reads_the_same_with_either_parser(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text(SHIPPED, encoding="utf-8")
    data = load_yaml(f, c_parser=True)
    assert data == load_yaml(f, c_parser=False) and isinstance(data, dict) and "detection" in data


@needs_libyaml
@pytest.mark.parametrize("content", [*[c for c, _ in HOSTILE.values()], BOMB, "a: &r [*r]\n",
                                     "camera:\n  fx_px: 600\n  fx_px: 700\n", "camera:\n  fy_px: [1, 2\n"])
def test_hostile_files_get_the_pure_python_parsers_answer(tmp_path: Path, content: object) -> None:
    f = tmp_path / "c.yaml"
    if isinstance(content, bytes):
        f.write_bytes(content)
    else:
        f.write_text(content, encoding="utf-8")
    assert _outcome(f, c_parser=True) == _outcome(f, c_parser=False)


@needs_libyaml
def test_mutated_configs_give_the_same_data_wherever_both_parsers_take_them(tmp_path: Path) -> None:
    rng = random.Random(21)
    f = tmp_path / "m.yaml"
    both = c_only = 0
    for _ in range(60):
        text = _mutate(rng, SHIPPED)
        f.write_text(text, encoding="utf-8", errors="surrogatepass")
        fast, slow = _outcome(f, c_parser=True), _outcome(f, c_parser=False)
        if slow[0] == "data":
            assert fast == slow  # libyaml's refusals fall back to the pure-Python parser
            both += 1
        elif fast[0] == "data":
            c_only += 1  # a file PyYAML refuses and libyaml takes (e.g. "|#"): its values meet the checks
        else:
            assert fast == slow  # both refuse: the pure-Python parser's words
    assert both > 10 and c_only <= 3


def test_without_libyaml_the_pure_python_parser_reads_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(yaml_safe, "_CLoader", None)
    f = tmp_path / "c.yaml"
    f.write_text("camera: {fx_px: 600}\n", encoding="utf-8")
    assert load_yaml(f) == {"camera": {"fx_px": 600}}
    f.write_text("camera: {fx_px: " + "9" * 500 + "}\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="digits is not a setting"):
        load_yaml(f)
