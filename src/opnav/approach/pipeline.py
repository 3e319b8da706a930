"""Paper-A pipeline steps called by the thin workflow scripts and the CLI.

Description
    * (re-exported from :mod:`opnav.approach.bounds`) :func:`bound_curve` - the CRLB of theta versus data used after ``N0``
      for a variant's information set (see :mod:`opnav.approach.crlb`);
      :func:`segment_bounds` - the bound of each segment's data. Their ``_many`` /
      plural forms (:func:`bound_curves`, :func:`segment_bounds_many`) run several
      items, and every window of each, as one batched recursion
      (:func:`opnav.approach.crlb.crlb_curves`); :func:`case_bounds` does every case
      of a group with and without process noise at once.
    * :func:`run_group` - the Monte Carlo of one case group, variant and EM
      scheme (a Snakemake job), each case with its bound attached.
    The tables' numbers and the summary live in :mod:`opnav.approach.summaries`, the verdict
    text in :mod:`opnav.report.approach_text`.
Units: arcsec, km, samples.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import cases, crlb
from . import scenario as sc
from .setup import Setup


from .bounds import (_start_covariances, _star_info, _window, bound_curve, bound_curves,  # noqa: F401
                     bound_data, segment_bounds, segment_bounds_many)


def groups_for(setup: Setup, variant: str) -> list[str]:
    """Case groups a variant runs (Snakemake jobs): the five groups (or "all" in one job when
    ``scatter: variant``) for ``table1_variants``, else the headline case only."""
    if variant not in setup.table1_variants:
        return ["headline"]
    return list(cases.GROUPS) if setup.scatter == "group" else ["all"]


#: Variants whose "headline" job also runs other Table-1 groups (the stars variant, beyond the
#: paper, shows its headline and polarity rows).
HEADLINE_EXTRA = {"stars": ("polarity",)}


def cases_in(setup: Setup, group: str, variant: str = "") -> list[cases.Case]:
    """The Table-1 cases of a Snakemake job's ``group`` (``headline``: T1-01, and for the
    variants of :data:`HEADLINE_EXTRA` their extra groups)."""
    allc = cases.table1_cases(setup)
    if group == "headline":
        return [allc[0]] + [c for c in allc if c.group in HEADLINE_EXTRA.get(variant, ())]
    if group == "all":
        return allc
    return [c for c in allc if c.group == group]


def run_group(setup: Setup, variant: str, group: str, method: str, mode: str = "sliding",
              log=None, shared: dict | None = None) -> list[cases.CaseRun]:
    """Monte Carlo of every case of ``group`` under ``variant``, EM ``method`` and segment
    ``mode`` (:class:`opnav.approach.cases.CaseRun` each), each case with its ``bounds``
    (:class:`opnav.approach.cases.CaseBounds`: of the data its estimate used, per segment, of
    all data, with Q and Q = 0) and, for the headline case, a rerun with the initial error
    drawn from the prior (``sampled``: the only spread that may be set beside a Bayesian bound);
    the time series are kept for the headline case only (figures).

    ``shared``: one dict passed to the calls of every EM scheme (``method``, ``mode``) of the
    same ``setup``, ``variant`` and ``group`` (one Snakemake job): they then share the
    geometry, the simulated measurements, the theta = 0 filter and the bounds of a mode,
    computed by the first call (the same numbers as computed by each)."""
    base = setup
    setup = base.scheme(mode)
    shared = {} if shared is None else shared
    if shared.setdefault("key", (base, variant, group)) != (base, variant, group):
        raise ValueError("run_group: a shared cache is for one setup, variant and group")
    n = setup.segments.n_samples
    if ("geo", n) not in shared:
        shared[("geo", n)] = sc.build_geometry(setup, variant)
    geo = shared[("geo", n)]
    seeds = range(setup.n_seeds)
    out = []
    clist = cases_in(setup, group, variant)
    head = [c for c in clist if c.case_index == 1]
    runs_list = clist + [replace(c, init_mode="sampled") for c in head]
    if ("data", n) not in shared:
        shared[("data", n)] = cases.prepare_cases(setup, variant, runs_list, seeds, geo=geo)
    lkey = ("label_bounds", setup.segments)
    if lkey not in shared:
        shared[lkey] = cases.label_bounds(setup, geo, runs_list, variant)
    runs = cases.run_cases(setup, variant, runs_list, seeds, geo=geo, method=method, data=shared[("data", n)],
                           seg_bounds=shared[lkey])
    sampled = runs[len(clist):]
    bkey = ("bounds", setup.segments)
    if bkey not in shared:
        shared[bkey] = case_bounds(setup, geo, clist, variant)
    bounds = shared[bkey]
    for case, r, b in zip(clist, runs, bounds):
        r = replace(r, group=group, bounds=b)
        if case.case_index == 1:
            r = replace(r, sampled=cases.SampledRun.of(sampled[0]))
        else:  # time series only for the headline case (figures)
            r = r.without_series()
        out.append(r)
        if log:
            log.info("%s %s %s/%s %s: est %s, bound %s, converged %d/%d, stalled %d", variant, group, mode,
                     method, case.case_id, np.round(r.theta_final_arcsec.mean(0), 3),
                     np.round(b.crlb_arcsec[:2], 3), r.converged.sum(), r.converged.size, r.stalled.sum())
    return out


def case_bounds(setup: Setup, geo: sc.Geometry, case_list: list[cases.Case], variant: str) -> list[cases.CaseBounds]:
    """Per case, the bound of the data its estimate used (``crlb_arcsec``; per segment
    ``crlb_seg_arcsec``; with Q = 0: ``crlb_q0_arcsec``, ``crlb_seg_q0_arcsec``) and of all
    the segments' data (``crlb_total_arcsec``; Q = 0: ``crlb_total_q0_arcsec``), arcsec,
    1-sigma (:class:`opnav.approach.cases.CaseBounds`); every case and both Q at once."""
    items = [(geo.measurement_variance(c.sigma3_px), c.truth_arcsec, zq) for c in case_list for zq in (False, True)]
    need_curves = setup.segments.mode == "growing" or sc.START_OF[variant] == "filter"
    curves = bound_curves(setup, geo, items, variant)
    segs = segment_bounds_many(setup, geo, items, variant, curves if need_curves else None)
    out = []
    for i in range(len(case_list)):
        seg, seg0 = segs[2 * i], segs[2 * i + 1]
        out.append(cases.CaseBounds(crlb_seg_arcsec=seg, crlb_seg_q0_arcsec=seg0, crlb_arcsec=seg[-1],
                                    crlb_q0_arcsec=seg0[-1], crlb_total_arcsec=_at_total(setup, curves[2 * i]),
                                    crlb_total_q0_arcsec=_at_total(setup, curves[2 * i + 1])))
    return out


def _at_total(setup: Setup, curve: np.ndarray) -> np.ndarray:
    return curve[min(setup.segments.data_samples, len(curve) - 1)]


def total_bound(setup: Setup, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, variant: str) -> np.ndarray:
    """The bound of all the segments' data, L N samples after N0 (3,), arcsec, 1-sigma."""
    return _at_total(setup, bound_curve(setup, geo, Rvar, theta_arcsec, variant))


def mars_attitude_bounds(setup: Setup, geo: sc.Geometry, Rvar_of, theta_arcsec,
                         variant: str) -> dict[float, np.ndarray]:
    """The bound of all the data (tx, ty, tz; arcsec, 1-sigma, with Q) of ``variant`` at each Mars-image
    attitude knowledge of ``camera.attitude_study_arcsec`` (issue 54, item 3): the same arc with the
    estimators' variances for that knowledge (``Rvar_of(geo)``: the case's variances of a geometry)."""
    out = {}
    for a in setup.camera.attitude_study_arcsec:
        g = replace(geo, attitude_sigma_rad=float(sc.rad(a)))
        out[float(a)] = total_bound(setup, g, Rvar_of(g), theta_arcsec, variant)
    return out


# ------------------------------------------------------------ the roll rate (issue 28, item 4)
def _head(geo: sc.Geometry, n: int) -> sc.Geometry:
    """The first ``n`` samples of a geometry (arrays cut to n + 1 rows)."""
    cut = {k: getattr(geo, k)[:n + 1] for k in ("t", "X_true", "X_ref", "X_mars", "Phi", "C", "u_ref", "u_true",
                                               "rho_ref")}
    return replace(geo, **cut)


def roll_rate_bounds(setup: Setup, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, rates_deg_s,
                     samples: int, zero_q: bool = False) -> np.ndarray:
    """1-sigma CRLB (arcsec) of the ``roll`` variant after ``samples`` samples from N0, with the
    camera rolling at each rate of ``rates_deg_s`` (R, 3): the same arc and prior
    (:func:`opnav.approach.scenario.with_roll_rate`), every rate in one batched recursion."""
    n = setup.segments.N0 + samples
    if n >= geo.t.shape[0]:
        raise ValueError(f"roll_rate_bounds: {samples} samples after N0 need an arc of {n} samples, "
                         f"the geometry has {geo.t.shape[0] - 1}")
    g = _head(geo, n)
    Rv = Rvar[:n + 1]
    geos = [sc.with_roll_rate(g, r) for r in rates_deg_s]
    wins = _window(g, Rv, zero_q)
    P = _start_covariances(g, wins.slice(0, setup.segments.N0), "roll")[-1]
    N0 = setup.segments.N0
    B = len(geos)
    c = crlb.crlb_curves(np.broadcast_to(g.Phi[N0:], (B, n + 1 - N0, 6, 6)), np.stack([x.C[N0:] for x in geos]),
                         np.broadcast_to(wins.Rvar[N0:], (B, n + 1 - N0, 3)), wins.Q,
                         np.stack([x.u_true[N0:] for x in geos]), np.broadcast_to(P, (B, 6, 6)),
                         sc.rad(theta_arcsec), setup.crlb_prior_sigma_rad)
    return sc.arcsec(c[:, -1])


def rate_to_target(setup: Setup, geo: sc.Geometry, Rvar: np.ndarray, theta_arcsec, samples: int,
                   target_arcsec: float, bracket_deg_s, iterations: int = 40) -> float:
    """The smallest roll rate (deg/s) at which the bound of both tx and ty after ``samples``
    samples from N0 is at most ``target_arcsec``: bisection on log(rate) inside ``bracket_deg_s``
    (the bound falls with the rate there); NaN when even the upper end does not reach it."""
    lo, hi = (float(x) for x in bracket_deg_s)

    def worst(rate):
        return float(roll_rate_bounds(setup, geo, Rvar, theta_arcsec, [rate], samples)[0, :2].max())

    if worst(hi) > target_arcsec:
        return float("nan")
    if worst(lo) <= target_arcsec:
        return lo
    for _ in range(iterations):
        mid = float(np.sqrt(lo * hi))
        lo, hi = (lo, mid) if worst(mid) <= target_arcsec else (mid, hi)
    return hi


#: points of the roll-rate grid (log-spaced over roll_rate_study.search_deg_s): 8 per decade over 0.001-20 deg/s
ROLL_GRID_POINTS = 36


@dataclass(frozen=True)
class RollRateBounds:
    """:func:`roll_rate_study`: the configured rates of ``roll_rate_study.rates_deg_s`` (deg/s) with
    the bound (arcsec, (R, 3)) after ``samples`` samples and after all the data
    (``total_samples``; with Q and Q = 0); the log-log slope of the all-data bound against the
    rate; the rate reaching ``target_arcsec`` within ``samples`` (NaN: none in the bracket); the
    bound after ``samples`` on a log grid over the searched bracket; the configured roll rate."""

    rates_deg_s: np.ndarray
    samples: int
    total_samples: int
    grid_rates_deg_s: np.ndarray
    bound_grid_arcsec: np.ndarray
    bound_at_samples_arcsec: np.ndarray
    bound_all_arcsec: np.ndarray
    bound_all_q0_arcsec: np.ndarray
    slope_all: float
    rate_to_target_deg_s: float
    target_arcsec: float
    config_rate_deg_s: float


def roll_rate_study(setup: Setup, samples: int, target_arcsec: float) -> RollRateBounds:
    """The roll rows' dependence on the roll rate (headline case): the bound of tx, ty after
    ``samples`` samples and after all the data, with and without process noise, at each rate
    of ``roll_rate_study.rates_deg_s``; the log-log slope of the all-data bound against the
    rate; the rate that brings the bound to ``target_arcsec`` within ``samples`` samples; and the
    bound after ``samples`` on a log grid of :data:`ROLL_GRID_POINTS` rates over the searched
    bracket (``grid_rates_deg_s``, ``bound_grid_arcsec``)."""
    case = cases.headline_case(setup)
    total = setup.segments.data_samples
    geo = sc.build_geometry(setup, "roll", n=setup.segments.N0 + max(samples, total))  # the arc may be shorter
    Rvar = geo.measurement_variance(case.sigma3_px)
    rates = np.asarray(setup.roll_rate_study.rates_deg_s, float)
    at_n = roll_rate_bounds(setup, geo, Rvar, case.truth_arcsec, rates, samples)
    at_all = roll_rate_bounds(setup, geo, Rvar, case.truth_arcsec, rates, total)
    at_all0 = roll_rate_bounds(setup, geo, Rvar, case.truth_arcsec, rates, total, zero_q=True)
    slope = float(np.polyfit(np.log(rates), np.log(at_all[:, :2].max(1)), 1)[0])
    rate = rate_to_target(setup, geo, Rvar, case.truth_arcsec, samples, target_arcsec,
                          setup.roll_rate_study.search_deg_s)
    # the bound after ``samples`` on a log grid over the searched bracket (issue 54: the claims
    # scorer reads the rate at which it reaches the plan's target from these points)
    grid = np.geomspace(*setup.roll_rate_study.search_deg_s, ROLL_GRID_POINTS)
    at_grid = roll_rate_bounds(setup, geo, Rvar, case.truth_arcsec, grid, samples)
    return RollRateBounds(rates_deg_s=rates, samples=samples, total_samples=total, grid_rates_deg_s=grid,
                          bound_grid_arcsec=at_grid, bound_at_samples_arcsec=at_n, bound_all_arcsec=at_all,
                          bound_all_q0_arcsec=at_all0, slope_all=slope, rate_to_target_deg_s=rate,
                          target_arcsec=target_arcsec, config_rate_deg_s=setup.roll.rate_deg_s)
