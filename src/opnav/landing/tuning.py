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
"""

from __future__ import annotations

import copy
import math

__all__ = ["tuning_report", "tuning_rows", "choose"]


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


def tuning_rows(landing_cfg: dict, tuning_cfg: dict) -> list[dict]:
    """Fly the tuning runs of one scenario (``landing_cfg``: its ``landing``
    config) for every candidate of ``tuning_cfg`` (``landing.tuning``); per
    candidate the mean position and velocity NEES, whether both lie in the band
    (``consistent``) or at least not above it (``not_overconfident``), and the
    median touchdown and last-landmark position errors (m)."""
    from opnav.landing.montecarlo import nees_band, per_run_stats, run_chunk

    if int(tuning_cfg["base_seed"]) == int(landing_cfg["mc"]["base_seed"]):
        raise ValueError("landing.tuning.base_seed must differ from landing.mc.base_seed "
                         "(the tuning runs must not be the reported runs)")
    n = int(tuning_cfg["n_runs"])
    lo, hi = nees_band(n, 3, 0.95)
    rows = []
    for scale, iters in tuning_cfg["candidates"]:
        cfg = copy.deepcopy(landing_cfg)
        cfg["filter"].update(meas_noise_scale=float(scale), iterations=int(iters))
        cfg["mc"] = {**cfg["mc"], "base_seed": int(tuning_cfg["base_seed"])}
        st = per_run_stats(run_chunk(cfg, tuning_cfg["method"], range(n), pick_ratio=False))
        npos, nvel = float(st["mean_nees_pos"].mean()), float(st["mean_nees_vel"].mean())
        rows.append({"meas_noise_scale": float(scale), "iterations": int(iters),
                     "nees_pos": npos, "nees_vel": nvel,
                     "consistent": bool(lo <= npos <= hi and lo <= nvel <= hi),
                     "not_overconfident": bool(npos <= hi and nvel <= hi),
                     "final_pos_err_m_median": float(st["final_pos_err_m"].median()),
                     "lastlm_pos_err_m_median": (float(st["lastlm_pos_err_m"].median())
                                                 if "lastlm_pos_err_m" in st else math.nan)})
    return rows


def tuning_report(scenario_cfgs: dict[str, dict], tuning_cfg: dict) -> dict:
    """:func:`tuning_rows` of every camera scenario (name -> its ``landing``
    config), the choice per scenario and the one tuning for all (:func:`_tiers`:
    the smallest scale meeting the best tier in every scenario), and whether the
    configured ``landing.filter`` (the same in every scenario) is that choice."""
    from opnav.landing.montecarlo import nees_band

    rows = {s: tuning_rows(c, tuning_cfg) for s, c in scenario_cfgs.items()}
    joint = _tiers(rows)
    f = next(iter(scenario_cfgs.values()))["filter"]
    n = int(tuning_cfg["n_runs"])
    return {"base_seed": int(tuning_cfg["base_seed"]), "n_runs": n, "method": tuning_cfg["method"],
            "band": list(nees_band(n, 3, 0.95)), "scenarios": {s: {"candidates": r, "chosen": choose(r)}
                                                              for s, r in rows.items()},
            "chosen": joint,
            "configured": {"meas_noise_scale": float(f["meas_noise_scale"]), "iterations": int(f["iterations"])},
            "config_matches": (float(f["meas_noise_scale"]) == joint["meas_noise_scale"]
                               and int(f["iterations"]) == joint["iterations"])}
