"""Paper A's scorecard rows (scored by :mod:`opnav.report.scorecard`): A-T1 cell by cell
against its published columns, and the headline claims against A-summary.json.

The absolute floors :data:`ABS_TOL_A` are for values published with few digits (arcsec to
half a unit). Units: arcsec, km, samples.
"""

from __future__ import annotations

import math

import pandas as pd

from opnav.approach.summaries import HeadlineSummary
from opnav.report.approach.text import nav_note
from opnav.core.verdicts import NOT_REPRODUCED, NOT_REPRODUCIBLE, REPRODUCED

#: floors for values published with few digits (module docstring)
ABS_TOL_A = {"arcsec": 0.5, "samples": 0.0, "km": 0.0}


def _unit_of(col: str) -> str:
    if col.startswith(("est_", "truth_", "crlb_")) or col.endswith("_arcsec"):
        return "arcsec"
    if "samples" in col or "converge" in col:
        return "samples"
    if col.endswith("_km"):
        return "km"
    return ""


def rows_paper_a(table1: pd.DataFrame, summary: HeadlineSummary, pub: dict) -> list[dict]:
    """Scorecard rows for paper A, cell by cell from A-T1's ``pub_*`` columns.

    For a published column ``pub_<name>``, our value is ``<name>_mean`` (or
    ``<name>``) and our spread ``<name>_std`` where present. Bias estimates
    (``est_x``/``est_y``) carry the truth and the CRLB of the row's variant so
    the verdict can say when the published accuracy is below the bound. ``summary``: the
    headline rows of A-summary.json (:meth:`HeadlineSummary.from_json`).
    """
    if not isinstance(summary, HeadlineSummary):
        raise TypeError(f"approach_scorecard.rows_paper_a: summary must be a HeadlineSummary "
                        f"(HeadlineSummary.from_json(<A-summary.json>)), got {type(summary).__name__}")
    rows: list[dict] = []
    pub_cols = [c for c in table1.columns if c.startswith("pub_")]
    for _, r in table1.iterrows():
        for pc in pub_cols:
            pv = r[pc]
            if pd.isna(pv) or not isinstance(pv, (int, float)):
                continue
            name = pc[len("pub_"):]
            base = name.removesuffix("_mean")
            ours_col = next((c for c in (f"{base}_mean", base) if c in table1.columns), None)
            if ours_col is None:
                continue
            axis = base.split("_")[1] if base.startswith("est_") else None
            unit = _unit_of(base)
            row = {
                "paper": "A",
                "item": f"T1 {r.get('variant', '')} {r.get('case_id', '')}: {base}",
                "published": float(pv),
                "ours": float(r[ours_col]),
                "spread": float(r[f"{base}_std"]) if f"{base}_std" in table1.columns else float("nan"),
                "unit": unit,
                "abs_tol": ABS_TOL_A.get(unit, 0.0),
            }
            if axis and f"truth_{axis}_arcsec" in table1.columns and f"crlb_{axis}_arcsec" in table1.columns:
                row["truth"] = float(r[f"truth_{axis}_arcsec"])
                row["crlb"] = float(r[f"crlb_{axis}_arcsec"])  # the bound of the data the estimate used
            row["reason_note"] = ((f"; {nav_note(r)}" if base.startswith("nav_err_after") and nav_note(r) else "")
                                  if base.startswith("nav_err") else _reading_note(r))
            rows.append(row)
    rows += _rows_paper_a_headline(summary, pub.get("headline", {}))
    head = pub.get("headline", {})
    if "tz_estimable" in head and "tz_observable" in table1.columns:
        tz_obs = bool(table1["tz_observable"].astype(str).str.lower().eq("true").any())
        rows.append({"paper": "A", "item": "claim: tz (roll about the boresight) cannot be estimated",
                     "published": float("nan"), "ours": float("nan"), "unit": "",
                     "verdict": REPRODUCED if tz_obs == bool(head["tz_estimable"]) else NOT_REPRODUCED,
                     "reason": "A-T1: tz unobservable in every case and variant" if not tz_obs
                     else "A-T1: tz observable in some case"})
    return rows


def _reading_note(r) -> str:
    """Reason suffix of a scorecard row: the run's reading (A-T1 ``reading``: its convergence
    label from the ML estimate of the data it used and, when converged, whether that data's
    bound lets the estimate mean anything); '' for a row without one."""
    return _reading_text(r.get("reading"))


def _reading_text(reading) -> str:
    return f"; EM {reading}" if isinstance(reading, str) and reading else ""


def _rows_paper_a_headline(summary: HeadlineSummary, head: dict) -> list[dict]:
    """Paper A's headline claims (sec. 3, abstract) against each headline row of the summary."""
    rows: list[dict] = []
    truth = head.get("truth_arcsec", [float("nan")] * 3)
    target = float(head.get("accuracy_claim_arcsec", 2.0))
    for v in summary.rows:
        name = v.key
        err = math.hypot(v.est_x_mean - truth[0], v.est_y_mean - truth[1]) / math.sqrt(2)
        crlb = max(v.crlb_x_arcsec, v.crlb_y_arcsec)
        ok = abs(v.est_x_mean - truth[0]) <= target and abs(v.est_y_mean - truth[1]) <= target
        if ok:
            verdict, reason = REPRODUCED, f"both axes within {target:g} arcsec of the truth"
        elif crlb > target:
            verdict, reason = NOT_REPRODUCIBLE, f"CRLB {crlb:.3g} arcsec exceeds the claimed {target:g} arcsec"
        else:
            verdict, reason = NOT_REPRODUCED, f"RMS axis error {err:.3g} arcsec although the CRLB is {crlb:.3g}"
        rows.append({"paper": "A", "item": f"claim [{name}]: bias accuracy better than {target:g} arcsec",
                     "published": target, "ours": err, "unit": "arcsec", "verdict": verdict, "reason": reason,
                     "reason_note": _reading_text(v.reading)})
        if "nav_err_before_km_text" in head and v.nav_err_before_km is not None:
            # the summary holds no spread of the headline row's navigation error
            rows.append({"paper": "A", "item": f"claim [{name}]: nav. error before compensation (sec. 3 text)",
                         "published": float(head["nav_err_before_km_text"]), "ours": v.nav_err_before_km,
                         "spread": float("nan"), "unit": "km"})
        if "abstract_claim_km" in head and v.nav_err_after_km is not None:
            lim = float(head["abstract_claim_km"][1])
            after = v.nav_err_after_km
            rows.append({"paper": "A", "item": f"claim [{name}]: nav. error after compensation within {lim:g} km (abstract)",
                         "published": lim, "ours": after, "unit": "km",
                         "verdict": REPRODUCED if after <= lim else NOT_REPRODUCED,
                         "reason": f"ours {after:.3g} km {'<=' if after <= lim else '>'} {lim:g} km",
                         "reason_note": (f"; {v.nav_note}" if v.nav_note else "")})
    return rows
