"""The ``identity`` section: track-id settings in the YAML, checked, dumped, and what the pipeline gets."""

from __future__ import annotations

import dataclasses

import pytest
import yaml

from rangebearing.config import Config, config_from_mapping, dump_config
from rangebearing.core.identity import IdentityParams
from rangebearing.core.pipeline import Pipeline
from rangebearing.errors import ConfigError


def test_identity_settings_reach_the_pipeline_and_survive_a_dump():
    cfg = config_from_mapping({"identity": {"max_hidden_frames": 30, "gate_d2": 9.21, "rate_after_updates": 4}})
    assert cfg.identity == IdentityParams(max_hidden_frames=30, gate_d2=9.21, rate_after_updates=4)
    assert Pipeline(cfg.pipeline).params.identity is cfg.identity
    again = config_from_mapping(yaml.safe_load(dump_config(cfg)))
    assert again.identity == cfg.identity
    dumped = yaml.safe_load(dump_config(Config()))["identity"]
    assert set(dumped) == {f.name for f in dataclasses.fields(IdentityParams)}


def test_every_identity_problem_is_named_at_once():
    bad = {"max_hidden_frames": -1, "gate_d2": 0, "outlier_fraction": 1.0, "rate_after_updates": 1,
           "min_bearing_sigma_rad": "x", "max_hiden_frames": 3}
    with pytest.raises(ConfigError) as info:
        config_from_mapping({"identity": bad}, "c.yaml")
    text = str(info.value)
    for key in bad:
        assert f"identity.{key}:" in text, key
    assert "6 problems" in text


@pytest.mark.parametrize("values, says", [
    ({"max_hidden_frames": 4, "max_hidden_young_frames": 5}, "identity.max_hidden_young_frames: 5 is more than"),
    ({"nominal_dt_s": 0.1, "max_dt_s": 0.05}, "identity.max_dt_s: 0.05 s is less than"),
    ({"outlier_range_frac": 0.005}, "identity.outlier_range_frac: 0.005 is less than"),
    ({"outlier_bearing_rad": 0.001}, "identity.outlier_bearing_rad: 0.001 is less than"),
])
def test_contradicting_identity_settings_are_refused(values, says):
    with pytest.raises(ConfigError, match=says):
        config_from_mapping({"identity": values})
