"""Navigation error against arc length, and whether tz affects navigation (issue 54, items 6-7).

Description
    Paper A states the navigation error after compensation ("from 100 km to within 20 km", A-C7)
    without the arc it was measured on, nor its error rule. :func:`nav_floor_by_arc` measures
    the error of one scenario variant and EM scheme (config ``nav_floor``: the best variant of
    the headline claims) against the arc length: the headline case over ``n_seeds`` seeds, one
    arc of the longest length, the segment-wise EM-EKF over it (:func:`opnav.approach.cases.em_segments`),
    and for each arc length T the estimate of the segment ending at T (it used the data up to T
    only) compensated over the arc 0..T. Beside it the filter given the true theta (a filter's
    floor, not an information bound) and the theta = 0 filter. The filtered error at a sample
    does not depend on later samples, so one filter run over the longest arc serves every
    shorter one. Two rules per arc: the plan's (RMS of ``|r_hat - r_true|`` over the last
    ``nav_error.last_fraction`` of the arc, :func:`opnav.approach.cases.rms_last`) and the last
    sample's; mean (and median, sd) over seeds.

    :func:`tz_nav_effect` measures paper A's "the z-axis deviation does not affect navigation"
    (sec. 3): the same seeds' measurements made with the case's tz and with tz = 0 (everything
    else equal, paired), each filtered with the true (tx, ty) and tz = 0 (the compensation a
    filter that cannot estimate tz applies); the navigation errors by the plan's rule.
Units: s, km, arcsec.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from opnav.core.tables import JSON_SKIP

from . import cases
from . import scenario as sc
from .ekf import run_filter
from .labels import variant_label
from .setup import Setup

#: seeds per filter pass (memory: a 16,000-sample arc's covariances are ~10 MB a seed)
SEED_CHUNK = 5


def arc_samples(setup: Setup, arcs_s) -> list[int]:
    """The samples of each arc, ``round(arc_s / dt_s)``; ValueError naming
    ``approach.nav_floor.arcs_s`` for an arc that does not reach past N0 (no data after it)."""
    N0, dt = setup.segments.N0, setup.dt_s
    out = []
    for a in arcs_s:
        n = int(round(a / dt))
        if n <= N0:
            raise ValueError(f"approach.nav_floor.arcs_s: {a:g} s ({n} samples of {dt:g} s) ends before the EM's "
                             f"first data (N0 = {N0} samples): use arcs longer than {N0 * dt:g} s")
        out.append(n)
    return out


def arcs_samples_of(setup: Setup) -> list[int]:
    """:func:`arc_samples` of the configured ``nav_floor``."""
    return arc_samples(setup, setup.nav_floor.arcs_s)


def growing_windows(N0: int, N: int, ends) -> list[tuple[int, int]]:
    """Growing windows (N0, b) every ``N`` samples up to the last of ``ends``, plus a window ending
    at each of ``ends`` (an arc's end need not be a multiple of N after N0), increasing."""
    last = max(ends)
    return [(N0, b) for b in sorted(set(range(N0 + N, last + 1, N)) | {int(e) for e in ends})]


def _scheme(scheme: str) -> tuple[str, str]:
    """``growing-squarem`` -> (growing, squarem)."""
    mode, _, method = scheme.rpartition("-")
    if mode != "growing":
        raise ValueError(f"approach.nav_floor.scheme: {scheme!r} is not a growing-window scheme (growing-<method>): "
                         "only a growing window's estimate at an arc's end rests on that arc's data")
    return mode, method


@dataclass(frozen=True)
class NavFloorRow:
    """One arc length of :func:`nav_floor_by_arc` (km; mean over seeds, with median and sd): the
    compensated filter's error by the plan's rule (``nav_err_km_rule``, RMS over the last
    ``nav_error.last_fraction`` of the arc) and at the arc's last sample (``*_last``), the same of
    the filter given the true theta (``true_theta_km_*``: a filter's floor) and of the theta = 0
    filter (``before_km_*``), and the estimate's seed mean (tx, ty), arcsec. The field order is
    A-X7's columns (the first seven: the claims engineer's contract, issue 54)."""

    arc_s: float
    variant: str
    nav_err_km_rule: float
    nav_err_km_last: float
    true_theta_km_rule: float
    true_theta_km_last: float
    n_seeds: int
    samples: int
    nav_err_km_rule_median: float
    nav_err_km_rule_sd: float
    nav_err_km_last_median: float
    nav_err_km_last_sd: float
    true_theta_km_rule_median: float
    true_theta_km_rule_sd: float
    true_theta_km_last_median: float
    true_theta_km_last_sd: float
    before_km_rule: float
    before_km_rule_median: float
    before_km_rule_sd: float
    before_km_last: float
    before_km_last_median: float
    before_km_last_sd: float
    est_x_mean_arcsec: float
    est_y_mean_arcsec: float


@dataclass(frozen=True)
class NavFloor:
    """:func:`nav_floor_by_arc`: the A-T1 row label of its scheme (``variant``), the scenario and
    scheme, the headline case's seeds and the rule's fraction of the arc (``last_fraction``), one
    :class:`NavFloorRow` per arc and the per-seed errors (``per_seed``: ``after_rule`` ... (S, arcs),
    km). Its words (``rule``) are the report's."""

    variant: str
    scenario: str
    scheme: str
    n_seeds: int
    last_fraction: float
    rows: tuple[NavFloorRow, ...]
    per_seed: dict[str, list] = field(default_factory=dict, repr=False)


def nav_floor_by_arc(setup: Setup, variant: str, scheme: str, arcs_s, log=None) -> NavFloor:
    """Navigation error against arc length (module docstring): one :class:`NavFloorRow` per arc."""
    mode, method = _scheme(scheme)
    ns = arc_samples(setup, arcs_s)
    nmax = max(ns)
    N0 = setup.segments.N0
    windows = growing_windows(N0, setup.growing.N, ns)
    ends = [b for (_, b) in windows]
    # the EM's settings of the growing scheme (growing.M maps per window) on an arc of nmax samples
    sx = setup.replace(segments=replace(setup.segments, mode="growing", N=setup.growing.N, M=setup.growing.M,
                                        L=len(windows)))
    geo = sc.build_geometry(sx, variant, n=nmax)
    case = cases.headline_case(setup)
    frac = setup.nav_last_fraction
    seeds = list(range(setup.n_seeds))
    per = {k: np.empty((len(seeds), len(ns))) for k in
           ("after_rule", "after_last", "true_rule", "true_last", "before_rule", "before_last")}
    theta_arc = np.empty((len(seeds), len(ns), 3))
    for c0 in range(0, len(seeds), SEED_CHUNK):
        chunk = seeds[c0:c0 + SEED_CHUNK]
        sl = slice(c0, c0 + len(chunk))
        d = cases.prepare_cases(sx, variant, [case], chunk, geo=geo)
        th_seg = [tr.theta[-1] for *_, tr in cases.em_segments(sx, variant, d, method, d.theta0.copy(), windows)]
        err_true = np.linalg.norm(d.f_true.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
        for j, n in enumerate(ns):
            th = th_seg[ends.index(n)]
            theta_arc[sl, j] = sc.arcsec(th)
            f = run_filter(d.z, th, d.dx0, geo.P0, d.win, predicted=False)
            err = np.linalg.norm(f.xf[:, :n + 1, :3] - geo.dx_true[None, :n + 1, :3], axis=-1)
            for k, e in (("after", err), ("true", err_true[:, :n + 1]), ("before", d.err_before[:, :n + 1])):
                per[f"{k}_rule"][sl, j] = cases.rms_last(e, frac)
                per[f"{k}_last"][sl, j] = e[:, n]
        if log:
            log.info("nav floor %s %s: seeds %s done", variant, scheme, chunk)
    label = variant_label(variant, method, mode)
    rows = []
    for j, n in enumerate(ns):
        stats = {}
        for k, name in (("after", "nav_err_km"), ("true", "true_theta_km"), ("before", "before_km")):
            for r in ("rule", "last"):
                x = per[f"{k}_{r}"][:, j]
                stats[f"{name}_{r}"] = float(x.mean())
                stats[f"{name}_{r}_median"] = float(np.median(x))
                stats[f"{name}_{r}_sd"] = float(x.std(ddof=1)) if x.size > 1 else math.nan
        ex, ey = (float(v) for v in theta_arc[:, j, :2].mean(0))
        rows.append(NavFloorRow(arc_s=float(n * setup.dt_s), variant=label, samples=int(n), n_seeds=len(seeds),
                                est_x_mean_arcsec=ex, est_y_mean_arcsec=ey, **stats))
    return NavFloor(variant=label, scenario=variant, scheme=scheme, n_seeds=len(seeds), last_fraction=frac,
                    rows=tuple(rows), per_seed={k: v.tolist() for k, v in per.items()})


@dataclass(frozen=True)
class TzNavEffect:
    """:func:`tz_nav_effect`: the navigation error (km, seed means) with the headline case's tz and
    with tz = 0, the paired difference's mean and sd (km), tz (arcsec), the seeds, the variant and
    the rule's fraction of the arc; ``rule``: its words (the report's, :mod:`opnav.report.approach.text`)."""

    nav_err_km_tz_on: float
    nav_err_km_tz_off: float
    diff_km_mean: float
    diff_km_sd: float
    tz_arcsec: float
    n_seeds: int
    variant: str
    last_fraction: float = field(metadata=JSON_SKIP)
    rule: str = ""


def tz_nav_effect(setup: Setup, variant: str) -> TzNavEffect:
    """Navigation error with the headline case's tz bias on and off (module docstring): paired
    seeds, the filter given the true (tx, ty) and tz = 0, over the profile's arc by the plan's
    rule."""
    geo = sc.build_geometry(setup, variant)
    case = cases.headline_case(setup)
    seeds = list(range(setup.n_seeds))
    truth = np.asarray(case.truth_arcsec, float)
    comp = np.broadcast_to(sc.rad([truth[0], truth[1], 0.0]), (len(seeds), 3))
    errs = []
    for tz in (truth[2], 0.0):  # on, off
        Rvar, z, dx0 = cases.simulate_case(setup, geo, case, seeds, truth_arcsec=(truth[0], truth[1], tz))
        f = run_filter(z, comp, dx0, geo.P0, geo.window(Rvar), predicted=False)
        err = np.linalg.norm(f.xf[:, :, :3] - geo.dx_true[None, :, :3], axis=-1)
        errs.append(cases.rms_last(err, setup.nav_last_fraction))
    on, off = errs
    diff = on - off
    return TzNavEffect(nav_err_km_tz_on=float(on.mean()), nav_err_km_tz_off=float(off.mean()),
                       diff_km_mean=float(diff.mean()), diff_km_sd=float(diff.std(ddof=1)) if diff.size > 1 else math.nan,
                       tz_arcsec=float(truth[2]), n_seeds=len(seeds), variant=variant,
                       last_fraction=setup.nav_last_fraction)
