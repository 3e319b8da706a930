"""Paper A's evidence (EM-EKF camera misalignment): every number A-T1 and A-summary.json hold
that a claim may read, as :class:`opnav.report.evidence.EvidenceRow` rows, with no verdict logic.

:func:`evidence_rows` reads one sample's A-T1 table (one row per Table-1 case x variant x EM
scheme: ``scope`` the case id, ``method`` the variant label) and A-summary.json, and writes per
row:

* ``rms_err_arcsec``: RMS error of the estimate about the truth over the seeds, the larger of
  theta_x and theta_y (se about rms / sqrt(2 n)), arcsec;
* ``crlb_arcsec`` / ``crlb_q0_arcsec`` (role ``bound``): the bound of the data the estimate used,
  larger axis (with Q = 0), arcsec;
* ``converged_label`` (1: the row's label reads converged) and ``converged_seeds_frac``;
* ``data_to_converge_samples`` and ``data_beyond_first_window_samples`` (the count less the
  first window of the row's scheme: at or below 0 the count only restates the window);
* ``nav_err_before_km`` / ``nav_err_after_km`` (mean over seeds, se from their sd) and
  ``nav_err_true_theta_km`` (role ``bound``: the filter given the true theta, a floor);
* ``tz_observable`` (1: the M-step finds tz observable); ``nees_pos_*`` (evidence only);

and from A-summary.json the bound after the published data against the roll rate
(``crlb_published_data_arcsec``, ``setting roll_rate_deg_s=...``), the navigation error against
the arc length (``nav_err_after_km``, ``nav_err_true_theta_km``, ``setting arc_s=...``), the tz
effect on navigation (``nav_err_tz_ratio``), the installation flag
(``installation_by_construction``) and the NEES comparison. :func:`published_rows` writes
published.yaml's paper-A values the claims quote (role ``published``).

Roles from the variant label: ``literal`` as written, ``reference-start...`` diagnostic,
``stars...`` beyond, every other label faithful (it adds something the paper does not state).
Units: arcsec, km, samples.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import pandas as pd

from opnav.approach.summaries import AS_WRITTEN
from opnav.report.evidence import NAN, EvidenceRow, quantity, rms_se
from opnav.report.plan import Plan

DIAGNOSTIC = "reference-start"
BEYOND = ("stars",)
HEADLINE_CASE = "T1-01"

quantity("rms_err_arcsec", "arcsec", "rms", "RMS error")
quantity("crlb_arcsec", "arcsec", "none", "bound of the data used")
quantity("crlb_q0_arcsec", "arcsec", "none", "bound of the data used with Q = 0")
quantity("crlb_published_data_arcsec", "arcsec", "none", "bound after the published data")
quantity("converged_label", "", "none", "converged label")
quantity("converged_seeds_frac", "", "none", "share of seeds converged")
quantity("data_to_converge_samples", "samples", "none", "data to converge")
quantity("data_beyond_first_window_samples", "samples", "none", "data to converge beyond the first window")
quantity("nav_err_before_km", "km", "mean", "navigation error before compensation")
quantity("nav_err_after_km", "km", "mean", "navigation error after compensation")
quantity("nav_err_true_theta_km", "km", "none", "navigation error with the true theta")
quantity("tz_observable", "", "none", "tz observable")
quantity("nav_err_tz_ratio", "", "none", "navigation error with tz over without")
quantity("installation_by_construction", "", "none", "installation cases identical by construction")
quantity("nees_pos_after_mean", "", "none", "position NEES compensated")
quantity("nees_pos_consider_mean", "", "none", "position NEES of the consider filter")
quantity("nees_pos_true_theta_mean", "", "none", "position NEES with the true theta")
quantity("nees_mean", "", "none", "position NEES")
quantity("reference_nees_mean", "", "none", "position NEES of the true-theta filter")
for _q, _t in (("accuracy_claim_arcsec", "claimed accuracy"), ("est_error_x_arcsec", "published error in theta_x"),
               ("est_error_y_arcsec", "published error in theta_y"), ("est_error_arcsec", "published error"),
               ("intro_nav_err_km", "introduction's navigation error"),
               ("intro_misalignment_arcsec", "introduction's misalignment")):
    quantity(_q, "km" if _q.endswith("_km") else "arcsec", "none", _t)


def role_of(label: str) -> str:
    """The role of a variant label (module docstring)."""
    head = label.split("+")[0]
    if label == AS_WRITTEN:
        return "as_written"
    if head == DIAGNOSTIC:
        return "diagnostic"
    if head in BEYOND:
        return "beyond"
    return "faithful"


def _f(x: Any) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return NAN


def _truthy(x: Any) -> bool:
    return x if isinstance(x, bool) else str(x).strip().lower() in ("true", "1", "1.0")


def _label(r) -> str:
    lab = r.get("label")
    if isinstance(lab, str) and lab:
        return lab
    return "stalled" if _truthy(r.get("stalled")) else "converged"


def _converged_seeds(r) -> int:
    c = r.get("converged_seeds")
    if c is not None and not pd.isna(c):
        return int(c)
    return int(r["n_seeds"]) - int(r.get("stalled_seeds", 0) or 0)


def evidence_rows(t1: pd.DataFrame, summary: Mapping[str, Any] | None, sample: str, source_t1: str,
                  source_summary: str = "", windows: Mapping[str, float] | None = None) -> list[EvidenceRow]:
    """Every evidence row of one sample's A-T1 (``t1``) and A-summary.json (``summary``);
    ``windows``: the first window (samples) of each EM mode (sliding: N, growing: its N)."""
    rows: dict[tuple, EvidenceRow] = {}
    windows = dict(windows or {})

    def add(scope, method, q, est, *, n=0, se=NAN, role=None, src=source_t1, where="", setting="", unit=None,
            lo=NAN, hi=NAN, level=NAN):
        from opnav.report.evidence import QUANTITIES

        key = (scope, method, q, setting)
        if key in rows:
            return
        rows[key] = EvidenceRow(claim_id="", sample=sample, scope=scope, method=method, versus="",
                                role=role or role_of(method), quantity=q, estimate=_f(est), lo=_f(lo), hi=_f(hi),
                                level=_f(level), n=int(n or 0), unit=QUANTITIES[q].unit if unit is None else unit,
                                source=f"{src}#{where}" if where else src, se=_f(se), setting=setting)

    for _, r in t1.iterrows():
        v, case, n = str(r["variant"]), str(r["case_id"]), int(r["n_seeds"])
        w = f"variant={v},case_id={case}"
        rms = max(_f(r["rmse_x_arcsec"]), _f(r["rmse_y_arcsec"]))
        add(case, v, "rms_err_arcsec", rms, n=n, se=rms_se(rms, n), where=f"{w}:rmse_x/y_arcsec")
        add(case, v, "crlb_arcsec", max(_f(r["crlb_x_arcsec"]), _f(r["crlb_y_arcsec"])), n=n, role="bound",
            where=f"{w}:crlb_x/y_arcsec")
        if "crlb_q0_x_arcsec" in r and not pd.isna(r["crlb_q0_x_arcsec"]):
            add(case, v, "crlb_q0_arcsec", max(_f(r["crlb_q0_x_arcsec"]), _f(r["crlb_q0_y_arcsec"])), n=n,
                role="bound", where=f"{w}:crlb_q0_x/y_arcsec")
        add(case, v, "converged_label", 1.0 if _label(r) == "converged" else 0.0, n=n, where=f"{w}:label")
        add(case, v, "converged_seeds_frac", _converged_seeds(r) / n if n else NAN, n=n, where=f"{w}:converged_seeds")
        dd = _f(r.get("data_to_converge_samples"))
        add(case, v, "data_to_converge_samples", dd, n=_converged_seeds(r), where=f"{w}:data_to_converge_samples")
        mode = r.get("mode") if isinstance(r.get("mode"), str) and r.get("mode") else "sliding"
        first = _f(windows.get(mode, windows.get("sliding", NAN)))
        if math.isfinite(first):
            add(case, v, "data_beyond_first_window_samples", dd - first, n=_converged_seeds(r),
                where=f"{w}:data_to_converge_samples - first window {first:g} ({mode})")
        for q in ("nav_err_before_km", "nav_err_after_km"):
            sd = _f(r.get(f"{q}_std"))
            add(case, v, q, r[q], n=n, se=sd / math.sqrt(n) if n else NAN, where=f"{w}:{q}")
        if "nav_err_true_theta_km" in r and not pd.isna(r["nav_err_true_theta_km"]):
            add(case, v, "nav_err_true_theta_km", r["nav_err_true_theta_km"], n=n, role="bound",
                where=f"{w}:nav_err_true_theta_km")
        add(case, v, "tz_observable", 1.0 if _truthy(r["tz_observable"]) else 0.0, n=n, where=f"{w}:tz_observable")
        for q in ("nees_pos_after_mean", "nees_pos_consider_mean", "nees_pos_true_theta_mean"):
            if q in r and not pd.isna(r[q]):
                add(case, v, q, r[q], n=n, where=f"{w}:{q}")
    s = summary or {}
    src = source_summary
    rb = s.get("roll_rate_bound")
    rr = s.get("roll_rate") or {}
    if rb:
        pairs, where = zip(rb.get("rate_deg_s") or [], rb.get("bound_arcsec") or []), "roll_rate_bound"
    else:
        pairs, where = zip(rr.get("rates_deg_s") or [], rr.get("bound_at_samples_arcsec") or []), \
            "roll_rate.bound_at_samples_arcsec"
    for rate, b in pairs:
        add(HEADLINE_CASE, "roll", "crlb_published_data_arcsec", b, role="faithful", src=src, where=where,
            setting=f"roll_rate_deg_s={_f(rate):g}")
    nf = s.get("nav_floor_by_arc") or {}
    for row in nf.get("rows") or []:
        arc, v, n = _f(row.get("arc_s")), str(row.get("variant", AS_WRITTEN)), int(row.get("n_seeds") or 0)
        for rule, suffix in (("", "rule"), (";rule=last", "last")):
            st = f"arc_s={arc:g}{rule}"
            sd = _f(row.get(f"nav_err_km_{suffix}_sd"))
            add(HEADLINE_CASE, v, "nav_err_after_km", row.get(f"nav_err_km_{suffix}"), n=n, src=src, setting=st,
                se=sd / math.sqrt(n) if n else NAN,
                where=f"nav_floor_by_arc.rows(arc_s={arc:g},variant={v}).nav_err_km_{suffix}")
            add(HEADLINE_CASE, v, "nav_err_true_theta_km", row.get(f"true_theta_km_{suffix}"), n=n, role="bound",
                src=src, setting=st, where=f"nav_floor_by_arc.rows(arc_s={arc:g},variant={v}).true_theta_km_{suffix}")
    tz = s.get("tz_nav_effect") or {}
    on, off = _f(tz.get("nav_err_km_tz_on")), _f(tz.get("nav_err_km_tz_off"))
    if math.isfinite(on) and math.isfinite(off) and off > 0:
        add(HEADLINE_CASE, str(tz.get("variant", AS_WRITTEN)), "nav_err_tz_ratio", on / off,
            n=int(tz.get("n_seeds") or 0), src=src, where="tz_nav_effect.nav_err_km_tz_on / nav_err_km_tz_off")
    inst = s.get("installation") or {}
    if "by_construction" in inst:
        add("", AS_WRITTEN, "installation_by_construction", 1.0 if inst["by_construction"] else 0.0, src=src,
            where="installation.by_construction")
    for v, ne in (s.get("nees") or {}).items():
        if not isinstance(ne, Mapping):
            continue
        for q in ("nees_mean", "reference_nees_mean"):
            if ne.get(q) is not None:
                add(HEADLINE_CASE, str(v), q, ne[q], n=int(ne.get("n_seeds") or 0), src=src, where=f"nees.{v}.{q}")
    return list(rows.values())


def published_rows(pub: Mapping[str, Any], source: str = "published.yaml") -> list[EvidenceRow]:
    """Paper A's published values the claims quote (role published): per Table-1 case the data
    to converge, the navigation errors and the estimate's error; the headline's claims."""
    out = []

    def add(scope, q, v, where):
        from opnav.report.evidence import QUANTITIES

        out.append(EvidenceRow(claim_id="", sample="main", scope=scope, method="", versus="", role="published",
                               quantity=q, estimate=float(v), unit=QUANTITIES[q].unit,
                               source=f"{source}#paper_a.{where}"))

    head = pub["headline"]
    for row in pub["table1"]:
        cid = row["case_id"]
        for q in ("data_to_converge_samples", "nav_err_before_km", "nav_err_after_km"):
            add(cid, q, row[q], f"table1({cid}).{q}")
        tr = row.get("bias_arcsec") or head["truth_arcsec"]
        add(cid, "est_error_arcsec", max(abs(row["est_x_arcsec"] - tr[0]), abs(row["est_y_arcsec"] - tr[1])),
            f"table1({cid}).est_x/y_arcsec - truth")
    add("", "accuracy_claim_arcsec", head["accuracy_claim_arcsec"], "headline.accuracy_claim_arcsec")
    add("", "est_error_x_arcsec", head["est_error_arcsec"][0], "headline.est_error_arcsec[0]")
    add("", "est_error_y_arcsec", head["est_error_arcsec"][1], "headline.est_error_arcsec[1]")
    add("", "intro_nav_err_km", head["intro_nav_err_km"], "headline.intro_nav_err_km")
    add("", "intro_misalignment_arcsec", head["intro_misalignment_arcsec"], "headline.intro_misalignment_arcsec")
    return out


def input_rows(pub: Mapping[str, Any], plan: Plan, dt_s: float) -> list[dict]:
    """Paper A's derived inputs (inputs.csv): the sample time, which the paper states as
    0.5 s while its '250 samples, about 4 min' implies about 1 s."""
    head, sim = pub["headline"], pub["simulation"]
    n, mins = float(head["data_to_converge_samples"]), float(head["data_to_converge_minutes"])
    implied = 60.0 * mins / n
    how = ((plan.raw.get("inputs") or {}).get("sample_time") or {}).get("how_derived", "")
    return [{"input": "A sample time", "ours": f"{dt_s:g} s",
             "published": f"{float(sim['dt_s']):g} s (sec. 3); {n:g} samples = about {mins:g} min implies {implied:.2g} s",
             "how_derived": how,
             "what_would_match": f"a {implied:.2g} s step makes {n:g} samples {mins:g} min; ours makes them "
                                 f"{n * dt_s / 60.0:.2g} min"}]


#: the claims the abstract quotes with their cause
HEADLINE_IDS = ("A-C1",)
