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
    assert out["n_landmarks"] > 10 and out["median_plan_time_us"] > 0


def test_cli_rejects_unknown_method(capsys):
    assert main(["landing", "--method", "nope"]) == 2
    err = capsys.readouterr().err
    assert "--method" in err and "unknown planning method 'nope'" in err
