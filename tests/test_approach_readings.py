"""Paper A's installation rows and sample time read against the model (issue 44, item 5)."""

from dataclasses import replace

import numpy as np

from opnav.approach import camera, readings
from opnav.core import published
from opnav.report.approach import text as words

from approach_helpers import approach_cfg, approach_setup
from opnav.approach.setup import Setup


def test_installation_cancels_from_the_measurement_by_construction():
    """The chain A_m A_c^b A_b^i with the commanded body attitude gives the same data for every
    installation angle (rounding only). Mutation tried: a body attitude that ignores the
    installation (A_b^i = A_c^i) changes the data by ~1 and fails."""
    chk = readings.installation_check(approach_setup(), [0.0, 45.0, 90.0, 135.0, 180.0], (10.0, 20.0, 10.0), n=20)
    assert chk.by_construction and chk.max_rel_change < 1e-12
    # a body-frame deviation would not cancel: ty takes tz's value at 90 deg (rot_x(90) (tx, ty, tz))
    np.testing.assert_allclose(chk.body_frame_theta_cam_arcsec[2], camera.rot_x(np.pi / 2) @ [10.0, 20.0, 10.0])
    assert "by construction" in words.installation_text(chk)
    assert "cancels" in words.installation_why(chk)


def test_sample_time_reading_puts_both_steps_side_by_side():
    """250 samples 'about 4 min' imply 0.96 s a sample; the config's step is beside it, and the
    roll variant's bound after 250 samples is smaller at the longer step (more roll turned)."""
    cfg = approach_setup(N0=200, N=50, L=5)
    pa = published.paper_a()
    st = readings.sample_time_reading(cfg, pa["headline"], pa["simulation"])
    assert st.dt_s.paper_4_min == 240.0 / 250
    assert st.dt_s.config == cfg.dt_s
    assert abs(st.minutes_for_samples.paper_4_min - 4.0) < 1e-12
    b = st.bound_after_samples_arcsec["roll"]
    assert b.paper_4_min < b.config
    assert "0.96 s a sample" in words.sample_time_text(st)


def test_study_estimator_growing_squarem_converges_where_sliding_plain_stalls():
    """A-X5's converging estimator (issue 44, item 5): SQUAREM over growing windows reaches the
    ML estimate of all the data in the roll variant, where sliding plain EM stalls, and its
    bound is that of all the data after N0 (below the last window's)."""
    from opnav.approach import study

    cfg = approach_cfg(N0=200, N=50, M=5, L=8)
    cfg["initial_error"]["mode"] = "sampled"
    cfg["growing"].update(N=100, M=5)
    cfg = Setup.from_config(cfg)
    em = study.run_runs(cfg, "roll", "em", [0, 1])
    gr = study.run_runs(cfg, "roll", "em_growing_squarem", [0, 1])
    assert (em["converged_pct"] == 0).all() and (gr["converged_pct"] == 100).all()
    assert (gr["crlb_used_x_arcsec"] < em["crlb_used_x_arcsec"]).all()


def _star_row(sweep, value, bound, per_image=10, att=5.0):
    curve = np.full((11, 3), bound)
    th = np.array([[10.0, 20.0, 10.0], [10.5, 19.5, 12.0]])
    from opnav.approach.alternatives import StarCounts, StarsEstimate, StarsRow

    return StarsRow(sweep=sweep, value=value, per_image=per_image, every_K=200, images=10,
                    attitude_sigma_arcsec=att, mode_drift_arcsec=1.0, mag_limit=8.0,
                    stars_per_image=(StarCounts(per_image, float(per_image), per_image)
                                     if sweep == "per_image" else StarCounts(10, 10.0, 10)),
                    field_deg=2.84 if per_image < 10 else 6.0, camera_field_deg=2.84, floor_arcsec=1.87,
                    crlb_stars_only_arcsec=np.full(3, bound), truth_arcsec=np.array([10.0, 20.0, 10.0]),
                    total_samples=10, crlb_all_arcsec=np.full(3, bound), crlb_all_q0_arcsec=np.full(3, bound),
                    crlb_curve_arcsec=curve,
                    estimators={"em_growing_squarem": StarsEstimate(th, np.full(2, 100.0),
                                                                    label=np.array(["converged"] * 2),
                                                                    theta_ml_arcsec=th)},
                    attitude_threshold_arcsec=5.38)


def doc(record):
    """A record as A-summary.json holds it (what the report reads back)."""
    from opnav.core.tables import json_ready

    return json_ready(record, nan_as_none=False)


def test_stars_text_reads_the_objection_from_the_numbers():
    """The manuscript's answer to paper A's objection comes from the study's numbers: the
    threshold, and whether more stars lowered the bound (a gain or none, as measured)."""
    from opnav.approach import summaries
    from opnav.report import approach_text

    rows = [_star_row("per_image", 3, 1.9, per_image=3), _star_row("per_image", 30, 1.9, per_image=30),
            _star_row("attitude_sigma_arcsec", 0.0, 1.07, att=0.0), _star_row("attitude_sigma_arcsec", 20.0, 6.1, att=20.0)]
    st = doc(summaries.stars_summary(rows, 2.0))
    assert set(st) == {"m3", "m30", "att0", "att20", "objection"}
    txt = approach_text.stars_text(st, 2.0)
    assert "better than 5.38 arcsec" in txt and "(unchanged)" in txt
    assert "With 3 stars in every image (to magnitude 8 in a 2.84 deg field) the bound" in txt
    assert "With 30 stars in every image (to magnitude 8 in a 6 deg field, widened from the camera's 2.84 deg)" in txt
    from opnav.core import wording
    assert not wording.long_sentences(txt), wording.long_sentences(txt)
    rows[1] = _star_row("per_image", 30, 0.95, per_image=30)
    assert "(50 % lower)" in approach_text.stars_text(doc(summaries.stars_summary(rows, 2.0)), 2.0)
    rows = [replace(r, attitude_threshold_arcsec=0.0) for r in rows]
    assert "does not answer" in approach_text.stars_text(doc(summaries.stars_summary(rows, 2.0)), 2.0)
