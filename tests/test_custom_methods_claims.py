"""A user's own planning method in the claims engine's evidence table (issue 58): its rows carry
role ``beyond`` and change no verdict (docs/claims-engine.md, "Adding a method without a verdict").
The summaries are test_claims' hand-made ones, with a method 'mine' added to every section a
B-summary holds for a method, its numbers far from the others'."""

from __future__ import annotations

import copy

import test_claims as T

from opnav.report import landing_claims as B

OWN = "mine"


def _with_own(sb: dict, diff: float = -5.0) -> dict:
    """``sb`` (a B-summary) with OWN compared against SVD and depth (landing.methods.compare_own's
    sections, merged as landing.own.with_own merges them), in the error and envelope blocks, all of it
    much better than depth."""
    sb = copy.deepcopy(sb)
    for s in sb["scenarios"].values():
        q = ("lastlm_pos_err_m", "lmrms_pos_err_m")
        own = {}
        for ref in ("svd", "depth"):
            own[ref] = {"reference": ref, "alpha": 0.05,
                        "metrics": {q[0]: {"means": {ref: 0.4, OWN: 0.01}}, q[1]: {"means": {ref: 2.0, OWN: 0.05}}},
                        "methods": {OWN: {q[0]: T._iv(diff, 0.001), q[1]: T._iv(diff, 0.001), "same_pick_pct": 1.0}}}
        by_base = dict(s["equivalence_vs_baselines"])
        for b, sec in own.items():      # a baseline's existing section gains the own methods
            by_base[b] = {**by_base[b], "methods": {**by_base[b]["methods"], **sec["methods"]}} if b in by_base else sec
        s["equivalence_vs_baselines"] = by_base
        s["methods"][OWN] = {"rms_vel_err_mps_3sigma": 0.01, "rms_att_err_deg_3sigma": 0.01}
        s["errors"][OWN] = {"lastlm_pos_err_m": {"3sigma": 0.01}, "lmrms_pos_err_m": {"3sigma": 0.02}}
    return sb


def test_an_own_methods_rows_are_beyond_and_change_no_verdict():
    base, _, _ = T.built()
    sb = _with_own(T.summary_b())
    rows, ev, _ = T.built(sb=sb)
    mine = [r for r in ev if r.method == OWN]
    assert mine and {r.role for r in mine} == {"beyond"}
    assert {r.versus for r in mine if r.quantity.startswith("err_diff")} == {"svd", "depth"}
    assert any(r.claim_id for r in mine), "keyed to the claims that read their quantity"
    assert {c: r.verdict for c, r in rows.items()} == {c: r.verdict for c, r in base.items()}
    # the depth rows of the SVD section are untouched by the merge
    depth = [r for r in ev if r.method == "depth" and r.versus == "svd" and r.quantity.startswith("err_diff")]
    assert depth and all(abs(r.estimate) < 1.0 for r in depth)


def test_the_test_has_teeth_an_own_method_given_a_judged_role_moves_a_verdict(monkeypatch):
    """Mutation: the same rows with role as_written (what an amendment adding it to a claim's units
    would judge) change at least one verdict."""
    base, _, _ = T.built()
    real = B.roles
    monkeypatch.setattr(B, "roles", lambda plan: {**real(plan), OWN: "as_written", "depth": "compared"})
    rows, _, _ = T.built(sb=_with_own(T.summary_b(), diff=+5.0))
    assert {c: r.verdict for c, r in rows.items()} != {c: r.verdict for c, r in base.items()}
