"""``opnav approach`` prints a JSON summary; bad flags give clear errors."""

import json

from opnav.cli import main


def test_cli_runs_one_case_and_prints_json(capsys):
    rc = main(["approach", "--bias", "10", "20", "10", "--seeds", "2", "--variant", "reference-start",
               "--N0", "50", "--N", "50", "--M", "3", "--L", "3", "--method", "squarem"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("truth_arcsec", "estimate_arcsec", "crlb_arcsec", "iterations",
                "data_to_converge_samples", "nav_err_before_km", "nav_err_after_km"):
        assert key in out
    assert out["crlb_arcsec"]["tz"] == "unobservable"
    est = out["estimate_arcsec"]["mean"]
    crlb = out["crlb_arcsec"]["tx"]
    assert abs(est[0] - 10.0) < 5 * max(crlb, 0.05) + 0.5
    assert out["nav_err_after_km"] < out["nav_err_before_km"]
    # the bound of the data used with Q = 0 beside it: no process noise can only add information
    for used, q0 in (("crlb_arcsec", "crlb_q0_arcsec"), ("crlb_all_data_arcsec", "crlb_all_data_q0_arcsec")):
        assert 0 < out[q0]["tx"] <= out[used]["tx"] * (1 + 1e-9)
    assert out["label"] in ("converged", "stalled", "not converged")
    assert out["reading"].startswith(out["label"])


def test_cli_rejects_bad_values(capsys):
    assert main(["approach", "--seeds", "0"]) == 2
    assert "--seeds" in capsys.readouterr().err


def test_cli_names_the_data_its_bound_covers(capsys):
    """Issue 44, item 5: the literal start carries every sample from t0, so the bound printed
    for the last segment is that of samples 1..end with the prior, and the text must say so
    (it said 'samples 2151..2200' before). Sliding prior windows name only their own window."""
    from opnav.approach import pipeline
    from approach_helpers import approach_cfg

    argv = ["approach", "--seeds", "1", "--N0", "50", "--N", "20", "--M", "2", "--L", "3", "--method", "plain"]
    assert main(argv + ["--variant", "literal"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["crlb_arcsec"]["data"].startswith("samples 1..110 ")
    assert out["crlb_all_data_arcsec"]["data"].startswith("samples 1..110 ")
    from opnav.approach.setup import Setup

    cfg = approach_cfg(N0=50, N=20, M=2, L=3)
    d = pipeline.bound_data(Setup.from_config(cfg), "prior")
    assert (d.first_sample, d.last_sample, d.n_samples) == (91, 110, 20)
    cfg["segments"]["mode"] = "growing"
    assert pipeline.bound_data(Setup.from_config(cfg), "roll").first_sample == 51
