"""Paper B in a parameter study (:mod:`opnav.studies`): per-run metrics of one method.

:func:`run_runs` flies the runs ``run_indices`` of ``method`` with a (study-modified)
``landing`` config (:func:`opnav.landing.montecarlo.run_chunk`; run ``i`` draws from
``SeedSequence([landing.mc.base_seed, i])`` only, so values and methods are paired) and
returns one row per run: the final and RMS error norms of position (m), velocity (m/s)
and attitude (deg) and the mean NEES (:func:`opnav.landing.montecarlo.per_run_stats`),
landmarks used, and per run the median wall / CPU time of a planning call (us; by replay
of recorded planning calls through the run's method, :func:`opnav.landing.timing.replay_own`,
apart from the filter's work: at most ``landing.timing.max_calls`` calls of the job, evenly
spaced over its runs' calls, so a run's median rests on about ``max_calls / runs`` calls and a
run with none is NaN) and the share of planning calls that chose no landmark (%). :func:`add_derived` adds
``converged_pct`` (100 if the final position error is below ``converged_pos_err_m``, else
0; its mean over runs is the converged share, as in B-T3).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from opnav.landing.montecarlo import MonteCarlo, per_run_stats, run_chunk
from opnav.landing.records import Replay
from opnav.landing.setup import Setup


def per_run_metrics(data: MonteCarlo, timing: Replay, method: str) -> pd.DataFrame:
    """One row per run of a chunk or gathered Monte Carlo (module docstring);
    ``timing``: the replay of its planning calls (``timing.replay_own``)."""
    from opnav.landing.timing_summary import per_run_median_us

    st = per_run_stats(data).reset_index()
    runs = st["run"].to_numpy()
    pr = np.asarray(data.plan_run)
    wall, cpu = per_run_median_us(timing, method), per_run_median_us(timing, method, "cpu")
    nopick = []
    for r in runs:
        idx = np.asarray(data.plan_index)[pr == r]
        nopick.append(float(100.0 * np.mean(idx < 0)) if idx.size else math.nan)
    st["median_plan_time_us"] = [wall.get(int(r), math.nan) for r in runs]
    st["median_plan_cpu_us"] = [cpu.get(int(r), math.nan) for r in runs]
    st["no_pick_pct"] = nopick
    return st


def run_runs(setup: Setup, method: str, run_indices) -> pd.DataFrame:
    """Fly ``run_indices`` with ``method`` (``setup``: the study value's landing setup); one row
    per run (module docstring). The replay budget is ``setup.timing.max_calls`` (0: every call)."""
    from opnav.landing.descent import build_scenario
    from opnav.landing.timing import replay_own

    max_calls = int(setup.timing.max_calls)
    data = run_chunk(setup, method, list(run_indices), pick_ratio=False)   # no study metric reads it
    df = per_run_metrics(data, replay_own(build_scenario(setup), data, method, max_calls), method)
    df.insert(1, "method", method)
    return df


def add_derived(runs: pd.DataFrame, converged_pos_err_m: float) -> pd.DataFrame:
    """``converged_pct`` per run (0 or 100) from the final position error."""
    out = runs.copy()
    out["converged_pct"] = np.where(out["final_pos_err_m"] < converged_pos_err_m, 100.0, 0.0)
    return out
