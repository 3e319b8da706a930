"""`opnav landing` prints a JSON summary of one descent and rejects bad input."""

import json

import pytest

from conftest import REPO
from opnav.cli import main


@pytest.mark.parametrize("method", ["depth", "svd"])
def test_cli_flies_one_descent(capsys, method):
    rc = main(["--config", str(REPO / "config" / "quick.yaml"), "landing", "--method", method,
               "--seed", "2"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("final_pos_err_m", "rms_pos_err_m", "final_vel_err_mps", "rms_vel_err_mps",
                "final_att_err_deg", "rms_att_err_deg", "n_landmarks", "median_plan_time_us",
                "mean_nees_pos", "mean_nees_vel"):
        assert key in out
    assert out["method"] == method and out["seed"] == 2
    assert out["scenario"] == "interior"                      # the headline scenario by default


@pytest.mark.slow  # ~1.1 CPU-s (issue 56: the default run <= 90 s)
def test_cli_scenario_flag_flies_that_camera(capsys):
    from opnav.core.config import load_config
    from opnav.landing.descent import build_scenario, run_descent
    from opnav.landing.montecarlo import summarize_run
    from landing_helpers import scenario_setups

    quick = str(REPO / "config" / "quick.yaml")
    assert main(["--config", quick, "landing", "--scenario", "site-tilt", "--seed", "1"]) == 0
    out = json.loads(capsys.readouterr().out)
    cfg = scenario_setups(load_config(overlays=[quick])["landing"])["site-tilt"]
    want = summarize_run(run_descent(build_scenario(cfg), "depth", 1))
    assert out["scenario"] == "site-tilt"
    assert out["final_pos_err_m"] == pytest.approx(want.stats["final_pos_err_m"], rel=1e-9)
    assert main(["landing", "--scenario", "nope"]) == 2
    assert "--scenario 'nope'" in capsys.readouterr().err
    assert out["n_landmarks"] > 10 and out["median_plan_time_us"] > 0


def test_cli_rejects_unknown_method(capsys):
    assert main(["landing", "--method", "nope"]) == 2
    err = capsys.readouterr().err
    assert "--method" in err and "'nope' is not one of" in err
