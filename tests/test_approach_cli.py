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
