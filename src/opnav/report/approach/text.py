"""Paper A's words made from its numbers: a run's reading, the navigation-error note, the
installation and sample-time readings, and the sentences A-summary.json carries beside its
numbers (``why``, ``rule``, ``reason``).

Moved out of the paper package (issue 56 item 2): :mod:`opnav.approach` computes the typed
records (:class:`opnav.approach.cases.CaseRun`, :class:`opnav.approach.summaries.ASummary` ...)
and this module words them; :func:`with_words` fills the summary's word fields and
:func:`with_readings` adds A-T1's ``reading`` column. The manuscript's finding sentences are
:mod:`opnav.report.approach_text`'s. Units: arcsec, km, samples, s.
"""

from __future__ import annotations

import math
from dataclasses import asdict, replace

import numpy as np
import pandas as pd

from opnav.approach import scenario as sc
from opnav.approach.cases import CaseRun
from opnav.approach.labels import row_label, variant_label
from opnav.approach.readings import InstallationCheck, SampleTimeReading
from opnav.approach.summaries import ASummary


# ------------------------------------------------------------ a run's reading (SPEC A.3c)
def bound_cause(start: str, mode: str, window: int) -> str:
    """Why the data used cannot tell theta apart (the cause half of the identifiability reading)."""
    if start == "filter":
        return "the window's start, from the theta = 0 filter, has absorbed rho*theta"
    if mode == "sliding":
        return f"one {window}-sample window holds too little information"
    return "the data and prior cannot separate theta from a lateral position error"


def reading_text(label: str, counts: dict, n: int, bound_arcsec: float, target_arcsec: float,
                 dist_ml_arcsec: float, rate: float, cause: str = "") -> str:
    """One run's reading: its convergence label (what the iteration reached on its data) and,
    for a converged one, what the bound of that data says the estimate can mean:
    ``converged (3/3); not identifiable from this data (bound 20.6 arcsec): <cause>``."""
    k = counts.get(label, 0)
    if label == "converged":
        if bound_arcsec > target_arcsec:
            return (f"converged ({k}/{n}); not identifiable from this data (bound {bound_arcsec:.3g} arcsec)"
                    + (f": {cause}" if cause else ""))
        return f"converged ({k}/{n}); bound {bound_arcsec:.3g} arcsec"
    rate_txt = "n/a" if rate is None or not math.isfinite(rate) else f"{rate:.4g}"
    return (f"{label} ({k}/{n}): {dist_ml_arcsec:.3g} arcsec from the ML estimate of its data, "
            f"contraction {rate_txt} per map")


def run_reading(r: CaseRun, target_arcsec: float) -> str:
    """:func:`reading_text` of one Monte-Carlo run (with its bounds, :func:`opnav.approach.pipeline.run_group`):
    the majority label over its seeds, the worse of the (tx, ty) bounds of the data it used, its mean
    distance to the ML estimate, the median contraction per map and the cause of its variant, windows
    and first window."""
    lab, counts = row_label(r.label)
    crlb = r.bounds.crlb_arcsec
    rate = (float(np.nanmedian(r.contraction_per_map)) if np.isfinite(r.contraction_per_map).any() else math.nan)
    cause = bound_cause(sc.START_OF[r.variant], r.mode, int(np.asarray(r.seg_data_used)[0]))
    return reading_text(lab, counts, len(np.asarray(r.data_to_converge)), float(max(crlb[0], crlb[1])),
                        target_arcsec, float(np.mean(r.dist_to_ml_arcsec)), rate, cause)


def with_readings(t1: pd.DataFrame, results: list[CaseRun], target_arcsec: float) -> pd.DataFrame:
    """A-T1 with each row's reading (:func:`run_reading` of its run: the row's A-T1 ``variant`` and
    ``case_id``) in the column ``reading``, after ``identifiable``."""
    words = {(variant_label(r.variant, r.method, r.mode), r.case_id): run_reading(r, target_arcsec) for r in results}
    out = t1.copy()
    out.insert(out.columns.get_loc("identifiable") + 1, "reading",
               [words[(v, c)] for v, c in zip(out["variant"], out["case_id"])])
    return out


# ------------------------------------------------------------ the summary's words
def _num(row, key: str) -> float | None:
    try:
        v = float(row[key])
    except (KeyError, TypeError, ValueError):
        return None
    return None if math.isnan(v) else (v if math.isfinite(v) else None)


def nav_note(r) -> str:
    """What sets a row's navigation error after compensation, from its split (A-T1 columns, or a
    summary row as a mapping): ``after X km (lateral L, range R); with the true theta T km (lateral,
    range)`` (the filters' consistency is :func:`opnav.approach.summaries.nees_summary`'s)."""
    def g(k):
        v = _num(r, k)
        return "n/a" if v is None else f"{v:.3g}"
    if _num(r, "nav_err_after_rng_km") is None:
        return ""
    lat, rng = _num(r, "nav_err_after_lat_km"), _num(r, "nav_err_after_rng_km")
    part = "range" if rng >= lat else "lateral"
    return (f"after compensation {g('nav_err_after_km')} km (lateral {g('nav_err_after_lat_km')}, range "
            f"{g('nav_err_after_rng_km')}: the {part} channel sets it); with the true theta "
            f"{g('nav_err_true_theta_km')} km (lateral {g('nav_err_true_theta_lat_km')}, range "
            f"{g('nav_err_true_theta_rng_km')})")


def mars_attitude_why(default_arcsec: float) -> str:
    """Why the Mars images' attitude knowledge is what the config says (issue 54, item 3)."""
    if default_arcsec == 0.0:
        return ("paper A's measurement (eq. 3) takes the camera attitude A_c^i as known: the reproduction keeps the "
                "paper's model, and the bound with an attitude error is shown beside it")
    return (f"our choice: each Mars image's attitude is known to {default_arcsec:g} arcsec (1-sigma per axis, "
            "independent per image), which the paper's measurement (eq. 3) leaves out")


def roll_rate_rule(samples: int) -> str:
    """The rule of the roll-rate bound the claims scorer reads (issue 54)."""
    return (f"roll variant, headline case: the worse of the 1-sigma Cramer-Rao bounds of tx and ty after "
            f"{int(samples)} samples from N0 (the paper's data to converge), with the filter's Q, "
            f"the camera rolling at each rate")


def installation_why(chk: InstallationCheck) -> str:
    """Whether the installation cases of Table 1 test anything (issue 54, item 7)."""
    if chk.by_construction:
        return ("the misalignment is defined in the camera frame and the body attitude is commanded to put the "
                "installed boresight on Mars (paper A eq. 3-5), so the installation matrix cancels from the "
                f"measurement (largest relative change over the angles {chk.max_rel_change:.1g}, rounding): the "
                "installation rows are noise replicates")
    return f"the installation angle changes the measurement (largest relative change {chk.max_rel_change:.2g})"


def installation_text(chk: InstallationCheck) -> str:
    """The manuscript's reading of the installation rows."""
    cam = np.asarray(chk.body_frame_theta_cam_arcsec)
    angles = ", ".join(f"{a:g}" for a in chk.install_deg)
    if not chk.by_construction:
        return (f"The installation angle changes the measurement (largest relative change "
                f"{chk.max_rel_change:.2g}): the installation rows test the estimator.")
    return (f"With the misalignment defined in the camera frame and the body attitude commanded to put the "
            f"installed boresight on Mars (paper A eq. 3-5), the installation angle ({angles} deg) cancels "
            f"from the measurement. Its largest relative change is {chk.max_rel_change:.1g}, rounding, so "
            f"'unaffected by the installation matrix' holds by construction and its rows are noise "
            f"replicates. Were the deviation fixed in the body frame, the camera would see ty from "
            f"{cam[:, 1].min():.3g} to {cam[:, 1].max():.3g} arcsec across these angles.")


def sample_time_text(st: SampleTimeReading) -> str:
    """One sentence: the two readings of the paper's sample time side by side."""
    d, m = st.dt_s, st.minutes_for_samples
    parts = [f"{v}: {x.config:.3g} vs {x.paper_4_min:.3g} arcsec" for v, x in st.bound_after_samples_arcsec.items()]
    return (f"Paper A states a {d.paper_stated:g} s step, yet calls {st.samples} samples about "
            f"{m.paper_4_min:.0f} min, which implies {d.paper_4_min:.2g} s a sample; we use "
            f"{d.config:g} s ({st.samples} samples = {m.config:.2g} min). The bound of (tx, ty) after "
            f"{st.samples} samples at our step and at {d.paper_4_min:.2g} s: " + "; ".join(parts) + ".")


def nav_floor_rule(label: str, n_seeds: int, last_fraction: float) -> str:
    """The rule of the navigation error against arc length (A-X7, A-C7's would_take)."""
    return (f"{label}, headline case, {n_seeds} seeds: position error |r_hat - r_true| of the filter compensated "
            f"with the estimate of the data up to the arc's end, RMS over the last {last_fraction:g} of the arc (the "
            f"plan's rule, nav_error.last_fraction; *_rule) and at the arc's last sample (*_last), mean over seeds; "
            f"true_theta: the filter given the true theta (a filter's floor); before: theta = 0")


def tz_rule(variant: str, tz_arcsec: float, last_fraction: float) -> str:
    """The rule of the tz on / off comparison (paper A: tz does not affect navigation)."""
    return (f"{variant} variant, headline case: the same seeds' measurements with tz = {tz_arcsec:g} arcsec "
            f"and with tz = 0, each filtered with the true (tx, ty) and tz = 0; RMS of |r_hat - r_true| "
            f"over the last {last_fraction:g} of the arc, mean over seeds")


# ------------------------------------------------------------ methods and runs in words
#: A-X2's methods (:data:`opnav.approach.alternatives_summary.METHODS`) in words
METHOD_LABELS = {
    "em_plain": "EM-EKF (plain)",
    "em_squarem": "EM-EKF (SQUAREM)",
    "em_growing_plain": "EM-EKF (growing windows, plain)",
    "em_growing_squarem": "EM-EKF (growing windows, SQUAREM)",
    "augmented": "augmented EKF",
    "batch_ml": "batch ML (IPOPT)",
}
#: the peer UKF (:data:`opnav.approach.peers.PEER`) in words
PEER_LABEL = "Basilisk pixelLineBiasUKF"
#: A-P1's runs (:data:`opnav.approach.peers.RUNS`) in words
RUN_LABELS = {"headline": "headline case", "bias_free": "zero misalignment (sanity)",
              "truth_start": "prior mean at the truth (diagnostic)"}


def with_method_labels(long: pd.DataFrame) -> pd.DataFrame:
    """A-X2's long form with each method's words (column ``method_label``, after ``method``)."""
    out = long.copy()
    out.insert(out.columns.get_loc("method") + 1, "method_label", [METHOD_LABELS[m] for m in out["method"]])
    return out


def p1_words(table: pd.DataFrame) -> pd.DataFrame:
    """A-P1's table with its ``estimator`` and ``run`` keys in words."""
    from opnav.approach.peers import PEER

    out = table.copy()
    out["estimator"] = [PEER_LABEL if k == PEER else METHOD_LABELS.get(k, k.removeprefix("em_"))
                        for k in out["estimator"]]
    out["run"] = [RUN_LABELS[k] for k in out["run"]]
    return out


def figure_reasons() -> dict[str, str]:
    """Why each of paper A's Figs. 5 and 6 is read as it is (issue 54, item 7); the published
    numbers from published.yaml (the text's 79.13 km and Table 1's 18.43 km)."""
    from opnav.core import published

    h = published.paper_a()["headline"]
    return {
        "A-F5": ("states no number of its own: the text reads it together with Fig. 4 (tx and ty estimated "
                 "effectively: A-C1); rows: the position error at the end of the first and the last EM segment"),
        "A-F6": (f"its numbers ({h['nav_err_before_km_text']:g} km before, {h['nav_err_after_km']:g} km after) are "
                 "Table 1's, judged as A-C6 and A-C7 by the table's rule; rows add the errors at the arc's last sample"),
    }


def bound_over_own_reading(ratio: float, tol: float = 0.1) -> str:
    """How a peer's bound over its own 3-sigma reads (A-P1): above one, the estimator claims more
    precision than the data hold; below one, less; within ``tol`` of one, about what they hold."""
    if not (isinstance(ratio, (int, float)) and math.isfinite(ratio)):
        return "not computed"
    if ratio > 1.0 + tol:
        return "a ratio above one: the UKF claims more than the data hold"
    if ratio < 1.0 - tol:
        return "a ratio below one: the UKF claims less than the data hold"
    return "a ratio of about one: the UKF claims what the data hold"


def p1_summary_words(summ):
    """A-P1-summary.json with its words: each variant's ``ukf_bound_over_own_reading``
    (:func:`bound_over_own_reading` of ``ukf_bound_over_own_3sigma_x``)."""
    variants = {k: replace(v, ukf_bound_over_own_reading=bound_over_own_reading(v.ukf_bound_over_own_3sigma_x))
                if v.ukf_bound_over_own_3sigma_x is not None else v for k, v in summ.variants.items()}
    return replace(summ, variants=variants)


def with_words(summ: ASummary, t1: pd.DataFrame) -> ASummary:
    """The summary with its word fields filled: each headline row's ``reading`` (from A-T1 with
    :func:`with_readings`) and ``nav_note``, and the ``why`` / ``rule`` / ``reason`` of the parts it
    holds."""
    reading = {(v, c): w for v, c, w in zip(t1["variant"], t1["case_id"], t1["reading"])}
    variants = {}
    for k, v in summ.variants.items():
        variants[k] = replace(v, reading=reading[(k, "T1-01")], nav_note=nav_note(asdict(v)))
    out = summ.replace(variants=variants)
    if out.mars_attitude is not None:
        out = out.replace(mars_attitude=replace(out.mars_attitude, why=mars_attitude_why(out.mars_attitude.default_arcsec)))
    if out.roll_rate_bound is not None:
        out = out.replace(roll_rate_bound=replace(out.roll_rate_bound, rule=roll_rate_rule(out.roll_rate_bound.samples)))
    if out.nav_floor_by_arc is not None:
        nf = out.nav_floor_by_arc
        out = out.replace(nav_floor_by_arc=replace(nf, rule=nav_floor_rule(nf.variant, nf.n_seeds, nf.last_fraction)))
    if out.tz_nav_effect is not None:
        tz = out.tz_nav_effect
        out = out.replace(tz_nav_effect=replace(tz, rule=tz_rule(tz.variant, tz.tz_arcsec, tz.last_fraction)))
    if out.figures_5_6 is not None:
        f = out.figures_5_6
        why = figure_reasons()
        out = out.replace(figures_5_6=replace(f, f5=replace(f.f5, reason=why["A-F5"]), f6=replace(f.f6, reason=why["A-F6"])))
    if out.installation is not None:
        out = out.replace(installation=replace(out.installation, why=installation_why(out.installation)))
    return out

