"""The descent's end (issue 43 item 3): the end-phase table equals what the per-step records
of a small Monte Carlo say when counted one run and one step at a time; the NEES reading and
the manuscript's generated sentences follow the numbers."""

import dataclasses
import math

import numpy as np
import pytest

from opnav.landing.montecarlo import end_phase
from opnav.report.landing.summary import end_phase_text, nees_reading


@pytest.fixture(scope="module")
def small_run():
    """Two site-tilt descents of depth (the main seed stream, runs 0-1) and the truth altitude."""
    from opnav.core.config import load_config
    from opnav.landing.montecarlo import run_chunk
    from landing_helpers import scenario_setups
    from opnav.landing.scenario import build_scenario

    cfg = scenario_setups(load_config()["landing"])["site-tilt"]
    d = run_chunk(cfg, "depth", [0, 1], pick_ratio=False)
    return d, build_scenario(cfg).truth.r[:, 2], cfg


@pytest.mark.slow   # two descents (~3-6 s)
def test_end_phase_equals_the_per_step_records_counted_by_hand(small_run):
    """Mutation tried: the last vision update taken from lm_updated fails (this test and the
    next)."""
    d, z, cfg = small_run
    margin = float(cfg.filter.update_altitude_margin_m)
    got = end_phase(d, z, margin)
    t = d.t
    last_lm, last_vis, below1, belowm, lowest = [], [], 0, 0, math.inf
    for run in range(d.n_runs):
        lm = [t[k] for k in range(len(t)) if d.lm_updated[run][k]]
        vis = [k for k in range(len(t)) if d.updated[run][k]]
        last_lm.append(lm[-1])
        last_vis.append(t[vis[-1]])
        below1 += any(z[k] < 1.0 for k in vis)
        belowm += any(z[k] < margin for k in vis)
        lowest = min([lowest] + [z[k] for k in vis])
    assert got.n_runs == 2
    assert got.last_lm_t_s_median == pytest.approx(np.median(last_lm))
    assert got.last_vis_t_s_median == pytest.approx(np.median(last_vis))
    assert (got.last_lm_t_s_min, got.last_lm_t_s_max) == (min(last_lm), max(last_lm))
    assert got.vision_after_last_lm_s_median == pytest.approx(np.median(np.subtract(last_vis, last_lm)))
    assert (got.runs_vision_below_ground_m, got.runs_vision_below_margin) == (below1, belowm)
    assert got.min_true_alt_vision_m == pytest.approx(lowest)
    assert got.last_vis_t_s_median >= got.last_lm_t_s_median


def _rec(updated, lm_updated, t):
    from opnav.landing.records import MonteCarlo

    return MonteCarlo(t=np.asarray(t, float), updated=np.asarray(updated, bool),
                      lm_updated=np.asarray(lm_updated, bool))


def test_end_phase_on_hand_made_records_and_its_sentences():
    """Known answer: run 0 updates vision until t = 4 (true altitude 0.5 m) with landmarks until
    t = 2; run 1 stops everything at t = 3 (altitude 3 m). Sentences quote those numbers."""
    t = np.arange(5.0)
    z = np.array([10.0, 8.0, 6.0, 3.0, 0.5])
    d = _rec([[1, 1, 1, 1, 1], [1, 1, 1, 1, 0]], [[1, 1, 1, 0, 0], [1, 1, 1, 1, 0]], t)
    e = end_phase(d, z, margin_m=5.0)
    assert (e.last_lm_t_s_min, e.last_lm_t_s_max, e.last_vis_t_s_max) == (2.0, 3.0, 4.0)
    assert e.vision_after_last_lm_s_median == pytest.approx(1.0)   # (2 + 0) / 2
    assert (e.runs_vision_below_ground_m, e.runs_vision_below_margin) == (1, 2)
    assert e.min_true_alt_vision_m == 0.5
    txt = end_phase_text({"depth": dataclasses.asdict(e)}, "site-tilt", 3.0)
    assert "1 take vision updates with the true altitude below 1 m" in txt and "2 below 5 m" in txt
    none = end_phase(_rec([[1, 1, 0, 0, 0]], [[1, 0, 0, 0, 0]], t), z, 5.0)
    assert "no run of 1 takes a vision update" in end_phase_text({"depth": dataclasses.asdict(none)}, "interior", 3.0)


def test_nees_reading_names_under_and_overconfidence():
    from opnav.landing.montecarlo import NeesConsistency

    def nees(pos_mean, vel_mean):
        return NeesConsistency(n_runs=300, level=0.95, band=(2.73, 3.28), pos_in_band_pct=13.6, pos_mean=pos_mean,
                               pos_median=pos_mean, vel_in_band_pct=2.0, vel_mean=vel_mean, vel_median=vel_mean)

    r = nees_reading(nees(1.76, 1.93))
    assert r.verdict == "underconfident" and "underconfident" in r.text and "1.76" in r.text
    assert nees_reading(nees(3.0, 3.5)).verdict == \
        "consistent in position, overconfident in velocity"
