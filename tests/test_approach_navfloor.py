"""Navigation error against arc length and tz's effect on navigation (issue 54, items 6-7), and
the summary keys the claims table reads (the contract of issue 54)."""

import dataclasses
import math

import numpy as np
import pytest

from opnav.approach import cases, navfloor, summaries
from opnav.approach.preflight import approach_problems
from opnav.approach.setup import Setup

from approach_helpers import approach_cfg


def _cfg():
    cfg = approach_cfg(N0=50, N=50, M=2, L=2)
    cfg["growing"].update(N=50, M=3)
    cfg["n_seeds"] = 3
    cfg["nav_floor"] = {"variant": "roll", "scheme": "growing-squarem", "arcs_s": [75.0, 125.0]}
    return cfg


@pytest.mark.slow
def test_each_arc_is_the_run_of_that_arc_alone():
    """The row of an arc equals the EM-EKF run on that arc alone (cases.run_cases with the
    segments ending there, growing windows, SQUAREM): the estimate of a growing window uses the
    data up to its end only, and a filtered error does not depend on later samples. The true-theta
    and theta = 0 filters too. Mutation tried: the longest arc's estimate used for every arc fails
    the short arc's row."""
    cfg = Setup.from_config(_cfg())
    out = navfloor.nav_floor_by_arc(cfg, "roll", "growing-squarem", [75.0, 125.0])
    assert [r.samples for r in out.rows] == [150, 250]
    for row in out.rows:
        c = approach_cfg(N0=50, N=50, M=2, L=(row.samples - 50) // 50)
        c["growing"].update(N=50, M=3)
        c["n_seeds"] = 3
        c["em"]["ml_max_maps"] = 3  # the label's reference (not compared here)
        s = Setup.from_config(c).scheme("growing")
        r = cases.run_case(s, "roll", cases.headline_case(s), range(3), method="squarem")
        np.testing.assert_allclose(row.nav_err_km_rule, r.nav_err_after_km.mean(), rtol=2e-5)
        np.testing.assert_allclose(row.true_theta_km_rule, r.nav_err_true_theta_km.mean(), rtol=2e-5)
        np.testing.assert_allclose(row.before_km_rule, r.nav_err_before_km.mean(), rtol=2e-5)
        np.testing.assert_allclose(row.nav_err_km_last, r.err_after_t_km[:, -1].mean(), rtol=2e-5)
        np.testing.assert_allclose(row.est_x_mean_arcsec, r.theta_final_arcsec[:, 0].mean(), rtol=2e-5)


def test_tz_does_not_move_the_navigation_error():
    """Paper A: the roll about the boresight does not affect navigation. With tz = 10 arcsec and 0
    (same seeds), filtered with the true (tx, ty) and tz = 0, the errors differ by far less than a
    metre per km of error; the same test on tx (left uncompensated) moves them by kilometres
    (control: the test can see an effect)."""
    setup = Setup.from_config(_cfg())
    for variant in ("literal", "roll"):     # the paper as written (A-C12's evidence), and rolling
        tz = navfloor.tz_nav_effect(setup, variant)
        assert tz.n_seeds == 3 and math.isfinite(tz.nav_err_km_tz_on) and tz.variant == variant
        assert abs(tz.diff_km_mean) < 1e-3 * tz.nav_err_km_tz_off
    # control: the same pairing with tx instead of tz
    from opnav.approach import scenario as sc
    from opnav.approach.ekf import run_filter

    geo = sc.build_geometry(setup, "roll")
    case = cases.headline_case(setup)
    err = []
    for tx in (10.0, 0.0):
        Rvar, z, dx0 = cases.simulate_case(setup, geo, case, range(3), truth_arcsec=(tx, 20.0, 0.0))
        f = run_filter(z, np.broadcast_to(sc.rad([0.0, 20.0, 0.0]), (3, 3)), dx0, geo.P0, geo.window(Rvar),
                       predicted=False)
        err.append(cases.rms_last(np.linalg.norm(f.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1), 0.5).mean())
    assert abs(err[0] - err[1]) > 1.0


def test_arcs_that_end_before_the_data_are_refused_before_any_work():
    cfg = approach_cfg()  # N0 = 200 samples of 0.5 s
    cfg["nav_floor"] = {"variant": "roll", "scheme": "growing-squarem", "arcs_s": [1100.0, 90.0]}
    msg = approach_problems(cfg)
    assert len(msg) == 1 and "'approach.nav_floor.arcs_s'" in msg[0] and "90 s" in msg[0]
    with pytest.raises(ValueError, match="approach.nav_floor.arcs_s"):
        navfloor.arc_samples(Setup.from_config(cfg), [90.0])
    cfg["nav_floor"]["arcs_s"] = [1100.0, 1234.0]  # any arc after N0: a growing window ends at it
    assert approach_problems(cfg) == []
    assert navfloor.growing_windows(200, 250, [2200, 2468])[-2:] == [(200, 2450), (200, 2468)]


def test_the_summary_holds_the_contract_keys():
    """The keys the claims engineer reads from A-summary.json (issue 54's contract)."""
    from types import SimpleNamespace

    from opnav.approach.navfloor import NavFloor, NavFloorRow
    from opnav.approach.readings import InstallationCheck
    from opnav.core.tables import json_ready
    from opnav.report.approach import text as words

    row = NavFloorRow(**{f.name: 1.0 for f in dataclasses.fields(NavFloorRow)})
    nf = NavFloor(variant="roll+growing+squarem", scenario="roll", scheme="growing-squarem", n_seeds=3,
                  last_fraction=0.5, rows=(row,))
    s = json_ready(summaries.nav_floor_summary(nf))
    assert set(s) == {"rule", "rows", "variant", "scenario", "scheme"}  # n_seeds, last_fraction: for the words only
    assert list(s["rows"][0])[:7] == ["arc_s", "variant", "nav_err_km_rule", "nav_err_km_last", "true_theta_km_rule",
                                      "true_theta_km_last", "n_seeds"]
    rr = summaries.roll_rate_bound_summary(SimpleNamespace(grid_rates_deg_s=np.array([0.01, 0.1]), samples=250,
                                                           bound_grid_arcsec=np.array([[9.0, 8.0, 1e3], [2.0, 3.0, 1e3]])))
    assert rr.rate_deg_s == [0.01, 0.1] and rr.bound_arcsec == [9.0, 3.0]
    ins = InstallationCheck(install_deg=[0.0, 90.0], max_rel_change=1e-16, by_construction=True,
                            body_frame_theta_cam_arcsec=[[10.0, 20.0, 10.0], [10.0, -10.0, 20.0]])
    assert json_ready(ins)["by_construction"] is True and "cancels" in words.installation_why(ins)
    import pandas as pd

    t1 = pd.DataFrame([{"case_id": "T1-01", "variant": "roll", "scenario": "roll", "method": "plain", "mode": "sliding",
                        "nees_pos_after_mean": 13.8, "nees_pos_true_theta_mean": 2.5, "nees_pos_consider_mean": 1.8,
                        "nees_pos_before_mean": 40.0, "nees_n_seeds": 20,
                        **{f"nees_pos_{k}_minus_true_theta_{q}": 1.0 for k in ("after", "consider")
                           for q in ("mean", "se")}}])
    n = summaries.nees_summary(t1)["roll"]
    assert (n.nees_mean, n.reference_nees_mean, n.n_seeds) == (13.8, 2.5, 20)


def test_the_nees_sentence_judges_against_the_true_theta_filter():
    """The consistency sentence reads the build's numbers and judges each compensated filter
    against the true-theta filter of the same runs (paired, two standard errors), never against 3."""
    from opnav.report import approach_text

    nees = {"roll+growing+squarem": {"nees_mean": 13.78, "reference_nees_mean": 2.53, "consider_nees_mean": 1.80,
                                     "n_seeds": 20, "after_minus_reference_mean": 11.2, "after_minus_reference_se": 2.0,
                                     "consider_minus_reference_mean": -0.73, "consider_minus_reference_se": 0.1}}
    txt = approach_text.nees_text(nees)
    assert "13.8" in txt and "2.53" in txt and "1.8" in txt and "20 seeds" in txt
    assert "above it (optimistic" in txt and "below it (conservative)" in txt and "3 expected" not in txt
    nees["roll+growing+squarem"]["consider_minus_reference_mean"] = -0.1
    assert "indistinguishable from it" in approach_text.nees_text(nees)


def test_the_a_x7_figure_and_table_draw_from_the_record():
    """A-X7 is drawn and tabled from the typed record (opnav.approach.navfloor.NavFloor), its words
    (the rule) made by the report layer; the table's columns are the row's fields in order."""
    import matplotlib

    matplotlib.use("Agg")
    from opnav.approach.navfloor import NavFloor, NavFloorRow
    from opnav.report.approach import plots
    from opnav.report.approach import text as words

    rows = tuple(NavFloorRow(**{**{f.name: 1.0 + i for f in dataclasses.fields(NavFloorRow)},
                                "variant": "roll+growing+squarem", "n_seeds": 3, "samples": 100 * (i + 1)})
                 for i in range(3))
    nf = NavFloor(variant="roll+growing+squarem", scenario="roll", scheme="growing-squarem", n_seeds=3,
                  last_fraction=0.5, rows=rows)
    frame = summaries.nav_floor_frame(nf)
    assert list(frame.columns) == [f.name for f in dataclasses.fields(NavFloorRow)] and len(frame) == 3
    fig = plots.fig_nav_floor(nf, 20.0)
    assert "3 seeds" in fig.axes[0].get_title()
    assert "RMS over the last 0.5 of the arc" in words.nav_floor_rule(nf.variant, nf.n_seeds, nf.last_fraction)
