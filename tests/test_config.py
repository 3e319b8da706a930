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


def test_schema_defaults_are_the_full_profile():
    """The schema's defaults (what an installed ``opnav`` uses outside a
    checkout) equal config/config.yaml key for key, nested sections included."""
    from opnav.config import SCHEMA_PATH, validate_config

    defaults = validate_config({}, SCHEMA_PATH)
    full = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    assert defaults == full


def test_outside_a_checkout_the_schema_defaults_apply(tmp_path, monkeypatch):
    import opnav.config as oc

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(oc, "repo_root", lambda start=None: (_ for _ in ()).throw(ConfigError("no checkout")))
    over = tmp_path / "o.yaml"
    over.write_text(yaml.safe_dump({"landing": {"mc": {"n_runs": 7}}}))
    cfg = load_config(overlays=[over])
    assert cfg["landing"]["mc"]["n_runs"] == 7
    assert cfg["approach"]["em"] == load_config(REPO / "config" / "config.yaml")["approach"]["em"]
