"""Science unchanged? Every Monte-Carlo mean of two builds' tables, the new one against
the old one's own 95 % interval (issue 31's target: B-T3, B-X1 and A-T1).

    python benchmarks/science_unchanged.py OLD_RESULTS NEW_RESULTS [--tables A-T1 B-T3 B-X1]

OLD_RESULTS and NEW_RESULTS are results folders of two builds of the same profile
(``results`` of the full profile, ``results/quick`` of the quick one). For every table
found in both (A-T1: ``approach/A-T1_table1.csv``; B-T3: ``landing/B-T3_summary_*.csv``;
B-X1: ``landing/B-X1_ranking_*.csv``), rows are matched by their key columns and, for
every mean column with a spread column beside it, the new mean is checked against the
old mean's 95 % interval ``old_mean +- 1.96 sd_old / sqrt(n_old)``:

* A-T1: ``est_x_mean`` / ``est_y_mean`` with ``est_x_std`` / ``est_y_std`` over
  ``n_seeds`` seeds;
* B-T3, B-X1: every ``<quantity>_mean`` with ``<quantity>_3sigma`` (sd = 3sigma / 3)
  over ``n_runs`` runs.

A mean whose old interval has zero width (sd 0, e.g. a deterministic quantity) must
agree to 1e-9 relative. Prints per table the count of means inside, then the means
outside (row, column, old, new, half-width, distance in half-widths). Last line:
``science unchanged: K of N means within their own 95 % interval``. Exit code 0.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import pandas as pd

Z95 = 1.959963984540054
TABLES = {
    "A-T1": ("approach/A-T1_table1.csv", ("variant", "case_id"), "n_seeds"),
    "B-T3": ("landing/B-T3_summary_*.csv", ("method",), "n_runs"),
    "B-X1": ("landing/B-X1_ranking_*.csv", ("method",), "n_runs"),
}


def mean_columns(table: str, cols) -> list[tuple[str, str, float]]:
    """(mean column, spread column, factor: sd = factor * spread) of a table."""
    if table == "A-T1":
        return [(f"est_{a}_mean", f"est_{a}_std", 1.0) for a in "xy"
                if f"est_{a}_mean" in cols and f"est_{a}_std" in cols]
    return [(c, c[:-5] + "_3sigma", 1.0 / 3.0) for c in cols
            if c.endswith("_mean") and c[:-5] + "_3sigma" in cols]


def compare(old: pd.DataFrame, new: pd.DataFrame, table: str, keys, n_col: str):
    """Yield (row key, column, old mean, new mean, half-width, inside)."""
    keys = [k for k in keys if k in old.columns and k in new.columns]
    o, n = old.set_index(keys), new.set_index(keys)
    for key in o.index.intersection(n.index):
        for m, s, f in mean_columns(table, [c for c in o.columns if c in n.columns]):
            try:
                mo, mn, sd, cnt = (float(v) for v in (o.at[key, m], n.at[key, m], f * o.at[key, s],
                                                      o.at[key, n_col]))
            except (TypeError, ValueError):
                continue
            if not all(math.isfinite(v) for v in (mo, mn, sd, cnt)):
                continue
            half = Z95 * sd / math.sqrt(cnt)
            inside = abs(mn - mo) <= half if half > 0 else abs(mn - mo) <= 1e-9 * max(abs(mo), 1e-300)
            yield key, m, mo, mn, half, inside


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--tables", nargs="*", default=list(TABLES), choices=list(TABLES))
    a = ap.parse_args()
    total = ok = 0
    for table in a.tables:
        pattern, keys, n_col = TABLES[table]
        for po in sorted(a.old.glob(pattern)):
            pn = a.new / po.relative_to(a.old)
            if not pn.exists():
                print(f"{table} {po.name}: not in the new build")
                continue
            rows = list(compare(pd.read_csv(po), pd.read_csv(pn), table, keys, n_col))
            k = sum(r[-1] for r in rows)
            total, ok = total + len(rows), ok + k
            print(f"{table} {po.name}: {k} of {len(rows)} means within their own 95 % interval")
            for key, m, mo, mn, half, inside in rows:
                if not inside:
                    d = abs(mn - mo) / half if half > 0 else math.inf
                    print(f"    outside: {key} {m}: old {mo:.6g}, new {mn:.6g}, half-width {half:.3g} "
                          f"({d:.2f} half-widths)")
    print(f"science unchanged: {ok} of {total} means within their own 95 % interval")


if __name__ == "__main__":
    main()
