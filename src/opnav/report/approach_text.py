"""Paper A's generated prose: the A-X1 verdict (A-X1_verdict.md) and the manuscript's
finding sentences (A-summary.json ``text``), the roll-rate and stars sentences among them.

Every sentence is made from the numbers of :mod:`opnav.approach.summaries` (the A-X1 table,
the summary dict); no finding is fixed text. Units: arcsec, km, samples.
"""

from __future__ import annotations

import math

import pandas as pd

from opnav.approach.setup import Setup
from opnav.approach.summaries import HeadlineRow, HeadlineSummary, prior_bound_arcsec
from opnav.core import wording


def _fmt(x, nd=2):
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{nd}f}"


def identifiability_text(setup: Setup, x1: pd.DataFrame, target_arcsec: float) -> str:
    """Plain-language A-X1 verdict, generated from the numbers of the A-X1 table; ``target_arcsec``:
    the claimed accuracy (the analysis plan's A-C1 target, :func:`opnav.core.planvalues.accuracy_target_arcsec`)."""
    target = target_arcsec
    s = setup.segments
    lines = ["# A-X1: what the data can tell about the camera misalignment", "",
             (f"Profile segments: N0 = {s.N0}, N = {s.N}, M = {s.M}, L = {s.L} ({s.mode}); "
             f"the paper claims an accuracy better than {target:g} arcsec (published)."), ""]
    for _, r in x1.iterrows():
        v = r["variant"]
        diag = " (DIAGNOSTIC: the E-step reference is the true state, which the measurements do not provide)" \
            if v == "reference-start" else ""
        b = r["crlb_x_total_arcsec"]
        verdict = "CAN" if r["bound_reaches_target"] else "CANNOT"
        need = r.get("samples_to_target")
        need_txt = (f" The bound falls below {target:g} arcsec after {wording.count(int(need), 'sample')}."
                    if need is not None and not pd.isna(need) else "")
        ps, rng = setup.prior_sigma, setup.geometry.range_km
        ratio = f"{ps.r_km:g} km / {rng:.3g} km = {prior_bound_arcsec(setup):.3g} arcsec"
        why = {
            "literal": ("The camera looks at Mars without turning, so a misalignment shifts the Mars vector "
                        "sideways by about rho*theta, which the data cannot tell from a lateral position error. "
                        f"Only the {ps.r_km:g} km prior separates them ({ratio}), and the literal EM start X_N0 "
                        "from the theta = 0 filter has already absorbed the offset"),
            "prior": ("In the same geometry the lateral offset rho*theta looks like a position error, and the "
                      f"prior ({ps.r_km:g} km, {ps.v_kms:g} km/s) only bounds theta to about {ratio}"),
            "roll": ("Turning the camera about its boresight turns the misalignment's offset in inertial space "
                     "while a position error stays fixed, so the data separate the two"),
            "reference-start": "Knowing the true start state removes the position ambiguity",
            "stars": ("Star images (beyond the paper) measure the camera attitude directly, with no parallax, so "
                      "theta is no longer confused with a position error; stars off the boresight see tz"),
        }.get(v, "")
        q0 = r.get("crlb_q0_x_total_arcsec", math.nan)
        q0_txt = (f"; {_fmt(q0)} with Q = 0, the truth having no process noise" if not pd.isna(q0) else "")
        lines.append(f"* **{v}**{diag}: CRLB(tx) = {_fmt(b)} arcsec after {int(r['total_samples'])} samples "
                     f"({_fmt(r['crlb_x_window_arcsec'])} on one {s.N}-sample sliding segment{q0_txt}). "
                     f"The information in this variant's data and prior {verdict} support {target:g} arcsec."
                     + (f" {why}." if why else "") + need_txt)
        extra = []
        for tag, name in (("plain", "Plain EM (paper's sliding segments)"),
                          ("growing_squarem", "SQUAREM on growing windows")):
            if f"em_{tag}_est_x_mean" in r and not pd.isna(r.get(f"em_{tag}_est_x_mean")):
                lab = r.get(f"em_{tag}_label")
                st = f", labelled {lab}" if isinstance(lab, str) and lab else ""
                extra.append(f"{name} ends at tx = {_fmt(r[f'em_{tag}_est_x_mean'])} +- "
                             f"{_fmt(r[f'em_{tag}_est_x_std'])} arcsec{st}: RMS error "
                             f"{_fmt(r[f'em_{tag}_rmse_x_arcsec'])}, bound of the data it used "
                             f"{_fmt(r[f'em_{tag}_crlb_x_arcsec'])} "
                             f"({_fmt(r.get(f'em_{tag}_crlb_q0_x_arcsec', math.nan))} with Q = 0).")
        if "maps_plain_median" in r and not pd.isna(r.get("maps_plain_median")):
            mp = r["maps_plain_median"]
            mp_txt = (f"more than the {int(r['max_maps'])} maps run (about "
                      f"{wording.num(r['maps_plain_extrapolated_median'])} at its contraction of "
                      f"{r['plain_rate_per_map']:.5f} a map{': stalled' if r['plain_rate_per_map'] > 0.999 else ''})"
                      if mp > r["max_maps"] else wording.count(round(float(mp)), "map"))
            extra.append(f"On one {int(r['mle_samples'])}-sample window the maximum-likelihood estimate (SQUAREM, "
                         f"{wording.count(round(float(r['maps_squarem_median'])), 'EM map', 'EM maps')}) has RMS error "
                         f"{_fmt(r['mle_rmse_x_arcsec'])} arcsec in tx against a CRLB of "
                         f"{_fmt(r['crlb_x_at_mle_samples'])}.")
            extra.append(f"Plain EM needs {mp_txt} to get within {r['tol_arcsec']:g} arcsec of it.")
        if extra:
            lines.append("  " + " ".join(extra))
        if not r["tz_observable"]:
            lines.append("  The roll about the boresight, tz, is unobservable: its bound stays at the diffuse prior.")
    lines += ["", ("Any published accuracy finer than a variant's CRLB cannot come from an unbiased estimator "
              "using that variant's measurements and prior; a match there would be luck or extra information.")]
    return "\n".join(lines) + "\n"


def roll_rate_text(rr: dict) -> str:
    """The manuscript's roll-rate sentences, from :func:`roll_rate_summary`."""
    rates = rr["rates_deg_s"]
    parts = [f"{b:.3g} arcsec at {r:g} deg/s" for r, b in zip(rates, rr["bound_all_arcsec"])]
    rate = rr["rate_to_target_deg_s"]
    reach = (f"It reaches the claimed {rr['target_arcsec']:g} arcsec within the paper's {rr['samples']} samples "
             f"from a roll rate of {rate:.3g} deg/s" if rate is not None else
             f"No rate in the searched range brings it to {rr['target_arcsec']:g} arcsec within "
             f"{rr['samples']} samples")
    return (f"The roll rows depend on the roll rate, which is our choice ({rr['config_rate_deg_s']:g} deg/s). The "
            f"bound of all {rr['total_samples']} samples is " + _join(parts)
            + f" (about rate^{rr['slope_all']:.2g}). {reach}.")


def _stars_phrase(v: dict) -> str:
    """'3 stars in every image (to magnitude 8 in a 2.84 deg field)' for one row of the stars sweep."""
    spi = v.get("stars_per_image")
    count = (f"{spi['min']}" if spi["min"] == spi["max"] else f"{spi['min']}-{spi['max']}") if spi else None
    field = v.get("field_deg")
    where = ""
    if field is not None and v.get("mag_limit") is not None:
        wide = v.get("camera_field_deg")
        where = (f" (to magnitude {v['mag_limit']:.3g} in a {field:.3g} deg field"
                 + (f", widened from the camera's {wide:.3g} deg" if wide is not None and field > wide + 1e-9 else "")
                 + ")")
    if count == str(v["per_image"]):
        return wording.count(v["per_image"], "star") + " in every image" + where
    return f"up to {v['per_image']} stars per image" + (f" ({count} in the field along the arc)" if spi else "") + where


def stars_text(st: dict, target: float) -> str:
    """The manuscript's stars sentences, from :func:`stars_summary` (each setting's numbers are
    table A-X6's): what star images add, the bound from the fewest to the most stars in every image,
    the attitude-knowledge sweep, and whether star calibration answers paper A's objection
    (unsynchronised modes, the camera possibly the only sensor). Every sentence short."""
    rows = {k: v for k, v in st.items() if k != "objection"}
    mrows = sorted((v for v in rows.values() if v.get("sweep", "per_image") == "per_image"),
                   key=lambda v: v["per_image"])
    if not mrows:
        return ""
    v0 = mrows[0]
    out = [f"Beyond the paper, star images of Hipparcos stars calibrate the camera the way flight teams do "
           f"({wording.count(v0['images'], 'image')}, one every {v0['every_K']} samples); stars off the boresight "
           "also observe the roll tz"]
    att_now = f" at the configured attitude knowledge ({mrows[-1].get('attitude_sigma_arcsec', float('nan')):g} arcsec)"
    b0 = max(v0["crlb_arcsec"][:2])
    if len(mrows) > 1:
        b1 = max(mrows[-1]["crlb_arcsec"][:2])
        how = wording.change(100 * (1 - b1 / b0))
        out.append(f"With {_stars_phrase(v0)} the bound of (tx, ty) is {b0:.3g} arcsec{att_now}")
        out.append(f"With {_stars_phrase(mrows[-1])} it is {b1:.3g} arcsec ({how})")
    else:
        out.append(f"With {_stars_phrase(v0)} the bound of (tx, ty) is {b0:.3g} arcsec{att_now}")
    reached = [v for v in mrows if v["samples_to_target"] is not None]
    out.append(f"It reaches {target:g} arcsec after {reached[0]['samples_to_target']:.0f} samples with "
               f"{wording.count(reached[0]['per_image'], 'star')} in every image" if reached else
               f"No count of stars brings it to {target:g} arcsec within the arc")
    att = sorted((v for v in rows.values() if v.get("sweep") == "attitude_sigma_arcsec"),
                 key=lambda v: v["attitude_sigma_arcsec"])
    if len(att) > 1:
        a, z = att[0], att[-1]
        out.append(f"Against each star image's attitude knowledge (drift {a['mode_drift_arcsec']:g} arcsec) the bound "
                   f"goes from {max(a['crlb_arcsec'][:2]):.3g} at {a['attitude_sigma_arcsec']:g} arcsec to "
                   f"{max(z['crlb_arcsec'][:2]):.3g} at {z['attitude_sigma_arcsec']:g} arcsec (attitude floor "
                   f"{a['floor_arcsec']:.3g} to {z['floor_arcsec']:.3g}), and the EM RMS from "
                   f"{a['estimators']['em_growing_squarem']['rmse_xy_arcsec']:.3g} to "
                   f"{z['estimators']['em_growing_squarem']['rmse_xy_arcsec']:.3g}")
    obj = st.get("objection")
    if obj:
        thr = obj["attitude_threshold_arcsec"]
        if thr <= 0.0:
            out.append(f"Even perfect attitude knowledge of the star images leaves the bound above {target:g} "
                       "arcsec: star calibration does not answer paper A's objection here")
        else:
            out.append(f"Star calibration answers paper A's objection (the camera may be the only sensor, its star "
                       f"and Mars modes unsynchronised) only while each star image's attitude relative to the Mars "
                       f"images is known to better than {thr:.3g} arcsec (1-sigma per axis)")
            out.append(f"Beyond that the bound exceeds {target:g} arcsec")
    return " ".join(o + "." for o in out)


def nees_text(nees: dict, keys=None) -> str:
    """The manuscript's consistency sentences, from :func:`opnav.approach.summaries.nees_summary`:
    each headline row's (those of ``keys``, all if None) compensated filters judged against the
    filter given the true theta on the same runs (the truth has no process noise while the
    filters' Q > 0, so that filter's NEES is the reference, not 3). A filter is above (optimistic)
    or below (conservative) the reference when the seed mean of its paired difference is more
    than two standard errors from zero. (The manuscript sets the same numbers as a table:
    :func:`opnav.report.text_tables.nees_rows`.)"""
    def side(d, se):
        if d is None or se is None or not math.isfinite(se):
            return "not judged (one seed)"
        if d > 2 * se:
            return "above it (optimistic: the position covariance too small)"
        if d < -2 * se:
            return "below it (conservative)"
        return "indistinguishable from it"

    parts = []
    for key, v in nees.items():
        if keys is not None and key not in keys:
            continue
        ref, n = v.get("reference_nees_mean"), v.get("n_seeds")
        if ref is None or v.get("nees_mean") is None:
            continue
        txt = (f"In {key} the reference is {ref:.3g} ({wording.count(n, 'seed')}); taken as exact, the estimate "
               f"gives {v['nees_mean']:.3g}, {side(v.get('after_minus_reference_mean'), v.get('after_minus_reference_se'))}")
        if v.get("consider_nees_mean") is not None:
            txt += (f", and the Schmidt filter carrying its covariance {v['consider_nees_mean']:.3g}, "
                    f"{side(v.get('consider_minus_reference_mean'), v.get('consider_minus_reference_se'))}")
        parts.append(txt + ".")
    if not parts:
        return ""
    return ("Filter consistency is read from the position NEES, initial error drawn from the prior, mean over the "
            "whole arc and the seeds. The truth has no process noise while the filters assume Q > 0, so the "
            "reference is the NEES of the filter given the true misalignment on the same runs, not 3. A filter is "
            "above or below it when its paired difference over seeds exceeds two standard errors. " + " ".join(parts))


def mars_attitude_text(ma: dict) -> str:
    """The sentences on the Mars images' attitude knowledge, from
    :func:`opnav.approach.summaries.mars_attitude_summary`: the default and why (the bound of all
    the data at the default and at each studied value is the manuscript's table,
    :func:`opnav.report.text_tables.mars_attitude_rows`)."""
    a0 = ma["default_arcsec"]
    head = ("The attitude of each Mars image is known exactly by default (camera.attitude_sigma_arcsec = 0)."
            if a0 == 0.0 else f"Each Mars image's attitude is known to {a0:g} arcsec by default.")
    why = " ".join(str(ma.get("why", "")).split())
    return head + (f" Why: {why[0].lower() + why[1:]}." if why else "")


def nav_floor_text(nf: dict) -> str:
    """The sentences on the navigation error against arc length, from
    :func:`opnav.approach.summaries.nav_floor_summary` (numbers only; table A-X7 gives every arc, and
    the claims table reads the arc at which it meets the paper's limit)."""
    rows = nf.get("rows") or []
    if not rows:
        return ""
    a, z = rows[0], rows[-1]
    return ("The paper states no arc length for its navigation error. "
            f"Against the arc, {nf['variant']} after compensation goes from {a['nav_err_km_rule']:.3g} km at "
            f"{a['arc_s']:,.0f} s to {z['nav_err_km_rule']:.3g} km at {z['arc_s']:,.0f} s (RMS over the arc's last "
            f"part, mean of {wording.count(rows[0]['n_seeds'], 'seed')}). The filter given the true theta reads "
            f"{a['true_theta_km_rule']:.3g} and {z['true_theta_km_rule']:.3g} km there.")


def tz_nav_text(tz: dict) -> str:
    """The sentence measuring paper A's 'tz does not affect navigation', from
    :func:`opnav.approach.navfloor.tz_nav_effect`."""
    sd = tz.get("diff_km_sd")
    sd_txt = "" if sd is None or not math.isfinite(sd) else f", sd {sd:.2g} km"
    return (f"Paper A says the roll tz does not affect navigation. Measured ({tz['variant']} variant, the same "
            f"{tz['n_seeds']} seeds with tz = {tz['tz_arcsec']:g} arcsec and tz = 0, each filtered with the true "
            f"(tx, ty) and tz = 0): {tz['nav_err_km_tz_on']:.4g} km against {tz['nav_err_km_tz_off']:.4g} km, a "
            f"paired difference of {tz['diff_km_mean']:.2g} km{sd_txt}.")


def _join(items: list[str], none: str = "none") -> str:
    items = list(items)
    if not items:
        return none
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def scheme_text(row: HeadlineRow) -> str:
    """The EM scheme of a headline row in words: 'plain EM, sliding windows' (the paper's),
    else what it adds ('growing', 'squarem', 'growing squarem')."""
    parts = (["growing"] if row.mode == "growing" else []) + ([row.method] if row.method != "plain" else [])
    return " ".join(parts) or "plain EM, sliding windows"


def findings(setup: Setup, summ: HeadlineSummary, pub_headline: dict, target_arcsec: float) -> dict:
    """Every sentence of the manuscript's paper-A results that states a finding, generated
    from the summary's flags and numbers (plain text; the macros escape it). ``summ``:
    :meth:`opnav.approach.summaries.HeadlineSummary.from_json` of the summary. Keys:

    ``bound``    which variants' all-data bound supports the claimed accuracy, and how the
                 literal bound compares with what the prior alone gives (sigma_r / rho);
    ``stall``    the convergence labels (converged / stalled / not converged, from the ML
                 estimate of the data each run used) per scheme and variant;
    ``reading``  where the published error is below the bound of the data the estimator
                 used (not reproducible there), which schemes reach their bound, and which
                 of our rows lies closest to the published estimates.
    ``headline_<key>`` one sentence per Table-1 headline row (its A-T1 ``variant``).

    ``target_arcsec``: the claimed accuracy (the analysis plan's A-C1 target).
    """
    if not isinstance(summ, HeadlineSummary):
        raise TypeError(f"approach_text.findings: summ must be a HeadlineSummary "
                        f"(HeadlineSummary.from_json(<summary>)), got {type(summ).__name__}")
    target = target_arcsec
    rows = summ.rows
    base = {r.scenario: r for r in rows if r.as_written_scheme}  # plain EM, sliding: the paper's scheme
    out = {}

    def nice(x, nd=3):
        return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{nd}g}"

    def label_or(r: HeadlineRow, default: str) -> str:
        return r.label if r.label is not None else default

    below = [k for k, r in base.items() if (r.crlb_all_x_arcsec or math.inf) <= target]
    diag = {"reference-start": "the reference-start diagnostic"}
    names = [diag.get(k, f"the {k} variant") for k in below]
    pb = summ.prior_bound_arcsec
    lit = base["literal"].crlb_all_x_arcsec if "literal" in base else None
    s = ("With the paper's prior, the bound of tx after all the data is "
         + _join([f"{nice(r.crlb_all_x_arcsec)} arcsec ({k})" for k, r in base.items()])
         + f", against the claimed {target:g} arcsec. "
         + (f"Only {_join(names)} {'gets' if len(names) == 1 else 'get'} below it." if below and len(below) < len(base)
            else "Every variant gets below it." if below else "No variant gets below it."))
    if lit is not None:
        ratio = lit / pb
        s += (f" The prior alone bounds theta to sigma_r / rho = {nice(pb)} arcsec "
              f"({setup.prior_sigma.r_km:g} km seen from {setup.geometry.range_km:.3g} km); the literal "
              f"bound is {ratio:.2f} times that, so in the literal geometry the measurements "
              + ("add almost nothing to the prior." if ratio > 0.8 else "add information beyond the prior."))
    out["bound"] = s

    by_scheme: dict[str, list[tuple[str, str]]] = {}
    for r in rows:
        by_scheme.setdefault(scheme_text(r), []).append((r.scenario, label_or(r, "stalled" if r.stalled else "")))
    parts = []
    for lab, lst in by_scheme.items():
        groups: dict[str, list[str]] = {}
        for scen, l_ in lst:
            groups.setdefault(l_ or "unlabelled", []).append(scen)
        parts.append(f"{lab[0].upper() + lab[1:]}: " + "; ".join(f"{l_} in {_join(sc_)}" for l_, sc_ in groups.items()))
    out["stall"] = ("An EM run is labelled converged when it ends within "
                    f"{setup.em.converge_frac_of_bound:g} times the 1-sigma bound of the data it used (in tx and ty) "
                    "of the maximum-likelihood estimate of that data. It is stalled when it does not and its "
                    f"contraction per map toward that estimate is about 1 (at least {setup.em.stall_rate:g}), "
                    "whatever its start; whether a converged estimate means anything is read from the bound of "
                    "that data. The headline rows read as follows. " + " ".join(p_ + "." for p_ in parts))

    for r in rows:
        conv = (f"; data to converge {nice(r.data_to_converge_samples, 4)} samples"
                if r.label == "converged" else "")
        reading = str(r.reading or "")
        out[f"headline_{r.key}"] = (f"{r.key}: tx = {nice(r.est_x_mean, 4)} +- {nice(r.est_x_std, 2)}, "
                                    f"ty = {nice(r.est_y_mean, 4)} +- {nice(r.est_y_std, 2)} arcsec, "
                                    f"bound of the data it used {nice(r.crlb_x_arcsec)} arcsec "
                                    f"({nice(r.crlb_q0_x_arcsec)} with Q = 0)"
                                    + (f". {reading[0].upper() + reading[1:]}{conv}" if reading else conv))

    truth = pub_headline.get("truth_arcsec", [math.nan] * 3)
    pe = max(abs(pub_headline.get("est_x_arcsec", math.nan) - truth[0]),
             abs(pub_headline.get("est_y_arcsec", math.nan) - truth[1]))
    nr = [r.key for r in rows if max(r.crlb_x_arcsec, r.crlb_y_arcsec) > pe]
    reach = [r.key for r in rows if label_or(r, "converged") == "converged" and not r.stalled
             and max(r.crlb_x_arcsec, r.crlb_y_arcsec) <= target
             and abs(r.est_x_mean - truth[0]) <= 3 * r.crlb_x_arcsec + 0.1
             and abs(r.est_y_mean - truth[1]) <= 3 * r.crlb_y_arcsec + 0.1]
    dist = {r.key: math.hypot(r.est_x_mean - pub_headline.get("est_x_arcsec", math.nan),
                              r.est_y_mean - pub_headline.get("est_y_arcsec", math.nan)) for r in rows}
    closest = min(dist, key=lambda k: (dist[k], k)) if dist else None
    others = [r.key for r in rows if r.key not in nr]
    which = (f" ({_join(nr)})" if len(nr) <= 3 else f" (all but {_join(others)})" if others and len(others) <= 3
             else "")
    s = (f"The published error ({nice(pe)} arcsec) is below the bound of the data the estimator used in "
         f"{len(nr)} of {len(rows)} headline rows{which}. There no unbiased estimator with the stated "
         "measurements and prior can know the misalignment that well, and we mark them not reproducible "
         "under stated assumptions. ")
    s += (f"Estimates converged, identifiable (bound at most {target:g} arcsec) and within 3 bound-sigma of "
          f"the truth: {_join(reach)}. " if reach
          else "No row is converged, identifiable and within 3 bound-sigma of the truth. ")
    if closest is not None:
        c = next(r for r in rows if r.key == closest)
        s += (f"The row closest to the published estimates is {closest} ({nice(dist[closest])} arcsec away"
              + ("; a diagnostic that needs the true state" if c.scenario == "reference-start" else "")
              + (f"; it is {c.label}" if label_or(c, "converged") != "converged" else "") + ").")
    out["reading"] = s
    out["roll_rate"] = roll_rate_text(summ.roll_rate) if summ.roll_rate is not None else ""
    out["stars"] = stars_text(summ.stars, target) if summ.stars is not None else ""
    # the paper's scheme of every scenario and the best row (the navigation floor's), if any
    nees_rows = {r.key for r in rows if r.as_written_scheme}
    if summ.nav_floor_by_arc:
        nees_rows.add(summ.nav_floor_by_arc.get("variant"))
    out["nees"] = nees_text(summ.nees, nees_rows) if summ.nees else ""
    out["mars_attitude"] = mars_attitude_text(summ.mars_attitude) if summ.mars_attitude else ""
    out["nav_floor"] = nav_floor_text(summ.nav_floor_by_arc) if summ.nav_floor_by_arc else ""
    out["tz_nav"] = tz_nav_text(summ.tz_nav_effect) if summ.tz_nav_effect else ""

    # the per-variant numbers are the manuscript's tables (opnav.report.text_tables): here one
    # sentence each, no per-variant repetition (issue 55 item 4)
    after = {k: r.nav_err_after_km for k, r in base.items() if r.nav_err_after_km is not None}
    out["nav"] = ""
    if after:
        lo, hi = min(after, key=after.get), max(after, key=after.get)
        out["nav"] = (f"After compensation the navigation error under the paper's scheme ranges from "
                      f"{nice(after[lo])} km ({diag.get(lo, lo)}) to {nice(after[hi])} km ({diag.get(hi, hi)}).")
    mx = summ.convergence_max_maps
    plain = {k: r.iterations_plain_median for k, r in base.items() if r.iterations_plain_median is not None}
    sq = {k: r.iterations_squarem_median for k, r in base.items() if r.iterations_squarem_median is not None}
    out["convergence"] = ""
    if plain and sq:
        over = [k for k, v in plain.items() if mx is not None and v > mx]
        out["convergence"] = (f"On one window of the convergence study SQUAREM comes within the tolerance of the "
                              f"maximum-likelihood estimate in at most {wording.count(round(max(sq.values())), 'map')}; "
                              + (f"plain EM needs more than the {mx} maps run in {_join([diag.get(k, k) for k in over])}."
                                 if over else f"plain EM in at most {wording.count(round(max(plain.values())), 'map')}."))
    return out
