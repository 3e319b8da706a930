"""The approach config parsed once into a frozen Setup (approach.setup)."""

import dataclasses

import pytest

from approach_helpers import approach_cfg
from opnav.approach import scenario as sc
from opnav.approach.setup import Missing, Setup


def test_setup_holds_the_config_values_and_is_frozen():
    cfg = approach_cfg(N0=30, N=10, L=4)
    s = Setup.of(cfg)
    assert Setup.of(s) is s
    assert (s.segments.N0, s.segments.N, s.segments.L) == (30, 10, 4)
    assert s.segments.windows() == [(30 + 10 * l, 40 + 10 * l) for l in range(4)]
    assert s.camera.sigma3_px == tuple(cfg["camera"]["sigma3_px"])
    assert s.em.method == cfg["em"]["method"] and s.base_seed == cfg["base_seed"]
    assert s.alternatives.batch_ml.checkpoint_stride == cfg["alternatives"]["batch_ml"]["checkpoint_stride"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.n_seeds = 3


def test_growing_scheme_covers_the_same_data():
    cfg = approach_cfg(N0=30, N=10, L=4)
    cfg["growing"].update(N=20, M=3)
    g = Setup.of(cfg).scheme("growing").segments
    assert (g.mode, g.N, g.M, g.L) == ("growing", 20, 3, 2)
    assert g.windows() == [(30, 50), (30, 70)]
    cfg["growing"]["N"] = 15
    with pytest.raises(ValueError, match="growing.N"):
        Setup.of(cfg).scheme("growing")


def test_a_key_the_rule_did_not_pass_fails_naming_it():
    cfg = approach_cfg()
    part = Setup.of({k: cfg[k] for k in ("segments", "accuracy_target_arcsec")})
    assert part.segments.N == cfg["segments"]["N"]
    assert isinstance(part.em, Missing)
    with pytest.raises(KeyError, match="approach.em"):
        part.em.method
    with pytest.raises(KeyError, match="approach.n_seeds"):
        range(part.n_seeds)


def test_measurement_variance_refuses_a_different_camera():
    cfg = approach_cfg(N0=5, N=5, L=1)
    geo = sc.build_geometry(cfg, "literal")
    other = approach_cfg(N0=5, N=5, L=1)
    other["camera"]["ifov_arcsec"] = 20.0
    with pytest.raises(ValueError, match="ifov_arcsec"):
        sc.measurement_variance(geo, other, (0.1, 0.1, 0.2))
    assert (sc.measurement_variance(geo, cfg, (0.1, 0.1, 0.2)) == geo.measurement_variance((0.1, 0.1, 0.2))).all()
