"""Tables the manuscript's text sets where a sentence would repeat itself for every method,
baseline or variant (issue 55 item 4: one sentence per pair made one run-on paragraph).

Each table is a LaTeX macro holding a booktabs tabular (rule paper_macros writes them to
``results/paper/tables.tex``; the sections place them in a float with \\R{Name}). The numbers
come from the papers' summaries; nothing here judges a claim (the claims table does).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from opnav.core import wording
from opnav.report.manuscript import latex_escape

#: how the text names a planner
METHOD_WORDS = {"depth": "depth", "svd": "SVD", "gdop": "GDOP", "cond": "condition number", "random": "random",
                "center": "most central", "closest": "closest"}
#: the paired errors the equivalence test reads (paper B's B-C1), as the table's column heads
EQ_METRICS = (("lastlm_pos_err_m", "last landmark update"), ("lmrms_pos_err_m", "landmark-phase RMS"))


def _name(m: str) -> str:
    return METHOD_WORDS.get(m, m)


def _interval(r: Mapping[str, Any]) -> str:
    vals = [r.get(k) for k in ("mean", "lo", "hi")]
    if any(v is None or not math.isfinite(float(v)) for v in vals):
        return "n/a"
    m, lo, hi = (float(v) for v in vals)
    return f"{wording.num(m)} [{wording.num(lo)}, {wording.num(hi)}]"


def equivalence_rows(summary: Mapping[str, Any]) -> list[dict[str, str]]:
    """The paired equivalence tests of paper B's headline camera (``B-summary.json``): depth
    against each baseline (SVD from ``equivalence``, the others from ``equivalence_vs_baselines``),
    then the negative controls against SVD. Each error's cell holds the paired mean difference
    (m), its interval (the level in the first column's head) and the margin; then the same-pick
    rate (%) and whether the pair is equivalent."""
    out = []
    eq = summary.get("equivalence") or {}
    others = summary.get("equivalence_vs_baselines") or {}
    order = [b for b in METHOD_WORDS if b in others] + sorted(b for b in others if b not in METHOD_WORDS)
    sections = [(eq, ("depth",), "compared")] + [(others[b], ("depth",), "compared") for b in order
                                                 if b != eq.get("reference")]
    sections.append((eq, tuple(m for m in (eq.get("methods") or {}) if m != "depth"), "control"))
    levels = [x.get("level") for sec, _, _ in sections for r in (sec.get("methods") or {}).values()
              for q, _ in EQ_METRICS for x in [r.get(q) or {}] if x.get("level") is not None]
    first = f"pair ({100 * float(levels[0]):.0f} % intervals)" if levels else "pair"
    for sec, methods, role in sections:
        ref = sec.get("reference", "")
        for m in methods:
            r = (sec.get("methods") or {}).get(m)
            if not r:
                continue
            row = {first: f"{_name(m)} minus {_name(ref)}" + (" (control)" if role == "control" else ""),
                   "role": role}
            for q, head in EQ_METRICS:
                x = r.get(q) or {}
                margin = "" if x.get("margin") is None else f" +-{wording.num(x['margin'])}"
                row[f"{head} (m)"] = _interval(x) + margin
            sp = r.get("same_pick_pct")
            row["same pick (%)"] = "n/a" if sp is None or not math.isfinite(float(sp)) else f"{float(sp):.0f}"
            row["equivalent"] = "yes" if r.get("equivalent") else "no"
            out.append(row)
    return out


def tabular(rows: list[Mapping[str, str]], right: tuple[str, ...] = ()) -> str:
    """A booktabs tabular of ``rows`` (their keys as heads, wrapped onto two lines where long);
    columns named in ``right`` are set flush right. Empty when there is no row."""
    if not rows:
        return ""
    cols = [c for c in rows[0] if c != "role"]   # the role groups the rows (a rule between groups), no column

    def head(c: str) -> str:
        words = c.split()
        if len(c) <= 22 or len(words) < 2:
            return latex_escape(c)
        k = max(1, len(words) // 2)
        return (r"\begin{tabular}[b]{@{}l@{}}" + latex_escape(" ".join(words[:k])) + r" \\ "
                + latex_escape(" ".join(words[k:])) + r"\end{tabular}")

    def cell(x: str) -> str:
        return latex_escape(str(x)).replace(r"+-", r"$\pm$")

    spec = "".join("r" if c in right else "l" for c in cols)
    lines = [rf"\begin{{tabular}}{{@{{}}{spec}@{{}}}}", r"\toprule", " & ".join(head(c) for c in cols) + r" \\",
             r"\midrule"]
    prev_role = None
    for r in rows:
        if "role" in r and prev_role is not None and r["role"] != prev_role:
            lines.append(r"\midrule")
        prev_role = r.get("role")
        lines.append(" & ".join(cell(r[c]) for c in cols) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines)


# ------------------------------------------------------------ paper A
#: the EM schemes a variant's key adds to the paper's (plain EM on sliding windows)
def _base_variants(summary: Mapping[str, Any]) -> list[str]:
    """Paper A's variants under the paper's EM scheme (plain EM, sliding windows): the keys
    of A-summary.json's ``variants`` without an added scheme (``roll``, not ``roll+squarem``)."""
    return [k for k in (summary.get("variants") or {}) if "+" not in k]


def _km(x: Any) -> str:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return "n/a"
    return wording.num(v) if math.isfinite(v) else "n/a"


def nav_rows(summary: Mapping[str, Any]) -> list[dict[str, str]]:
    """Paper A, headline case, per variant under the paper's scheme: the navigation error (RMS over
    the arc's last part, km) before and after compensation, after it split across (lateral) and
    along (range) the line of sight, and the filter given the true misalignment (a floor)."""
    out = []
    for k in _base_variants(summary):
        v = summary["variants"][k]
        if v.get("nav_err_after_km") is None:
            continue
        out.append({"variant": k, "before (km)": _km(v.get("nav_err_before_km")),
                    "after (km)": _km(v.get("nav_err_after_km")), "after, lateral": _km(v.get("nav_err_after_lat_km")),
                    "after, range": _km(v.get("nav_err_after_rng_km")),
                    "true θ (km)": _km(v.get("nav_err_true_theta_km")),
                    "true θ, lateral": _km(v.get("nav_err_true_theta_lat_km")),
                    "true θ, range": _km(v.get("nav_err_true_theta_rng_km"))})
    return out


def _side(d: Any, se: Any) -> str:
    """A filter's NEES against the reference's: above (optimistic), below (conservative) or
    indistinguishable, by its paired seed mean against two standard errors."""
    try:
        d, se = float(d), float(se)
    except (TypeError, ValueError):
        return "not judged"
    if not (math.isfinite(d) and math.isfinite(se)):
        return "not judged"
    return "above" if d > 2 * se else "below" if d < -2 * se else "same"


def nees_rows(summary: Mapping[str, Any]) -> list[dict[str, str]]:
    """Paper A, headline case: the position NEES (mean over the arc and the seeds, initial error
    drawn from the prior) of each compensated filter beside the filter given the true misalignment
    on the same runs (the reference: the truth has no process noise, so it is not 3), for the
    paper's scheme of every variant and the navigation floor's row; 'above' / 'below' when the
    paired seed mean lies more than two standard errors from the reference."""
    nees = summary.get("nees") or {}
    keys = _base_variants(summary)
    nf = (summary.get("nav_floor_by_arc") or {}).get("variant")
    if nf and nf not in keys:
        keys.append(nf)
    out = []
    for k in keys:
        v = nees.get(k)
        if not v or v.get("nees_mean") is None:
            continue
        out.append({"variant": k, "as exact": _km(v.get("nees_mean")),
                    "as exact vs reference": _side(v.get("after_minus_reference_mean"), v.get("after_minus_reference_se")),
                    "Schmidt": _km(v.get("consider_nees_mean")),
                    "Schmidt vs reference": _side(v.get("consider_minus_reference_mean"),
                                                  v.get("consider_minus_reference_se")),
                    "reference (true θ)": _km(v.get("reference_nees_mean")),
                    "seeds": str(v.get("n_seeds", "n/a"))})
    return out


def convergence_rows(summary: Mapping[str, Any]) -> list[dict[str, str]]:
    """Paper A, one window of the convergence study: the EM maps plain EM and SQUAREM need to
    come within the tolerance of the maximum-likelihood estimate, per variant (paper's scheme);
    beyond the maps run, the count extrapolated from the measured contraction rate."""
    mx = summary.get("convergence_max_maps")
    out = []
    for k in _base_variants(summary):
        v = summary["variants"][k]
        mp, ex, sq = (v.get("iterations_plain_median"), v.get("iterations_plain_extrapolated_median"),
                      v.get("iterations_squarem_median"))
        if mp is None:
            continue
        plain = (f"more than {mx} (about {wording.num(ex)})" if mx is not None and float(mp) > float(mx)
                 else wording.num(mp))
        out.append({"variant": k, "plain EM (maps)": plain, "SQUAREM (maps)": wording.num(sq)})
    return out


def mars_attitude_rows(summary: Mapping[str, Any]) -> list[dict[str, str]]:
    """Paper A: the bound of (tx, ty) after all the data (arcsec) per variant at the default
    attitude knowledge of each Mars image and at each studied value (1-sigma per axis)."""
    ma = summary.get("mars_attitude") or {}
    rows = ma.get("bound_all_arcsec") or {}
    vals = [f"{float(a):g}" for a in ma.get("values_arcsec", [])]
    d0 = ma.get("default_arcsec")
    heads = [("default", f"{float(d0):g} arcsec (default)" if d0 is not None else "default")] + [
        (v, f"{v} arcsec") for v in vals]
    return [{"variant": k, **{h: _km(r.get(key)) for key, h in heads}} for k, r in rows.items()]


def table_macros(summaries: Mapping[str, Mapping[str, Any]]) -> dict[str, str]:
    """``{macro name: tabular}`` for every table the summaries can fill (``summaries``: by key,
    as rule paper_macros reads them: ``B`` is B-summary.json)."""
    out = {}
    a = summaries.get("A")
    if a:
        for name, rows in (("ANavTable", nav_rows(a)), ("ANeesTable", nees_rows(a)),
                           ("AConvergenceTable", convergence_rows(a)), ("AMarsAttitudeTable", mars_attitude_rows(a))):
            if rows:
                out[name] = tabular(rows, right=tuple(c for c in rows[0] if c != "variant"))
    b = summaries.get("B")
    if b:
        rows = equivalence_rows(b)
        if rows:
            out["BEquivalenceTable"] = tabular(rows, right=tuple(k for k in rows[0] if "same pick" in k))
    return out


def render(tables: Mapping[str, str]) -> str:
    """The tables as ``\\newcommand`` lines (sorted by name), for ``results/paper/tables.tex``."""
    lines = ["% Generated by rule paper_macros (opnav.report.text_tables); do not edit."]
    lines += [f"\\newcommand{{\\{k}}}{{{v}}}" for k, v in sorted(tables.items())]
    return "\n".join(lines) + "\n"
