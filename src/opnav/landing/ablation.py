"""One-value ablations of paper B (B-X2): camera field of view and observations
per landmark (SPEC B.2, Fig. 3 strategy).

Description
-----------
A sweep changes ONE config value of the ``landing`` section and flies the same
runs as the main Monte Carlo: run ``i`` draws its initial error, IMU and pixel
noise from ``SeedSequence([base_seed, i])`` (``opnav.landing.descent``), so at
the configured (default) value ablation run ``i`` IS main run ``i``, and the
values are compared on paired draws. :data:`SWEEPS` maps a sweep name to the
config key it changes; :func:`with_value` returns the modified config;
:func:`sweep_table` reduces the per-value Monte-Carlo results to one row per
(value, method) with the B-T3 statistics (``montecarlo.summary_table``):
final and RMS position (m) and velocity (m/s) error norms as mean and 3-sigma
(three sample standard deviations over the runs), mean position/velocity NEES,
landmarks used per run, median planning-call wall/CPU time (us), planning
calls and the share of them that chose no landmark (%, the planner's ideal
point had no detected landmark among its nearest, ``opnav.landing.planner``).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pandas as pd

from opnav.landing.montecarlo import summary_table

__all__ = ["SWEEPS", "with_value", "value_label", "parse_value", "sweep_table", "ABLATION_COLUMNS"]

#: sweep name -> (config key in landing.ablation, landing sub-section, key there, unit, type)
SWEEPS: dict[str, tuple[str, str, str, str, type]] = {
    "fov": ("fov_deg", "camera", "fov_deg", "deg", float),
    "obs": ("obs_per_landmark", "filter", "obs_per_landmark", "", int),
}

#: summary columns kept in the ablation tables (names of montecarlo.summary_table)
ABLATION_COLUMNS = (
    "n_runs",
    "final_pos_err_m_mean", "final_pos_err_m_3sigma", "rms_pos_err_m_mean", "rms_pos_err_m_3sigma",
    "final_vel_err_mps_mean", "final_vel_err_mps_3sigma", "rms_vel_err_mps_mean",
    "rms_vel_err_mps_3sigma", "final_pos_err_m_median", "converged_runs_pct",
    "mean_nees_pos", "mean_nees_vel", "landmarks_per_run", "plan_calls", "no_pick_pct",
    "median_plan_time_us", "median_plan_cpu_us",
)


def _sweep(name: str) -> tuple[str, str, str, str, type]:
    if name not in SWEEPS:
        raise ValueError(f"unknown ablation sweep {name!r}; available: {sorted(SWEEPS)}")
    return SWEEPS[name]


def value_label(name: str, value) -> str:
    """The value as it appears in file names (``60``, ``22.5``, ``3``)."""
    typ = _sweep(name)[4]
    return f"{typ(value):g}" if typ is float else str(int(value))


def parse_value(name: str, label: str, values) -> float | int:
    """The configured value whose :func:`value_label` is ``label``."""
    for v in values:
        if value_label(name, v) == label:
            return _sweep(name)[4](v)
    raise ValueError(f"landing.ablation.{_sweep(name)[0]}: no value {label!r} in {list(values)}")


def with_value(landing_cfg: dict, name: str, value) -> dict:
    """A deep copy of the ``landing`` config with the swept key set to ``value``
    (everything else, seeds included, unchanged)."""
    _, section, key, _, typ = _sweep(name)
    if section not in landing_cfg or key not in landing_cfg[section]:
        raise KeyError(f"landing.{section}.{key} missing from the config (ablation {name!r})")
    out = copy.deepcopy(landing_cfg)
    out[section][key] = typ(value)
    return out


def default_value(landing_cfg: dict, name: str):
    """The configured value of the swept key (the main Monte Carlo's)."""
    _, section, key, _, typ = _sweep(name)
    return typ(landing_cfg[section][key])


def sweep_table(name: str, data: dict[float | int, dict[str, dict]],
                converged_pos_err_m: float = 100.0) -> pd.DataFrame:
    """One row per (swept value, method): see the module docstring.

    ``data[value][method]`` is a gathered Monte-Carlo dict
    (``montecarlo.gather``). Rows are ordered by value, then method order.
    """
    col = _sweep(name)[0]
    rows = []
    for value in sorted(data):
        df = summary_table(data[value], converged_pos_err_m=converged_pos_err_m)
        for rec in df.to_dict("records"):
            row = {col: value, "method": rec["method"]}
            row.update({k: rec.get(k, math.nan) for k in ABLATION_COLUMNS})
            idx = np.asarray(data[value][rec["method"]]["plan_index"])
            row["no_pick_pct"] = float(100.0 * np.mean(idx < 0)) if idx.size else math.nan
            rows.append(row)
    out = pd.DataFrame(rows)
    out["n_runs"] = out["n_runs"].astype(np.int64)
    return out
