"""The configuration loader the CLI uses applies the same schema as Snakemake."""

import pytest
import yaml

from conftest import REPO
from opnav.config import ConfigError, load_config


def test_defaults_fill_missing_keys(tmp_path):
    cfg_path = tmp_path / "c.yaml"
    cfg_path.write_text(yaml.safe_dump({"approach": {}, "landing": {}}))
    cfg = load_config(REPO / "config" / "config.yaml", overlays=[cfg_path])
    assert cfg["landing"]["mc"]["n_runs"] == 300
    assert cfg["landing"]["initial_state"]["r_m"] == [3300.0, 5870.0, 6570.0]


def test_missing_file_is_named(tmp_path):
    with pytest.raises(ConfigError, match="nope.yaml"):
        load_config(REPO / "config" / "config.yaml", overlays=[tmp_path / "nope.yaml"])


def test_bad_value_names_key(tmp_path):
    bad = tmp_path / "b.yaml"
    bad.write_text(yaml.safe_dump({"landing": {"mc": {"runs_per_job": -1}}}))
    with pytest.raises(ConfigError, match=r"landing\.mc\.runs_per_job"):
        load_config(REPO / "config" / "config.yaml", overlays=[bad])
