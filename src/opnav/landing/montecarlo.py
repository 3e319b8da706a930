"""Monte Carlo of the powered descent: chunks, gathering, and the B-T3 summary
(paper B sec. 3, Fig. 6-7; SPEC B.4).

Description
-----------
Run ``i`` of every method uses the random stream ``SeedSequence([base_seed,
i])`` only (``opnav.landing.descent.run_descents``), so the methods are paired
(same initial errors, IMU and pixel noise) and a run's result does not depend
on how runs are grouped into Snakemake jobs or batches. :func:`run_chunk`
flies a list of run indices (in batches of ``landing.mc.batch_size``) and
stacks the per-run arrays; :func:`summarize_run` is one run's
:func:`per_run_stats` row; :func:`gather` concatenates chunks
in run order; :func:`summary_table` builds B-T3.

Statistics (per method, over the runs): final (touchdown) and RMS (over time)
error norms of position (m), velocity (m/s) and attitude (deg, small-angle
``dtheta``), each as mean and ``3 sigma`` (three sample standard deviations),
and the position and velocity error at the last vision update (``lastvis_``:
the filter then coasts on the IMU to touchdown); the median
objective evaluations per call (the descent's count). Planning times come from
the replay of the recorded planning calls (``opnav.landing.timing``), not from
the descent: the median wall and CPU (``thread_time_ns``) time of a call (us)
on the configured and the alternative metric path, and each method's time
reduction against each other ``100 (1 - median_a / median_b)`` (%) on the same
replayed calls, with a paired bootstrap standard deviation
(``timing.time_reduction``).
"""

from __future__ import annotations

import math
import re

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd
# The descent (scipy, CasADi) and pandas are imported by the functions that use them:
# the workflow parses this module at start-up and the gather jobs only stack arrays.

from opnav.landing.timing import RECORD_KEYS   # numpy only

__all__ = ["yaw_convergence", "run_chunk", "stack_runs", "summarize_run", "last_update_index", "save", "load", "gather", "summary_table", "per_run_stats",
           "chunks", "chunk_label", "chunk_runs", "CHUNK_PATTERN",
           "same_pick_pct", "pick_quality"]

_PLAN = ("plan_ns", "plan_cpu_ns", "plan_evals", "plan_t", "plan_beta", "plan_index", "plan_edge",
         "plan_ratio", "plan_ns_alt", "plan_cpu_ns_alt") + RECORD_KEYS   # (+ planning inputs, replay)
_TRACKS = ("err_r", "err_v", "err_th_deg", "err_rpy_deg", "sig_r", "sig_v", "sig_th_deg",
           "sig_yaw_deg", "nees_r", "nees_v", "updated")


def chunks(n_runs: int, runs_per_job: int) -> list[list[int]]:
    """Run indices grouped into jobs of ``runs_per_job``."""
    if n_runs < 1 or runs_per_job < 1:
        raise ValueError("landing.mc.n_runs and runs_per_job must be >= 1")
    return [list(range(a, min(a + runs_per_job, n_runs))) for a in range(0, n_runs, runs_per_job)]


def chunk_label(run_indices) -> str:
    """A chunk's name from its (consecutive) run indices: ``[4, 5]`` -> ``"r0004-0005"``.

    Chunk files are named by the runs they hold, not by their position, so
    raising ``n_runs`` keeps every full chunk (same name, same runs) and only
    the new runs (and a formerly partial last chunk) are flown.
    """
    runs = [int(i) for i in run_indices]
    if not runs or runs != list(range(runs[0], runs[0] + len(runs))):
        raise ValueError(f"a chunk holds consecutive run indices, got {runs}")
    return f"r{runs[0]:04d}-{runs[-1]:04d}"


def chunk_runs(label: str) -> list[int]:
    """The run indices of a :func:`chunk_label` (inverse)."""
    m = re.fullmatch(r"r(\d{4,})-(\d{4,})", label)
    if not m or int(m.group(2)) < int(m.group(1)):
        raise ValueError(f"not a Monte-Carlo chunk label: {label!r} (expected e.g. 'r0000-0024')")
    return list(range(int(m.group(1)), int(m.group(2)) + 1))


#: Snakemake wildcard pattern of :func:`chunk_label`.
CHUNK_PATTERN = r"r[0-9]+-[0-9]+"


def run_chunk(landing_cfg: dict, method: str, run_indices, batch_size: int | None = None) -> dict:
    """Fly the runs ``run_indices`` with ``method``; stacked arrays (see module doc).

    Runs are flown in batches of ``batch_size`` (default ``landing.mc.batch_size``;
    0 = all runs as one batch); the numbers do not depend on it (to round-off)."""
    from opnav.landing.descent import run_descents
    from opnav.landing.scenario import build_scenario

    scn = build_scenario(landing_cfg)
    idx = [int(i) for i in run_indices]
    if batch_size is None:
        batch_size = int(landing_cfg.get("mc", {}).get("batch_size", 0))
    size = len(idx) if batch_size <= 0 else int(batch_size)
    runs = []
    for a in range(0, len(idx), max(size, 1)):
        runs.extend(run_descents(scn, method, idx[a:a + size]))
    return stack_runs(idx, runs, scn.truth.t)


def stack_runs(run_indices, runs: list[dict], t: np.ndarray) -> dict:
    """The per-run dicts of :func:`opnav.landing.descent.run_descents` as one
    chunk: tracks stacked (runs x ...), planning calls concatenated with their
    run index (``plan_run``)."""
    out = {"run_index": np.asarray(list(run_indices), np.int64), "t": np.asarray(t).copy()}
    for k in _TRACKS:
        out[k] = np.stack([r[k] for r in runs])
    for k in _PLAN:
        out[k] = np.concatenate([r[k] for r in runs]) if runs else np.zeros(0)
    out["plan_run"] = np.concatenate([np.full(len(r["plan_t"]), int(i), np.int64)
                                      for i, r in zip(run_indices, runs)]) if runs else np.zeros(0, np.int64)
    out["n_landmarks"] = np.array([r["n_landmarks"] for r in runs], np.int64)
    out["init_error"] = np.stack([r["init_error"] for r in runs])
    return out


def summarize_run(run: dict, run_index: int = 0) -> dict:
    """One run of :func:`opnav.landing.descent.run_descent`: its
    :func:`per_run_stats` row (final, last-vision and RMS error norms, mean
    NEES, landmarks used) plus the final yaw error (deg), the number of
    planning calls, their median time (us) and median evaluation count."""
    data = stack_runs([run_index], [run], run["t"])
    out = {k: (int(v) if k == "n_landmarks" else float(v))
           for k, v in per_run_stats(data).iloc[0].items()}
    out["final_yaw_err_deg"] = float(run["err_rpy_deg"][-1, 2])
    out["n_plans"] = int(len(run["plan_t"]))
    out["median_plan_time_us"] = _median_us(run["plan_ns"])
    out["median_plan_evals"] = float(np.median(run["plan_evals"])) if len(run["plan_evals"]) else math.nan
    return out


def save(path, data: dict, method: str) -> None:
    """Write a chunk or gathered result (``.npz``, atomically)."""
    from opnav.tables import atomic_target

    with atomic_target(path) as tmp:
        np.savez_compressed(tmp, method=np.array(method), **data)


def load(path) -> dict:
    """Read a :func:`save` file; a truncated or corrupt one raises
    :class:`opnav.snakeio.CorruptIntermediate` naming it and its rebuild command."""
    import zipfile

    from opnav.snakeio import corrupt_intermediate

    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except (zipfile.BadZipFile, EOFError, ValueError, OSError, KeyError) as exc:
        raise corrupt_intermediate(path, exc) from exc


def gather(parts: list[dict]) -> dict:
    """Concatenate chunk results in run-index order; checks for gaps/duplicates."""
    if not parts:
        raise ValueError("no Monte-Carlo chunks to gather")
    methods = {str(p["method"]) for p in parts if "method" in p}
    if len(methods) > 1:
        raise ValueError(f"chunks of different methods gathered together: {sorted(methods)}")
    idx = np.concatenate([p["run_index"] for p in parts])
    order = np.argsort(idx, kind="stable")
    if len(np.unique(idx)) != len(idx):
        raise ValueError("duplicate run indices in the Monte-Carlo chunks")
    out = {"run_index": idx[order], "t": parts[0]["t"]}
    for k in _TRACKS + ("n_landmarks", "init_error"):
        out[k] = np.concatenate([p[k] for p in parts])[order]
    pr = np.concatenate([p["plan_run"] for p in parts])
    po = np.argsort(pr, kind="stable")
    for k in _PLAN:
        out[k] = np.concatenate([p[k] for p in parts])[po]
    out["plan_run"] = pr[po]
    if methods:
        out["method"] = np.array(methods.pop())
    return out


def per_run_stats(data: dict) -> pd.DataFrame:
    """Per run: final and RMS error norms (m, m/s, deg) and mean NEES."""
    import pandas as pd

    rows = {}
    for key, name in (("err_r", "pos_err_m"), ("err_v", "vel_err_mps"), ("err_th_deg", "att_err_deg")):
        nrm = np.linalg.norm(data[key], axis=2)
        rows[f"final_{name}"] = nrm[:, -1]
        if "updated" in data:      # at the last vision update (then the IMU-only coast)
            rows[f"lastvis_{name}"] = nrm[np.arange(len(nrm)), last_update_index(data["updated"])]
        rows[f"rms_{name}"] = np.sqrt(np.mean(nrm**2, axis=1))
    rows["mean_nees_pos"] = data["nees_r"].mean(axis=1)
    rows["mean_nees_vel"] = data["nees_v"].mean(axis=1)
    rows["n_landmarks"] = data["n_landmarks"]
    return pd.DataFrame(rows, index=pd.Index(data["run_index"], name="run"))


def last_update_index(updated: np.ndarray):
    """Index of the last filter time with a vision update (0 if none), per run
    for ``updated`` (runs, times), or an int for one run (times,): after it the
    filter coasts on the IMU to touchdown."""
    u = np.asarray(updated, bool)
    last = u.shape[-1] - 1 - np.argmax(u[..., ::-1], axis=-1)
    out = np.where(u.any(axis=-1), last, 0)
    return int(out) if u.ndim == 1 else out


def _median_us(ns: np.ndarray) -> float:
    return float(np.median(ns) / 1e3) if len(ns) else math.nan


def pick_quality(d: dict) -> dict:
    """Per method: share of planning calls whose in-plane optimum fell on an end
    of the visible interval (edge rule, %), and the median / max over calls of
    the picked landmark's metric over the best detected landmark's (1 = best)."""
    out = {"edge_calls_pct": math.nan, "pick_ratio_median": math.nan, "pick_ratio_max": math.nan}
    if "plan_edge" in d and len(d["plan_edge"]):
        out["edge_calls_pct"] = float(100.0 * np.mean(d["plan_edge"]))
    r = np.asarray(d.get("plan_ratio", []), float)
    r = r[np.isfinite(r)]
    if r.size:
        out["pick_ratio_median"] = float(np.median(r))
        out["pick_ratio_max"] = float(r.max())
    return out


def same_pick_pct(a: dict, b: dict) -> float:
    """Percentage of planning calls (matched by run and time) at which two
    methods chose the same landmark."""
    ka = {(int(r), float(t)): int(i) for r, t, i in zip(a["plan_run"], a["plan_t"], a["plan_index"])}
    kb = {(int(r), float(t)): int(i) for r, t, i in zip(b["plan_run"], b["plan_t"], b["plan_index"])}
    common = set(ka) & set(kb)
    if not common:
        return math.nan
    return 100.0 * sum(ka[k] == kb[k] for k in common) / len(common)


def yaw_convergence(data: dict, ratio: float, method: str) -> dict:
    """Does the Monte-Carlo 3-sigma envelope of the yaw error shrink (paper B: it
    does not, one known landmark leaves yaw unobservable)? Converging means the
    3-sigma at touchdown is below ``ratio`` times the one at the start (deg)."""
    yaw = data["err_rpy_deg"][:, :, 2]
    s_first, s_last = float(3 * yaw[:, 0].std(ddof=1)), float(3 * yaw[:, -1].std(ddof=1))
    converges = s_last < ratio * s_first
    return {"converges": bool(converges), "n_runs": int(yaw.shape[0]),
            "reason": (f"yaw 3-sigma over the {yaw.shape[0]} runs ({method}): "
                       f"{s_first:.2f} deg at start, {s_last:.2f} deg at touchdown "
                       f"({'below' if converges else 'not below'} {ratio:.0%} of the start)")}


def summary_table(data: dict[str, dict], timing: dict, published_reduction_vs_svd: float | None = None,
                  converged_pos_err_m: float = 100.0) -> pd.DataFrame:
    """B-T3: one row per method (see the module docstring for the columns);
    ``timing``: the replay of the scenario's planning calls
    (``opnav.landing.timing.replay``, every method of ``data`` timed);
    ``converged_runs_pct`` counts the runs whose final position error is below
    ``converged_pos_err_m`` (m)."""
    import pandas as pd

    from opnav.landing import timing as tmg

    methods = list(data)
    missing = [m for m in methods if tmg.times_ns(timing, m).size == 0 and len(timing["source"])]
    if missing:
        raise ValueError(f"the planning-time replay did not time {missing}")
    rows = []
    for m in methods:
        st = per_run_stats(data[m])
        row = {"method": m, "n_runs": len(st)}
        for q in ("pos_err_m", "vel_err_mps", "att_err_deg"):
            for kind in ("final", "rms"):
                col = st[f"{kind}_{q}"]
                row[f"{kind}_{q}_mean"] = float(col.mean())
                row[f"{kind}_{q}_3sigma"] = float(3.0 * col.std(ddof=1)) if len(col) > 1 else math.nan
        row["final_pos_err_m_median"] = float(st["final_pos_err_m"].median())
        row["final_vel_err_mps_median"] = float(st["final_vel_err_mps"].median())
        if "lastvis_pos_err_m" in st:   # at the last vision update, before the IMU-only coast
            for q in ("pos_err_m", "vel_err_mps"):
                col = st[f"lastvis_{q}"]
                row[f"lastvis_{q}_mean"] = float(col.mean())
                row[f"lastvis_{q}_median"] = float(col.median())
                row[f"lastvis_{q}_3sigma"] = float(3.0 * col.std(ddof=1)) if len(col) > 1 else math.nan
        row["converged_runs_pct"] = float(100.0 * (st["final_pos_err_m"] < converged_pos_err_m).mean())
        row["mean_nees_pos"] = float(st["mean_nees_pos"].mean())
        row["mean_nees_vel"] = float(st["mean_nees_vel"].mean())
        row["landmarks_per_run"] = float(st["n_landmarks"].mean())
        alt_m = "alt" if tmg.times_ns(timing, m, "alt").size else "main"
        row["median_plan_time_us"] = tmg.median_us(timing, m)
        row["median_plan_cpu_us"] = tmg.median_us(timing, m, clock="cpu")
        # the same replayed calls on the alternative metric path (the configured one
        # for methods without it)
        row["median_plan_time_alt_us"] = tmg.median_us(timing, m, alt_m)
        row["median_plan_cpu_alt_us"] = tmg.median_us(timing, m, alt_m, clock="cpu")
        row["timed_calls"] = int(len(timing["source"]))
        ev = data[m]["plan_evals"]
        row["metric_evals_per_call"] = float(np.median(ev)) if len(ev) else math.nan
        row["plan_calls"] = int(len(ev))
        row.update(pick_quality(data[m]))
        if m != methods[0]:
            row[f"same_pick_as_{methods[0]}_pct"] = same_pick_pct(data[m], data[methods[0]])
        for b in methods:
            if b == m:
                continue
            from opnav.landing.ranking import pair_comparison

            pc = pair_comparison(data[m], data[b])
            row[f"same_pick_vs_{b}_pct"] = pc["same_pick_pct"]
            row[f"median_abs_dbeta_vs_{b}_deg"] = pc["median_abs_dbeta_deg"]
            for k in ("d_rms_pos", "d_final_pos"):
                row[f"{k}_vs_{b}_m"] = pc[f"{k}_m"]
                row[f"{k}_vs_{b}_lo_m"] = pc[f"{k}_lo_m"]
                row[f"{k}_vs_{b}_hi_m"] = pc[f"{k}_hi_m"]
            red, sd = tmg.time_reduction(timing, m, b)
            row[f"time_reduction_vs_{b}_pct"] = red
            row[f"time_reduction_vs_{b}_pct_std"] = sd
            row[f"cpu_time_reduction_vs_{b}_pct"] = tmg.time_reduction(timing, m, b, clock="cpu",
                                                                       n_boot=0)[0]
            alt_b = "alt" if tmg.times_ns(timing, b, "alt").size else "main"
            red, sd = tmg.time_reduction(timing, m, b, path_a=alt_m, path_b=alt_b)
            row[f"time_reduction_vs_{b}_alt_pct"] = red
            row[f"time_reduction_vs_{b}_alt_pct_std"] = sd
        rows.append(row)
    df = pd.DataFrame(rows)
    if published_reduction_vs_svd is not None:
        df["time_reduction_vs_svd_pct_published"] = [
            float(published_reduction_vs_svd) if m == "depth" else math.nan for m in df["method"]]
    return df
