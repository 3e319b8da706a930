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
        need_txt = (f" The bound falls below {target:g} arcsec after {int(need)} samples."
                    if need is not None and not pd.isna(need) else "")
        ps, rng = setup.prior_sigma, setup.geometry.range_km
        ratio = f"{ps.r_km:g} km / {rng:.3g} km = {prior_bound_arcsec(setup):.3g} arcsec"
        why = {
            "literal": "the camera looks at Mars without turning, so a misalignment shifts the Mars vector "
                       "sideways by about rho*theta, which the data cannot tell from a lateral position error; "
                       f"only the {ps.r_km:g} km prior separates them ({ratio}). The literal "
                       "EM start X_N0 from the theta = 0 filter has already absorbed the offset",
            "prior": "the same geometry: the lateral offset rho*theta looks like a position error, and the "
                     f"prior ({ps.r_km:g} km, {ps.v_kms:g} km/s) only bounds theta to about {ratio}",
            "roll": "turning the camera about its boresight turns the misalignment's offset in inertial space "
                    "while a position error stays fixed, so the data separate the two",
            "reference-start": "knowing the true start state removes the position ambiguity",
            "stars": "star images (beyond the paper) measure the camera attitude directly, with no parallax, so "
                     "theta is no longer confused with a position error, and stars off the boresight see tz",
        }.get(v, "")
        q0 = r.get("crlb_q0_x_total_arcsec", math.nan)
        q0_txt = (f"; {_fmt(q0)} arcsec with Q = 0, the truth having no process noise" if not pd.isna(q0) else "")
        lines.append(f"* **{v}**{diag}: CRLB(tx) = {_fmt(b)} arcsec after {int(r['total_samples'])} samples{q0_txt} "
                     f"(one {s.N}-sample sliding segment: {_fmt(r['crlb_x_window_arcsec'])} arcsec). "
                     f"The information in this variant's data and prior {verdict} support {target:g} arcsec: "
                     f"{why}.{need_txt}")
        extra = []
        for tag, name in (("plain", "plain EM (paper's sliding segments)"),
                          ("growing_squarem", "SQUAREM on growing windows")):
            if f"em_{tag}_est_x_mean" in r and not pd.isna(r.get(f"em_{tag}_est_x_mean")):
                lab = r.get(f"em_{tag}_label")
                st = f"; labelled {lab} (from the ML estimate of the data it used)" if isinstance(lab, str) and lab else ""
                extra.append(f"{name} ends at tx = {_fmt(r[f'em_{tag}_est_x_mean'])} +- "
                             f"{_fmt(r[f'em_{tag}_est_x_std'])} arcsec (initial error drawn from the prior; "
                             f"RMS error {_fmt(r[f'em_{tag}_rmse_x_arcsec'])}, bound of the data it used "
                             f"{_fmt(r[f'em_{tag}_crlb_x_arcsec'])}, "
                             f"{_fmt(r.get(f'em_{tag}_crlb_q0_x_arcsec', math.nan))} with Q = 0){st}")
        if "maps_plain_median" in r and not pd.isna(r.get("maps_plain_median")):
            mp = r["maps_plain_median"]
            mp_txt = (f"more than the {int(r['max_maps'])} run (about {r['maps_plain_extrapolated_median']:.3g} "
                      f"extrapolated from its measured contraction factor {r['plain_rate_per_map']:.5f} per "
                      f"iteration{'; stalled' if r['plain_rate_per_map'] > 0.999 else ''})"
                      if mp > r["max_maps"] else f"{mp:.0f}")
            extra.append(f"on one {int(r['mle_samples'])}-sample window the maximum-likelihood estimate "
                         f"(SQUAREM, {r['maps_squarem_median']:.0f} EM maps) has RMS error "
                         f"{_fmt(r['mle_rmse_x_arcsec'])} arcsec in tx against a CRLB of "
                         f"{_fmt(r['crlb_x_at_mle_samples'])}; plain EM needs {mp_txt} iteration(s) to get within "
                         f"{r['tol_arcsec']:g} arcsec of it")
        if extra:
            lines.append("  " + "; ".join(extra) + ".")
        if not r["tz_observable"]:
            lines.append("  tz (roll about the boresight) is unobservable: its bound stays at the diffuse prior.")
    lines += ["", ("Any published accuracy finer than a variant's CRLB cannot come from an unbiased estimator "
              "using that variant's measurements and prior; a match there would be luck or extra information.")]
    return "\n".join(lines) + "\n"


def roll_rate_text(rr: dict) -> str:
    """The manuscript's roll-rate sentence, from :func:`roll_rate_summary`."""
    rates = rr["rates_deg_s"]
    parts = [f"{b:.3g} arcsec at {r:g} deg/s" for r, b in zip(rates, rr["bound_all_arcsec"])]
    rate = rr["rate_to_target_deg_s"]
    reach = (f"the bound reaches the claimed {rr['target_arcsec']:g} arcsec within the paper's {rr['samples']} samples "
             f"from a roll rate of {rate:.3g} deg/s" if rate is not None else
             f"no rate in the searched range brings the bound to {rr['target_arcsec']:g} arcsec within "
             f"{rr['samples']} samples")
    return (f"The roll rows depend on the roll rate, which is our choice ({rr['config_rate_deg_s']:g} deg/s): the "
            f"bound of all {rr['total_samples']} samples is " + _join(parts)
            + f" (about rate^{rr['slope_all']:.2g}); {reach}.")


def stars_text(st: dict, target: float) -> str:
    """The manuscript's stars sentences, from :func:`stars_summary`: the estimates per stars per
    image, then the attitude-knowledge and magnitude sweeps and whether star calibration answers
    paper A's objection (unsynchronised modes, the camera possibly the only sensor)."""
    rows = {k: v for k, v in st.items() if k != "objection"}
    parts = []
    for v in rows.values():
        if v.get("sweep", "per_image") != "per_image":
            continue
        b, g, a = v["crlb_arcsec"], v["estimators"].get("em_growing_squarem"), v["estimators"].get("augmented")
        need = v["samples_to_target"]
        spi = v.get("stars_per_image")
        count = (f"{spi['min']}" if spi['min'] == spi['max'] else f"{spi['min']}-{spi['max']}") if spi else None
        field = v.get("field_deg")
        where = ""
        if field is not None and v.get("mag_limit") is not None:
            wide = v.get("camera_field_deg")
            where = (f" (to magnitude {v['mag_limit']:.3g} in a {field:.3g} deg field"
                     + (f", widened from the camera's {wide:.3g} deg" if wide is not None and field > wide + 1e-9 else "")
                     + ")")
        txt = ((f"{count} star{'s' if v['per_image'] > 1 else ''} in every image" if count == str(v['per_image'])
                else f"up to {v['per_image']} stars per image" + (f" ({count} in the field along the arc)" if spi else ""))
               + where + f", {v['images']} images one every {v['every_K']} samples: bound "
               f"(tx, ty, tz) = ({b[0]:.3g}, {b[1]:.3g}, {b[2]:.3g}) arcsec, "
               + (f"{target:g} arcsec reached after {need:.0f} samples" if need is not None else
                  f"{target:g} arcsec not reached"))
        for name, e in (("EM-EKF (growing, SQUAREM)", g), ("augmented EKF", a)):
            if e:
                m, sd = e["mean_arcsec"], e["sd_arcsec"]
                txt += (f"; {name} ({m[0]:.3g} +- {sd[0]:.2g}, {m[1]:.3g} +- {sd[1]:.2g}, {m[2]:.3g} +- {sd[2]:.2g})"
                        + (f", {e['label']}" if e.get("label") else ""))
        parts.append(txt)
    if not parts:
        return ""
    out = ("Beyond the paper, star images of Hipparcos stars calibrate the camera the way flight teams do: "
           + "; ".join(parts) + ". Stars off the boresight also observe the roll tz.")
    att = sorted((v for v in rows.values() if v.get("sweep") == "attitude_sigma_arcsec"),
                 key=lambda v: v["attitude_sigma_arcsec"])
    if att:
        out += (" Against the attitude knowledge of each star image (drift "
                f"{att[0]['mode_drift_arcsec']:g} arcsec): " + "; ".join(
                    f"{v['attitude_sigma_arcsec']:g} arcsec: bound {max(v['crlb_arcsec'][:2]):.3g} "
                    f"(stars alone {max(v['crlb_stars_only_arcsec'][:2]):.3g}, floor {v['floor_arcsec']:.3g}), "
                    f"EM RMS {v['estimators']['em_growing_squarem']['rmse_xy_arcsec']:.3g}" for v in att) + ".")
    obj = st.get("objection")
    if obj:
        thr = obj["attitude_threshold_arcsec"]
        if thr <= 0.0:
            out += (f" Even perfect attitude knowledge of the star images leaves the bound above {target:g} arcsec: "
                    "star calibration does not answer paper A's objection here.")
        else:
            out += (f" Star calibration answers paper A's objection (the camera may be the only sensor and its "
                    f"star and Mars modes are not synchronised) only while each star image's attitude relative to "
                    f"the Mars images is known to better than {thr:.3g} arcsec (1-sigma per axis): beyond that "
                    f"the bound exceeds {target:g} arcsec.")
        mrows = sorted((v for v in rows.values() if v.get("sweep", "per_image") == "per_image"),
                       key=lambda v: v["per_image"])
        if len(mrows) > 1:
            n0 = mrows[0].get("stars_per_image", {}).get("median", mrows[0]["per_image"])
            n1 = mrows[-1].get("stars_per_image", {}).get("median", mrows[-1]["per_image"])
            b0, b1 = max(mrows[0]["crlb_arcsec"][:2]), max(mrows[-1]["crlb_arcsec"][:2])
            change = 100 * (1 - b1 / b0)
            how = (f"{change:.0f} % lower" if change >= 0.5 else f"{-change:.0f} % higher" if change <= -0.5
                   else "unchanged")
            out += (f" From {n0:g} to {n1:g} stars per image the bound goes from {b0:.3g} to {b1:.3g} arcsec "
                    f"({how}) at the configured attitude knowledge "
                    f"({mrows[-1].get('attitude_sigma_arcsec', float('nan')):g} arcsec).")
    return out


def nees_text(nees: dict, keys=None) -> str:
    """The manuscript's consistency sentence, from :func:`opnav.approach.summaries.nees_summary`:
    each headline row's (those of ``keys``, all if None) compensated filters judged against the
    filter given the true theta on the same runs (the truth has no process noise while the
    filters' Q > 0, so that filter's NEES is the reference, not 3). A filter is above (optimistic)
    or below (conservative) the reference when the seed mean of its paired difference is more
    than two standard errors from zero."""
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
        txt = (f"{key}: {v['nees_mean']:.3g} compensated with the estimate taken as exact, "
               f"{side(v.get('after_minus_reference_mean'), v.get('after_minus_reference_se'))}")
        if v.get("consider_nees_mean") is not None:
            txt += (f"; {v['consider_nees_mean']:.3g} with the Schmidt filter carrying its covariance, "
                    f"{side(v.get('consider_minus_reference_mean'), v.get('consider_minus_reference_se'))}")
        parts.append(txt + f" (reference {ref:.3g}, {n} seeds)")
    if not parts:
        return ""
    return ("Filter consistency (position NEES, initial error drawn from the prior, mean over the whole arc and the "
            "seeds): the truth has no process noise while the filters assume Q > 0, so the reference is the NEES "
            "of the filter given the true misalignment on the same runs, not 3; a filter is above or below it "
            "when its paired difference over seeds exceeds two standard errors. " + "; ".join(parts) + ".")


def mars_attitude_text(ma: dict) -> str:
    """The sentence on the Mars images' attitude knowledge, from
    :func:`opnav.approach.summaries.mars_attitude_summary`: the default and why, and the bound of
    all the data at the default and at each studied value."""
    a0 = ma["default_arcsec"]
    head = (f"The attitude of each Mars image is known exactly by default (camera.attitude_sigma_arcsec = 0): "
            if a0 == 0.0 else f"Each Mars image's attitude is known to {a0:g} arcsec by default: ") + ma["why"] + "."
    rows = ma.get("bound_all_arcsec") or {}
    vals = [f"{float(a):g}" for a in ma.get("values_arcsec", [])]
    parts = [", ".join(f"{r[k]:.3g}" for k in ["default", *vals] if k in r) + f" ({v})" for v, r in rows.items()]
    if vals and parts:
        head += (f" The bound of (tx, ty) after all the data at the default ({a0:g} arcsec) and at "
                 f"{_join(vals)} arcsec per image (1-sigma per axis, independent per image): " + "; ".join(parts) + ".")
    return head


def nav_floor_text(nf: dict) -> str:
    """The sentence on the navigation error against arc length, from
    :func:`opnav.approach.summaries.nav_floor_summary` (numbers only; the claims table reads the
    arc at which it meets the paper's limit)."""
    rows = nf.get("rows") or []
    if not rows:
        return ""
    parts = [f"{r['arc_s']:,.0f} s: {r['nav_err_km_rule']:.3g} km ({r['nav_err_km_last']:.3g} at the last sample; "
             f"true theta {r['true_theta_km_rule']:.3g}, {r['true_theta_km_last']:.3g})" for r in rows]
    return (f"The paper states no arc length for its navigation error. Against the arc, {nf['variant']} after "
            f"compensation reads " + "; ".join(parts) + f" (RMS over the arc's last part, mean of {rows[0]['n_seeds']} "
            "seeds; the filter given the true theta beside it).")


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
         + f", against the claimed {target:g} arcsec; "
         + (f"only {_join(names)} {'gets' if len(names) == 1 else 'get'} below it." if below and len(below) < len(base)
            else "every variant gets below it." if below else "no variant gets below it."))
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
        parts.append(f"{lab}: " + "; ".join(f"{l_} in {_join(sc_)}" for l_, sc_ in groups.items()))
    out["stall"] = ("An EM run is labelled converged when it ends within "
                    f"{setup.em.converge_frac_of_bound:g} times the 1-sigma bound of the data it used (in tx and ty) "
                    "of the maximum-likelihood estimate of that data, stalled when it does not and its contraction per map toward that estimate is about 1 "
                    f"(at least {setup.em.stall_rate:g}), whatever its start; whether a converged estimate means "
                    "anything is read from the bound of that data. Headline rows: " + " | ".join(parts) + ".")

    for r in rows:
        conv = (f"; data to converge {nice(r.data_to_converge_samples, 4)} samples"
                if r.label == "converged" else "")
        out[f"headline_{r.key}"] = (f"{r.key}: tx = {nice(r.est_x_mean, 4)} +- {nice(r.est_x_std, 2)}, "
                                    f"ty = {nice(r.est_y_mean, 4)} +- {nice(r.est_y_std, 2)} arcsec, "
                                    f"bound of the data it used {nice(r.crlb_x_arcsec)} arcsec "
                                    f"({nice(r.crlb_q0_x_arcsec)} with Q = 0); {r.reading}{conv}")

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
    s = (f"The published error ({nice(pe)} arcsec) is below the bound of the data the estimator used in "
         f"{len(nr)} of {len(rows)} headline rows ({_join(nr)}): there no unbiased estimator with the stated "
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

    parts = [f"{diag.get(k, k)}: {r.nav_note}" for k, r in base.items() if r.nav_note]
    out["nav"] = ("Navigation error (RMS over the last part of the arc) after compensation, split across and "
                  "along the line of sight, beside the filter given the true theta (a diagnostic floor): "
                  + "; ".join(parts) + "." if parts else "")

    parts = []
    mx = summ.convergence_max_maps
    for k, r in base.items():
        mp, ex, sq = r.iterations_plain_median, r.iterations_plain_extrapolated_median, r.iterations_squarem_median
        if mp is None:
            continue
        plain = (f"more than the {mx} maps run (about {nice(ex)} extrapolated from its measured contraction rate)"
                 if mx is not None and mp > mx else f"{mp:.0f} maps")
        parts.append(f"{diag.get(k, k)}: plain EM needs {plain}, SQUAREM {nice(sq)}")
    out["convergence"] = ("On one window of the convergence study, the EM maps needed to come within "
                          "the tolerance of the maximum-likelihood estimate are: " + "; ".join(parts) + "."
                          if parts else "")
    return out
