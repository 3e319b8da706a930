"""Out-of-sample filter tuning (opnav.landing.tuning): the choice rule on
hand-made NEES, and the tuning runs on their own seed stream."""

import pytest

from opnav.landing.tuning import _tiers, choose, tuning_report


def _row(scale, it, npos, nvel, lo=2.29, hi=3.81):
    return {"meas_noise_scale": scale, "iterations": it, "nees_pos": npos, "nees_vel": nvel,
            "consistent": lo <= npos <= hi and lo <= nvel <= hi,
            "not_overconfident": npos <= hi and nvel <= hi}


def test_choice_prefers_consistent_then_not_overconfident_smallest_scale():
    rows = [_row(2, 3, 17.0, 18.0), _row(4, 3, 3.1, 3.9), _row(5, 3, 2.2, 2.7), _row(6, 3, 2.1, 2.2)]
    assert choose(rows)["meas_noise_scale"] == 5 and choose(rows)["tier"] == "not_overconfident"
    rows[1] = _row(4, 3, 3.1, 3.5)                 # now consistent: it wins
    assert (choose(rows)["meas_noise_scale"], choose(rows)["tier"]) == (4, "consistent")
    # one tuning for two scenarios: the binding one decides
    other = [_row(2, 3, 3.2, 4.4), _row(4, 3, 1.8, 1.9), _row(5, 3, 1.7, 1.8), _row(6, 3, 1.6, 1.7)]
    rows[1] = _row(4, 3, 3.1, 3.9)
    assert choose(other)["meas_noise_scale"] == 4
    assert _tiers({"a": rows, "b": other})["meas_noise_scale"] == 5


def test_tuning_runs_use_their_own_stream():
    from conftest import REPO
    from opnav.core.config import load_config
    from opnav.landing.scenario import camera_scenarios

    cfg = load_config(overlays=[str(REPO / "config" / "quick.yaml")])["landing"]
    scn = {"interior": camera_scenarios(cfg)["interior"]}
    tc = {"base_seed": 5, "n_runs": 2, "method": "closest", "candidates": [[5.0, 3]]}
    out = tuning_report(scn, tc)
    assert out["configured"] == {"meas_noise_scale": 5.0, "iterations": 3}
    assert out["config_matches"] == (out["chosen"]["meas_noise_scale"] == 5.0)
    row = out["scenarios"]["interior"]["candidates"][0]
    assert row["nees_pos"] > 0 and out["band"][0] < 3 < out["band"][1]
    with pytest.raises(ValueError, match="must differ"):
        tuning_report(scn, {**tc, "base_seed": cfg["mc"]["base_seed"]})
