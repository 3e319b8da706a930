"""Page views of paper A's wide tables (A-T1, A-X1, A-X2, A-P1): the columns that fit a
page, with display labels; the CSVs keep every column. :data:`COMPACT_VIEWS` is read by
:mod:`opnav.report.manuscript`.
"""

from __future__ import annotations

from collections.abc import Iterable

import pandas as pd

from opnav.approach.alternatives_summary import MethodSummary
from opnav.report.approach.text import METHOD_LABELS
from opnav.core.tables import cell_num, cell_pm

#: the table captions of paper A's tables (their CSV/LaTeX/Markdown headers)
CAPTIONS = {
    "A-T1": ("A-T1: paper A Table 1 reproduced, mean and sd over Monte-Carlo seeds, with the CRLB of the data "
             "each estimate used (Q = 0 beside); pub_* = published. The EM label comes from the ML estimate of the "
             "data each run used (converged / stalled / not converged); a row is identifiable when that bound is "
             "at most the published accuracy."),
    "A-X1": "A-X1: CRLB of the misalignment per scenario variant beside the EM estimates and iterations.",
    "A-X2": ("A-X2: EM-EKF against the augmented EKF and batch ML (IPOPT) on the Table-1 cases; "
             "errors in arcsec (estimate minus truth), CRLB = Cramer-Rao bound, nav error in km, "
             "data needed in samples, run time in s per Monte-Carlo seed."),
}


COMPACT_COLUMNS = {
    "variant": "variant", "case_id": "case", "truth_x_arcsec": "truth x", "truth_y_arcsec": "truth y",
    "est_x_mean": "est x", "est_x_std": "sd x", "pub_est_x_mean": "pub x",
    "est_y_mean": "est y", "est_y_std": "sd y", "pub_est_y_mean": "pub y",
    "crlb_x_arcsec": "CRLB x (data used)", "crlb_q0_x_arcsec": "CRLB x Q=0", "label": "EM label",
    "identifiable": "identifiable", "dist_to_ml_arcsec": "to ML",
    "data_to_converge_samples": "conv", "pub_data_to_converge_samples": "pub conv",
    "nav_err_before_km": "before km", "pub_nav_err_before_km": "pub before",
    "nav_err_after_km": "after km", "pub_nav_err_after_km": "pub after",
}


def table1_compact(t1: pd.DataFrame) -> pd.DataFrame:
    """The Table-1 columns that fit a page (LaTeX/Markdown); the CSV keeps them all."""
    return t1[list(COMPACT_COLUMNS)].rename(columns=COMPACT_COLUMNS)


def x2_table(rows: Iterable[MethodSummary]) -> pd.DataFrame:
    """A-X2 table: per variant and method (:func:`opnav.approach.alternatives_summary.method_summaries`),
    the headline case (T1-01) and all-case aggregates, with the page's column names."""
    return pd.DataFrame([{
        "variant": r.variant, "method": METHOD_LABELS[r.method],
        "n_cases": r.n_cases, "n_seeds": r.n_seeds,
        "T1-01 err_x mean": r.head_err_x_mean_arcsec, "T1-01 err_x sd": r.head_err_x_sd_arcsec,
        "T1-01 err_y mean": r.head_err_y_mean_arcsec, "T1-01 err_y sd": r.head_err_y_sd_arcsec,
        "T1-01 CRLB_x": r.head_crlb_x_arcsec,  # of the data used
        "T1-01 CRLB_x Q=0": r.head_crlb_q0_x_arcsec,
        "T1-01 CRLB_x all data": r.head_crlb_all_x_arcsec,
        "T1-01 label": r.head_label,
        "RMSE_xy all cases": r.rmse_xy_all_arcsec,
        "median sd all cases": r.median_sd_all_arcsec,
        "median CRLB all cases": r.median_crlb_all_arcsec,
        "nav err after km (T1-01)": r.head_nav_err_after_km,
        "nav err after km (all)": r.nav_err_after_all_km,
        "data needed (T1-01)": r.head_data_to_converge_samples,
        "data needed (median)": r.median_data_to_converge_samples,
        "run time s/seed (T1-01)": r.head_runtime_s_per_seed,
    } for r in rows])


def _label_or(r, text: str) -> str:
    """``text`` (the data to converge) for a converged row, else its label with the seed count."""
    lab = r.get("label")
    if isinstance(lab, str) and lab and lab != "converged":
        k = r.get("stalled_seeds") if lab == "stalled" else r.get("n_seeds", 0) - r.get("converged_seeds", 0)
        return f"{lab} ({cell_num(k, '{:.0f}')}/{cell_num(r.get('n_seeds'), '{:.0f}')})"
    return text


def compact_a_t1(df: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """A-T1 for the page: one table per scenario variant, ours beside published.

    Estimates are mean ± standard deviation over the noise seeds (arcsec);
    navigation errors before / after compensation in km.
    """
    out = []
    for variant, g in df.groupby("variant", sort=False):
        rows = []
        for _, r in g.iterrows():
            rows.append({
                "group": r.get("group", ""),
                "case": r["case_id"],
                'truth x, y (")': f"{cell_num(r['truth_x_arcsec'], '{:g}')}, {cell_num(r['truth_y_arcsec'], '{:g}')}",
                'est. x (")': cell_pm(r["est_x_mean"], r.get("est_x_std")),
                'est. y (")': cell_pm(r["est_y_mean"], r.get("est_y_std")),
                'CRLB x, y, data used (")': f"{cell_num(r['crlb_x_arcsec'], '{:.3g}')}, {cell_num(r['crlb_y_arcsec'], '{:.3g}')}",
                'CRLB x Q = 0 (")': cell_num(r.get("crlb_q0_x_arcsec"), "{:.3g}"),
                "data (samples)": _label_or(r, cell_num(r["data_to_converge_samples"], "{:.0f}")),
                "identifiable": "yes" if str(r.get("identifiable")).lower() == "true" else "no",
                'to ML (")': cell_num(r.get("dist_to_ml_arcsec"), "{:.3g}"),
                "nav. before / after (km)": f"{cell_num(r['nav_err_before_km'], '{:.1f}')} / {cell_num(r['nav_err_after_km'], '{:.1f}')}",
                "after: lateral / range (km)": f"{cell_num(r.get('nav_err_after_lat_km'), '{:.1f}')} / {cell_num(r.get('nav_err_after_rng_km'), '{:.1f}')}",
                "true theta: total / range (km)": f"{cell_num(r.get('nav_err_true_theta_km'), '{:.1f}')} / {cell_num(r.get('nav_err_true_theta_rng_km'), '{:.1f}')}",
                'published est. x, y (")': f"{cell_num(r.get('pub_est_x_mean'), '{:g}')}, {cell_num(r.get('pub_est_y_mean'), '{:g}')}",
                "published data": cell_num(r.get("pub_data_to_converge_samples"), "{:.0f}"),
                "published nav. (km)": f"{cell_num(r.get('pub_nav_err_before_km'), '{:g}')} / {cell_num(r.get('pub_nav_err_after_km'), '{:g}')}",
            })
        out.append((str(variant), pd.DataFrame(rows)))
    return out


def compact_a_x1(df: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """A-X1 for the page: CRLB per variant beside the EM and ML estimates' RMS error."""
    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"],
            'CRLB x, 1 segment (")': cell_num(r.get("crlb_x_window_arcsec"), "{:.3g}"),
            'CRLB x, all data (")': cell_num(r.get("crlb_x_total_arcsec"), "{:.3g}"),
            'CRLB x, all data, Q = 0 (")': cell_num(r.get("crlb_q0_x_total_arcsec"), "{:.3g}"),
            "reaches 2\"": "yes" if bool(r.get("bound_reaches_target")) else "no",
            "EM plain label": r.get("em_plain_label") if isinstance(r.get("em_plain_label"), str) else "",
            'EM plain RMSE x (")': cell_num(r.get("em_plain_rmse_x_arcsec"), "{:.3g}"),
            'EM SQUAREM RMSE x (")': cell_num(r.get("em_squarem_rmse_x_arcsec"), "{:.3g}"),
            'ML RMSE x (")': cell_num(r.get("mle_rmse_x_arcsec"), "{:.3g}"),
            "EM maps plain / SQUAREM": f"{cell_num(r.get('maps_plain_median'), '{:.0f}')} / {cell_num(r.get('maps_squarem_median'), '{:.0f}')}",
        })
    return [("", pd.DataFrame(rows))]


def compact_a_x2(df: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """A-X2 for the page: EM-EKF vs augmented EKF vs batch ML, headline case and all cases."""
    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"], "method": r["method"],
            'T1-01 error x (")': cell_pm(r.get("T1-01 err_x mean"), r.get("T1-01 err_x sd")),
            'T1-01 error y (")': cell_pm(r.get("T1-01 err_y mean"), r.get("T1-01 err_y sd")),
            'CRLB x, data used (")': cell_num(r.get("T1-01 CRLB_x"), "{:.3g}"),
            'CRLB x, Q = 0 (")': cell_num(r.get("T1-01 CRLB_x Q=0"), "{:.3g}"),
            "label": r.get("T1-01 label") if isinstance(r.get("T1-01 label"), str) else "",
            'RMSE all cases (")': cell_num(r.get("RMSE_xy all cases"), "{:.3g}"),
            "nav. after (km)": cell_num(r.get("nav err after km (T1-01)"), "{:.1f}"),
            "data (samples)": cell_num(r.get("data needed (T1-01)"), "{:.0f}"),
            "time (s/seed)": cell_num(r.get("run time s/seed (T1-01)"), "{:.3f}"),
        })
    return [("", pd.DataFrame(rows))]


def compact_a_p1(df: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """A-P1 for the page: the peer UKF beside the paper's estimators, estimate, own 3-sigma, bound."""
    rows = []
    for _, r in df.iterrows():
        rows.append({
            "variant": r["variant"], "estimator": r["estimator"], "run": r["run"],
            'tx (")': cell_pm(r.get("est_x_mean_arcsec"), r.get("est_x_sd_arcsec")),
            'ty (")': cell_pm(r.get("est_y_mean_arcsec"), r.get("est_y_sd_arcsec")),
            'own 3-sigma x (")': cell_num(r.get("own_3sigma_x_arcsec"), "{:.3g}"),
            "truth in own 3-sigma": str(r.get("within_own_3sigma_text", "--")),
            '3 CRLB x, data used (")': cell_num(r.get("crlb_3sigma_x_arcsec"), "{:.3g}"),
            '3 CRLB x, Q = 0 (")': cell_num(r.get("crlb_q0_3sigma_x_arcsec"), "{:.3g}"),
        })
    return [("", pd.DataFrame(rows))]


#: Page views of paper A's tables too wide for a page, by SPEC id.
COMPACT_VIEWS = {"A-T1": compact_a_t1, "A-X1": compact_a_x1, "A-X2": compact_a_x2, "A-P1": compact_a_p1}
