"""A study's tables: its runs gathered from the chunk files, the tidy summary (statistics
per value, [variant,] method and metric), the wide human view and the log-log slopes."""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pandas (0.3 CPU-s of import) inside the functions
    import pandas as pd

from opnav.studies.metrics import CONSTANT_METRICS, shown_statistic, table_metrics
from opnav.studies.values import display_value

__all__ = ["ci95", "gather_runs", "loglog_slopes", "summarize", "tidy_table", "wide_table"]


def gather_runs(parts: Iterable[tuple[str, pd.DataFrame]], study: Mapping,
                converged_pos_err_m: float | None = None) -> pd.DataFrame:
    """Every run of a study, one row per (instance, [variant,] method, run): the chunk
    tables ``(instance label, frame)`` joined, the rows of the study's methods (and
    variants) kept (a chunk also holds those of other studies of the same value), runs
    beyond ``study["runs"]`` dropped (kept chunks of a larger earlier study), paper-B
    derived metrics added, the swept values beside each row; rows in (value, [variant,]
    method, run) order, whatever the chunking."""
    import pandas as pd
    frames = []
    for label, df in parts:
        df = df.copy()
        df.insert(0, "instance", label)
        frames.append(df)
    runs = pd.concat(frames, ignore_index=True)
    keep = runs["method"].isin(study["methods"]) & (runs["run"] < study["runs"])
    if study["variants"]:
        keep &= runs["variant"].isin(study["variants"])
    runs = runs[keep]
    variants = list(study["variants"]) or [None]
    counts = runs.groupby(["instance", "variant", "method"] if study["variants"] else ["instance", "method"]).size()
    for label, v, m in itertools.product(study["instances"], variants, study["methods"]):
        n = int(counts.get((label, v, m) if v else (label, m), 0))
        if n != study["runs"]:
            raise ValueError(f"study '{study['name']}': value {label}: {n} runs of {f'{v}/{m}' if v else m}, "
                             f"expected {study['runs']} (rerun its study_runs jobs)")
    if study["paper"] == "landing":
        from opnav.landing.study import add_derived

        runs = add_derived(runs, converged_pos_err_m)
    for key in study["keys"]:
        runs.insert(1, key, [str(study["instances"][i][key]) for i in runs["instance"]])
    # one row order whatever the chunking (runs_per_job): value, [variant,] method, run
    order = {c: {v: i for i, v in enumerate(vals)} for c, vals in
             (("instance", list(study["instances"])), ("variant", list(study["variants"])),
              ("method", list(study["methods"])))}
    cols = ["instance", *(["variant"] if study["variants"] else []), "method", "run"]
    runs = runs.sort_values(cols, key=lambda col: col.map(order[col.name]) if col.name in order else col,
                            kind="stable")
    return runs.reset_index(drop=True)


def tidy_table(runs: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """The study's tidy summary (:func:`summarize`) with the study name and swept values."""
    tidy = summarize(runs, table_metrics(study), study["methods"])
    for key in reversed(study["keys"]):
        tidy.insert(1, key, [study["instances"][i][key] for i in tidy["instance"]])
    tidy.insert(0, "study", study["name"])
    return tidy


def loglog_slopes(tidy: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """Power-law exponents: per ([variant,] method, metric) the least-squares slope of
    log(statistic) against log(first swept key), the statistic being
    :func:`shown_statistic`'s (+1: proportional). Values or statistics <= 0 are left out;
    NaN below two points."""
    import pandas as pd
    key = study["keys"][0]
    unit = (["variant"] if "variant" in tidy else []) + ["method", "metric"]
    rows = []
    for keys, g in tidy[tidy["metric"].isin(table_metrics(study))].groupby(unit, sort=False):
        keys = keys if isinstance(keys, tuple) else (keys,)
        stat = shown_statistic(study, keys[-1])
        x = np.array([float(study["instances"][i][key]) for i in g["instance"]])
        y = g[stat].to_numpy(float)
        ok = (x > 0) & (y > 0) & np.isfinite(y)
        slope = (float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])
                 if ok.sum() >= 2 and np.ptp(np.log(x[ok])) > 0 else math.nan)
        rows.append({"study": study["name"], **dict(zip(unit, keys)), "statistic": stat,
                     "against": key, "n_values": int(ok.sum()), "slope": slope})
    return pd.DataFrame(rows)


# ------------------------------------------------------------------ statistics
def ci95(x) -> tuple[float, float]:
    """95 % confidence interval of the mean of the finite values of ``x`` (Student t,
    :func:`opnav.landing.ranking.paired_t_interval`); NaN below two values."""
    from opnav.landing.ranking import paired_t_interval

    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        return math.nan, math.nan
    _, lo, hi, _ = paired_t_interval(x, 0.95)
    return lo, hi


def summarize(runs: pd.DataFrame, metrics: Iterable[str], methods: Iterable[str]) -> pd.DataFrame:
    """Tidy summary: one row per (instance, [variant,] method, metric).

    ``runs`` holds one row per (instance, [variant,] method, run) with the
    metric columns. The paired difference is against the first of ``methods``
    on the same (instance, variant, run).
    """
    import pandas as pd
    methods = list(methods)
    ref = methods[0]
    unit = ["instance"] + (["variant"] if "variant" in runs else [])
    rows = []
    for keys, g in runs.groupby(unit, sort=False):
        keys = keys if isinstance(keys, tuple) else (keys,)
        base = g[g["method"] == ref].set_index("run")
        for m in methods:
            gm = g[g["method"] == m]
            for metric in metrics:
                x = gm[metric].to_numpy(float)
                fin = x[np.isfinite(x)]
                lo, hi = ci95(fin)
                row = dict(zip(unit, keys))
                row.update(method=m, metric=metric, n_runs=int(fin.size),
                           mean=float(fin.mean()) if fin.size else math.nan,
                           sd=float(fin.std(ddof=1)) if fin.size > 1 else math.nan,
                           rms=float(np.sqrt(np.mean(fin**2))) if fin.size else math.nan,
                           median=float(np.median(fin)) if fin.size else math.nan,
                           ci95_low=lo, ci95_high=hi)
                if m != ref:
                    d = (gm.set_index("run")[metric] - base[metric]).to_numpy(float)
                    d = d[np.isfinite(d)]
                    dlo, dhi = ci95(d)
                    row.update({"diff_vs": ref, "diff_mean": float(d.mean()) if d.size else math.nan,
                                "diff_ci95_low": dlo, "diff_ci95_high": dhi})
                else:
                    row.update({"diff_vs": "", "diff_mean": math.nan, "diff_ci95_low": math.nan,
                                "diff_ci95_high": math.nan})
                rows.append(row)
    return pd.DataFrame(rows)


def wide_table(tidy: pd.DataFrame, study: Mapping) -> pd.DataFrame:
    """The human view: one row per value x [variant x] method, '<stat> [lo, hi]' per metric."""
    import pandas as pd
    stat = study["statistic"]
    inst = study["instances"]
    rows = []
    unit = ["instance"] + (["variant"] if "variant" in tidy else []) + ["method"]
    for keys, g in tidy.groupby(unit, sort=False):
        row = {k: display_value(v) for k, v in inst[keys[0]].items()}
        row.update(dict(zip(unit[1:], keys[1:])))
        row["n_runs"] = int(g["n_runs"].max())
        for r in g.itertuples():
            shown = shown_statistic(study, r.metric)
            if not np.isfinite(getattr(r, shown)):  # e.g. the stall share of a non-EM estimator
                row[r.metric if shown == "mean" else f"{r.metric} ({stat})"] = "--"
                continue
            if r.metric not in study["metrics"] or r.metric in CONSTANT_METRICS:  # the same for every run
                row[r.metric] = f"{r.mean:.4g}"
            elif shown == "mean":  # mean +- half-width of its 95 % interval
                row[r.metric] = (f"{r.mean:.4g} ± {(r.ci95_high - r.ci95_low) / 2:.2g}"
                                 if np.isfinite(r.ci95_low) else f"{r.mean:.4g}")
            else:
                row[f"{r.metric} ({stat})"] = f"{getattr(r, stat):.4g}"
        rows.append(row)
    return pd.DataFrame(rows)
