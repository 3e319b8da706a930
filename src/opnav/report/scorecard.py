"""The reproduced-vs-published scorecard: every published number of both papers beside
ours, with the verdict of :mod:`opnav.core.verdicts` (its module docstring states the rule).
Each paper's rows come from its own module (:func:`opnav.report.approach_scorecard.rows_paper_a`,
:func:`opnav.report.landing.summary.rows_paper_b`); here they are scored and laid out.
"""

from __future__ import annotations

import pandas as pd

from opnav.core.verdicts import (  # noqa: F401
    K_SPREAD,
    MAX_BAND_REL,
    NOT_REPRODUCED,
    NOT_REPRODUCIBLE,
    REL_TOL,
    REPRODUCED,
    Verdict,
    judge,
    tolerance,
)

#: the caption of the scorecard table
CAPTION = "Scorecard: published values beside ours."


def score_rows(rows: list[dict]) -> pd.DataFrame:
    """Score a list of dicts with keys paper, item, published, ours, spread, unit
    (and optional truth, crlb, abs_tol, verdict/reason for pre-judged claims, and ``band``:
    the rel_tol / k_spread / max_band_rel of the row's claim in the analysis plan)."""
    out = []
    for r in rows:
        if "verdict" in r:
            v = Verdict(r["verdict"], r["reason"])
        else:
            v = judge(r["published"], r["ours"], r.get("spread"), r.get("abs_tol", 0.0),
                      r.get("truth"), r.get("crlb"), r.get("unit", ""), **(r.get("band") or {}))
        pub, ours = r.get("published"), r.get("ours")
        diff = (ours - pub) if isinstance(pub, (int, float)) and isinstance(ours, (int, float)) else float("nan")
        out.append({
            "paper": r["paper"],
            "item": r["item"],
            "unit": r.get("unit", ""),
            "published": pub,
            "ours (mean)": ours,
            "ours (spread)": r.get("spread", float("nan")),
            "difference": diff,
            "verdict": v.verdict,
            "reason": v.reason + r.get("reason_note", ""),
        })
    return pd.DataFrame(out, columns=SCORECARD_COLUMNS)


SCORECARD_COLUMNS = ["paper", "item", "unit", "published", "ours (mean)", "ours (spread)",
                     "difference", "verdict", "reason"]


def to_longtable(df: pd.DataFrame) -> str:
    """The scorecard as a LaTeX longtable (it spans pages in the manuscript)."""
    if df.empty:
        return "% scorecard: no published numbers compared yet\n"
    show = df.drop(columns=["difference"]).rename(columns={"ours (mean)": "ours", "ours (spread)": "spread"})
    tex = show.to_latex(index=False, longtable=True, escape=True, na_rep="--",
                        float_format=lambda x: f"{x:.4g}", column_format=LONGTABLE_COLUMNS)
    # long snake_case names may break after an underscore (else they overrun their column)
    return tex.replace(r"\_", r"\_\allowbreak{}")


def _wrap(width: str) -> str:
    return rf">{{\raggedright\arraybackslash}}p{{{width}\linewidth}}"


#: Longtable columns (paper, item, unit, published, ours, spread, verdict,
#: reason): the three text columns wrap within fixed shares of the line width,
#: so the table fits the page whatever the item names (with the manuscript's
#: 3 pt column separation: 0.55 of the width in text, 5 short columns beside).
LONGTABLE_COLUMNS = "l" + _wrap("0.22") + "lrrr" + _wrap("0.12") + _wrap("0.21")


def verdict_counts(df: pd.DataFrame) -> pd.DataFrame:
    """Number of items per paper and verdict (the scorecard at a glance)."""
    if df.empty:
        return pd.DataFrame(columns=["paper", REPRODUCED, NOT_REPRODUCED, NOT_REPRODUCIBLE, "total"])
    t = pd.crosstab(df["paper"], df["verdict"])
    for v in (REPRODUCED, NOT_REPRODUCED, NOT_REPRODUCIBLE):
        if v not in t.columns:
            t[v] = 0
    t = t[[REPRODUCED, NOT_REPRODUCED, NOT_REPRODUCIBLE]]
    t["total"] = t.sum(axis=1)
    return t.reset_index()


def headline(df: pd.DataFrame, case_id: str = "T1-01") -> pd.DataFrame:
    """The items a reader looks at first: paper A's headline case under every
    variant, and every paper-B item."""
    keep = (df["paper"] == "B") | df["item"].str.contains(f" {case_id}:", regex=False)
    return df.loc[keep, ["paper", "item", "unit", "published", "ours (mean)", "ours (spread)", "verdict"]]
