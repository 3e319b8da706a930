"""Out-of-sample filter tuning of paper B's EKF (bearing-noise scale and update
iterations), chosen on runs of a separate random stream.

Description
-----------
The Monte Carlo's runs use ``SeedSequence([landing.mc.base_seed, i])``; the
tuning runs use ``SeedSequence([landing.tuning.base_seed, i])``, ``i <
landing.tuning.n_runs``, a stream no reported run shares, so the NEES of the
300 reported runs is held-out evidence of consistency.

For each camera scenario and each candidate ``(meas_noise_scale, iterations)``
of ``landing.tuning.candidates`` the tuning runs are flown with
``landing.tuning.method``; a candidate is *consistent* when the mean position
and velocity NEES (over runs and filter times, 3 dof each) lie in the 95 %
band of an ``n_runs`` mean (``montecarlo.nees_band``). The choice is the
consistent candidate with the smallest scale (then the fewest iterations):
the least inflated noise model that is still honest about its errors; if none
is consistent, the smallest scale that is not overconfident (both NEES at most
the band's upper end: an underconfident filter is the safe side), flagged
(``chosen_consistent`` False).
One tuning serves both camera scenarios (one filter): the smallest scale that
meets the best tier in every scenario. :func:`tuning_report` flies and
chooses; ``config_matches`` says whether the configured ``landing.filter`` is
the choice (the pipeline checks and reports it; it does not change the config:
the Monte Carlo is flown with the config).

Retuned variant (:func:`retune`, :func:`heldout`): the paper tuning above is the flown
default; beside it, per camera scenario and on the tuning runs alone, the bearing-noise
scale whose mean position and velocity NEES lie closest to the band's centre (the larger
of the two log distances, :func:`distance_to_centre`): the candidates at the chosen
iterations, then ``landing.tuning.retune_points`` log-spaced scales between the best
candidate's neighbours. :func:`heldout` flies that scale on the Monte Carlo's own runs (the
held-out evidence) and reads its NEES beside the paper tuning's; nothing else is flown
with it. One scale multiplies the filter's bearing noise only, so it moves the position
and velocity NEES together, and a mean over runs follows its largest runs: the tuning
rows keep the median and the largest run's NEES to show how far the errors are from the
Gaussian the filter assumes.
"""

from __future__ import annotations

import math

import numpy as np

from opnav.landing.setup import Setup, Tuning

__all__ = ["tuning_report", "tuning_rows", "choose", "tuning_row", "distance_to_centre", "retune", "heldout", "errors",
           "retuned_record"]


def _tiers(rows_by_scn: dict[str, list[dict]]) -> dict:
    """The candidate (scale, iterations) chosen jointly over scenarios: per tier
    (consistent, then not overconfident) the smallest scale, then fewest
    iterations, meeting it in every scenario; else the smallest worst NEES."""
    cands = [(r["meas_noise_scale"], r["iterations"]) for r in next(iter(rows_by_scn.values()))]
    by = {c: [next(r for r in rows if (r["meas_noise_scale"], r["iterations"]) == c)
              for rows in rows_by_scn.values()] for c in cands}
    for tier in ("consistent", "not_overconfident"):
        ok = [c for c in cands if all(r[tier] for r in by[c])]
        if ok:
            return {"meas_noise_scale": min(ok)[0], "iterations": min(ok)[1], "tier": tier}
    c = min(cands, key=lambda c: (max(max(r["nees_pos"], r["nees_vel"]) for r in by[c]),) + c)
    return {"meas_noise_scale": c[0], "iterations": c[1], "tier": "smallest worst NEES"}


def choose(rows: list[dict]) -> dict:
    """The choice for one scenario (:func:`_tiers` of that scenario alone)."""
    return _tiers({"one": rows})


def tuning_rows(setup: Setup, tuning: Tuning) -> list[dict]:
    """Fly the tuning runs of one scenario (``setup``: its landing setup) for every candidate of
    ``tuning`` (``landing.tuning``): one :func:`tuning_row` each."""
    if int(tuning.base_seed) == int(setup.mc.base_seed):
        raise ValueError("landing.tuning.base_seed must differ from landing.mc.base_seed "
                         "(the tuning runs must not be the reported runs)")
    return [tuning_row(setup, tuning, scale, iters) for scale, iters in tuning.candidates]


def tuning_row(setup: Setup, tuning: Tuning, scale: float, iters: int) -> dict:
    """The tuning runs (``landing.tuning``'s stream, ``n_runs``, ``method``) flown with the
    filter's bearing-noise scale ``scale`` and ``iters`` update iterations: the mean position
    and velocity NEES, whether both lie in the band (``consistent``) or at least not above it
    (``not_overconfident``), the median and largest run's position NEES, and the median
    touchdown and last-landmark position errors (m)."""
    from opnav.landing.montecarlo import nees_band, per_run_stats, run_chunk

    n = int(tuning.n_runs)
    lo, hi = nees_band(n, 3, 0.95)
    cfg = setup.with_filter(meas_noise_scale=float(scale), iterations=int(iters)).with_seed(tuning.base_seed)
    st = per_run_stats(run_chunk(cfg, tuning.method, range(n), pick_ratio=False))
    npos, nvel = float(st["mean_nees_pos"].mean()), float(st["mean_nees_vel"].mean())
    return {"meas_noise_scale": float(scale), "iterations": int(iters), "nees_pos": npos, "nees_vel": nvel,
            "nees_pos_run_median": float(st["mean_nees_pos"].median()),
            "nees_pos_run_max": float(st["mean_nees_pos"].max()),
            "consistent": bool(lo <= npos <= hi and lo <= nvel <= hi),
            "not_overconfident": bool(npos <= hi and nvel <= hi),
            "final_pos_err_m_median": float(st["final_pos_err_m"].median()),
            "lastlm_pos_err_m_median": (float(st["lastlm_pos_err_m"].median())
                                        if "lastlm_pos_err_m" in st else math.nan)}


def distance_to_centre(row: dict, centre: float) -> float:
    """How far a tuning row's NEES is from ``centre`` (the band's centre): the larger of
    ``|ln(nees_pos / centre)|`` and ``|ln(nees_vel / centre)|`` (a factor, either way, on
    either state)."""
    return max(abs(math.log(row["nees_pos"] / centre)), abs(math.log(row["nees_vel"] / centre)))


def retune(setup: Setup, tuning: Tuning, rows: list[dict], iterations: int) -> dict:
    """The retuned bearing-noise scale of one scenario, on its tuning runs only (module
    docstring): among ``rows`` (:func:`tuning_rows`) at ``iterations``, the candidate
    closest to the band's centre (:func:`distance_to_centre`; ties: the smaller scale), then
    ``tuning.retune_points`` scales log-spaced strictly between its neighbouring
    candidates (at the ends half or twice the candidate, never below 1: the filter's noise
    is not assumed smaller than the true one), flown; the closest of
    all. Returns that row, its ``distance``, the ``centre``, ``in_band`` (both NEES in the
    tuning runs' band) and every row ``evaluated`` in scale order."""
    from opnav.landing.montecarlo import nees_band

    lo, hi = nees_band(int(tuning.n_runs), 3, 0.95)
    centre = 0.5 * (lo + hi)
    rows = sorted((r for r in rows if int(r["iterations"]) == int(iterations)), key=lambda r: r["meas_noise_scale"])
    if not rows:
        raise ValueError(f"landing.tuning.candidates: no candidate with {iterations} iterations to retune from")

    def best(rs):
        return min(rs, key=lambda r: (distance_to_centre(r, centre), r["meas_noise_scale"]))

    b = best(rows)
    scales = [r["meas_noise_scale"] for r in rows]
    i = scales.index(b["meas_noise_scale"])
    left = scales[i - 1] if i > 0 else b["meas_noise_scale"] / 2.0
    right = scales[i + 1] if i + 1 < len(scales) else b["meas_noise_scale"] * 2.0
    k = int(tuning.retune_points)
    new = [float(x) for x in np.geomspace(max(left, 1.0), right, k + 2)[1:-1]] if k > 0 else []
    rows = rows + [tuning_row(setup, tuning, x, iterations) for x in new if x not in scales]
    rows.sort(key=lambda r: r["meas_noise_scale"])
    b = best(rows)
    return {**b, "distance": distance_to_centre(b, centre), "centre": centre, "band": [lo, hi],
            "in_band": bool(lo <= b["nees_pos"] <= hi and lo <= b["nees_vel"] <= hi),
            "evaluated": [{k_: r[k_] for k_ in ("meas_noise_scale", "nees_pos", "nees_vel")} for r in rows]}


def heldout(setup: Setup, method: str, n_runs: int, meas_noise_scale: float, iterations: int) -> dict:
    """``method`` flown on the Monte Carlo's own runs ``0..n_runs-1`` (``setup``'s
    ``mc.base_seed``: never the tuning runs) with the filter's bearing-noise scale and
    iterations set to the given ones: ``montecarlo.nees_consistency`` of those runs and their
    median last-landmark and touchdown position errors (m)."""
    from opnav.landing.montecarlo import nees_consistency, run_chunk

    cfg = setup.with_filter(meas_noise_scale=float(meas_noise_scale), iterations=int(iterations))
    d = run_chunk(cfg, method, range(int(n_runs)), pick_ratio=False)
    return {**nees_consistency(d), **errors(d)}


def errors(data: dict) -> dict:
    """Median last-landmark and touchdown position errors (m) of a Monte Carlo."""
    from opnav.landing.montecarlo import per_run_stats

    st = per_run_stats(data)
    return {"lastlm_pos_err_m_median": (float(st["lastlm_pos_err_m"].median())
                                        if "lastlm_pos_err_m" in st else math.nan),
            "final_pos_err_m_median": float(st["final_pos_err_m"].median())}


def tuning_report(scenarios: dict[str, Setup], tuning: Tuning) -> dict:
    """:func:`tuning_rows` of every camera scenario (name -> its landing setup), the choice per scenario and the one tuning for all (:func:`_tiers`:
    the smallest scale meeting the best tier in every scenario), whether the
    configured ``landing.filter`` (the same in every scenario) is that choice, and per
    scenario the retuned scale (:func:`retune`, at the chosen iterations; ``retuned``)."""
    from opnav.landing.montecarlo import nees_band

    rows = {s: tuning_rows(c, tuning) for s, c in scenarios.items()}
    joint = _tiers(rows)
    retuned = {s: retune(c, tuning, rows[s], joint["iterations"]) for s, c in scenarios.items()}
    f = next(iter(scenarios.values())).filter
    n = int(tuning.n_runs)
    return {"base_seed": int(tuning.base_seed), "n_runs": n, "method": tuning.method,
            "band": list(nees_band(n, 3, 0.95)), "scenarios": {s: {"candidates": r, "chosen": choose(r)}
                                                              for s, r in rows.items()},
            "chosen": joint, "retuned": retuned,
            "configured": {"meas_noise_scale": float(f.meas_noise_scale), "iterations": int(f.iterations)},
            "config_matches": (float(f.meas_noise_scale) == joint["meas_noise_scale"]
                               and int(f.iterations) == joint["iterations"])}


def retuned_record(tuning: dict, scenario: str, setup: Setup, method: str, n_runs: int,
                   paper_heldout: dict) -> dict:
    """The paper tuning and the retuned scale of ``scenario`` side by side on the held-out
    runs: ``tuning`` is :func:`tuning_report`'s output, ``paper_heldout`` the Monte Carlo's own
    ``nees_consistency`` and :func:`errors` of ``method`` (flown with the configured filter);
    the retuned scale is flown by :func:`heldout` on the same ``n_runs`` runs. Each side holds
    its scale, iterations, the tuning runs' NEES (mean, median and largest run in position;
    NaN where the configured filter is not a candidate) and the held-out numbers."""
    def tuning_side(row):
        keys = ("nees_pos", "nees_vel", "nees_pos_run_median", "nees_pos_run_max")
        return {f"tuning_{k}": (float(row[k]) if row else math.nan) for k in keys}

    conf = tuning["configured"]
    cands = tuning["scenarios"][scenario]["candidates"]
    row = next((c for c in cands if c["meas_noise_scale"] == conf["meas_noise_scale"]
                and c["iterations"] == conf["iterations"]), None)
    r = tuning["retuned"][scenario]
    return {"scenario": scenario, "method": method, "n_runs": int(n_runs), "tuning_n_runs": int(tuning["n_runs"]),
            "tuning_band": list(tuning["band"]),
            "paper": {"meas_noise_scale": float(conf["meas_noise_scale"]), "iterations": int(conf["iterations"]),
                      **tuning_side(row), **paper_heldout},
            "retuned": {"meas_noise_scale": float(r["meas_noise_scale"]), "iterations": int(r["iterations"]),
                        **tuning_side(r), "tuning_in_band": bool(r["in_band"]),
                        **heldout(setup, method, n_runs, r["meas_noise_scale"], r["iterations"])}}
