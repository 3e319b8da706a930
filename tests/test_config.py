"""The configuration loader the CLI uses applies the same schema as Snakemake."""

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO
from opnav.core.config import ConfigError, load_config


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
    from opnav.core.config import SCHEMA_PATH, validate_config

    defaults = validate_config({}, SCHEMA_PATH)
    full = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    assert defaults == full


def test_outside_a_checkout_the_schema_defaults_apply(tmp_path, monkeypatch):
    import opnav.core.config as oc

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(oc, "repo_root", lambda start=None: (_ for _ in ()).throw(ConfigError("no checkout")))
    over = tmp_path / "o.yaml"
    over.write_text(yaml.safe_dump({"landing": {"mc": {"n_runs": 7}}}))
    cfg = load_config(overlays=[over])
    assert cfg["landing"]["mc"]["n_runs"] == 7
    assert cfg["approach"]["em"] == load_config(REPO / "config" / "config.yaml")["approach"]["em"]


@settings(max_examples=40, deadline=None)
@given(range_km=st.floats(4.0e3, 2.0e6), aim_km=st.floats(0.0, 5.0e4), v_inf=st.floats(0.2, 10.0),
       frac=st.sampled_from([0.01, 0.3, 0.6, 0.9, 0.97, 1.0, 1.03, 1.1, 1.5, 5.0]),
       dx=st.floats(-1.0, 1.0), dz=st.floats(-1.0, 1.0))
def test_closest_approach_closed_form_matches_numerical_integration(range_km, aim_km, v_inf, frac, dx, dz):
    """checks' closest range of the approach arc (closed-form hyperbola, the config
    check that refuses arcs reaching Mars or a disc larger than the detector) equals
    scipy's integration of the same two-body motion: before, at and past periapsis,
    and Mars' radius when the arc reaches the surface."""
    import numpy as np

    from opnav.approach import dynamics
    from opnav.approach.preflight import _hyperbola_min_range_km, _integrated_min_range_km

    d = np.array([0.3 + dx, -0.9, 0.1 + dz])
    d /= np.linalg.norm(d)
    perp = np.cross(d, [0.0, 0.0, 1.0])
    perp /= np.linalg.norm(perp)
    r0 = -range_km * d + aim_km * perp                 # as scenario.initial_truth builds it
    r0 *= range_km / np.linalg.norm(r0)
    v0 = np.sqrt(v_inf ** 2 + 2.0 * dynamics.MU_MARS / range_km) * d
    mu, R = dynamics.MU_MARS, dynamics.R_MARS_KM
    T = frac * range_km / np.linalg.norm(v0)           # arcs ending before, near and past periapsis
    got = _hyperbola_min_range_km(r0, v0, T, mu, R)
    want = _integrated_min_range_km(r0, v0, T, mu, R)
    assert got == pytest.approx(want, rel=1e-6)
    assert R <= got <= range_km


def test_the_approach_check_uses_the_closest_approach_of_the_configured_arc():
    """The configured arc's closest range is the closed form's, and an arc aimed
    at Mars is refused naming geometry."""
    from opnav.approach import dynamics, scenario
    from opnav.approach.preflight import _approach_min_range_km, _integrated_min_range_km, approach_problems

    a = load_config(REPO / "config" / "config.yaml")["approach"]
    T = 5.0e5
    from opnav.approach.setup import Setup

    X0 = scenario.initial_truth(Setup.from_config(a)) - dynamics.kepler_state(
        dynamics.KeplerElements.from_config(a["mars_elements"]), 0.0)
    assert _approach_min_range_km(a, T) == pytest.approx(
        _integrated_min_range_km(X0[:3], X0[3:], T, dynamics.MU_MARS, dynamics.R_MARS_KM), rel=1e-6)
    a["geometry"].update(aim_offset_km=0.0, range_km=6.0e3)   # Mars in ~10 min
    assert any("invalid config key 'approach.geometry'" in p and "surface" in p
               for p in approach_problems(a))
