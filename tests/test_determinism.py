"""Two builds of the same config agree off the clock (issue 46 item 6; docs/usage.md
"What a rebuild reproduces"): every table's non-timing columns and every Monte-Carlo
output are equal; what differs is what is measured (times) and what is made from it."""

import pickle
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import copy_workflow, run_snakemake

#: A column, array or metric that holds a measured time (or a quantity made from one).
TIMING = re.compile(r"time|_us\b|_us_|cpu|wall|second|speed|reduction|runtime|elapsed|_ns\b", re.I)
#: Files that are measurements or made from them (docs/usage.md): not compared.
MEASURED = re.compile(r"(^|/)(logs|benchmarks|timing|paper|kernels)/|provenance|claims|scorecard|"
                      r"B-F7|summary|page_one|\.(log|tsv|tex|md|pdf|png|rst|json|sha256)$")


def _same(a, b, path: str) -> list[str]:
    """Where plain data ``a`` and ``b`` differ (numbers exactly, NaN equal), skipping keys
    that hold times."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: keys {sorted(set(a) ^ set(b), key=str)}"]
        return [d for k in a if not TIMING.search(str(k)) for d in _same(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} vs {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _same(x, y, f"{path}[{i}]")]
    if isinstance(a, pd.DataFrame):
        return _frames(a, b, path)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return [f"{path}: shape {a.shape} vs {b.shape}"]
        if a.dtype.kind in "fc":
            return [] if np.array_equal(a, b, equal_nan=True) else [f"{path}: arrays differ"]
        return [] if np.array_equal(a, b) else [f"{path}: arrays differ"]
    if hasattr(a, "__dict__") and type(a) is type(b):
        return _same(vars(a), vars(b), path)
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return []
    return [] if a == b else [f"{path}: {a!r} vs {b!r}"[:200]]


def _frames(a: pd.DataFrame, b: pd.DataFrame, path: str) -> list[str]:
    keep = [c for c in a.columns if not TIMING.search(str(c))]
    if "metric" in a.columns:                    # a study's tidy table: rows per metric
        a, b = (f[~f["metric"].astype(str).str.contains(TIMING)] for f in (a, b))
    try:
        pd.testing.assert_frame_equal(a[keep].reset_index(drop=True), b[keep].reset_index(drop=True),
                                      check_exact=True)
    except (AssertionError, KeyError) as exc:
        return [f"{path}: {' '.join(str(exc).split())[:300]}"]
    return []


def _compare(one: Path, two: Path) -> tuple[int, list[str]]:
    compared, diffs = 0, []
    for f in sorted(one.rglob("*")):
        rel = f.relative_to(one).as_posix()
        if not f.is_file() or MEASURED.search(rel):
            continue
        g = two / rel
        if not g.is_file():
            diffs.append(f"{rel}: only in the first build")
            continue
        compared += 1
        if f.suffix == ".csv":
            from opnav.core.snakeio import CSV_STAMP, load_csv, load_table

            read = load_csv if f.read_text().startswith(CSV_STAMP) else load_table   # study runs are stamped
            diffs += _frames(read(f), read(g), rel)
        elif f.suffix == ".npz":
            with np.load(f, allow_pickle=True) as x, np.load(g, allow_pickle=True) as y:
                diffs += _same({k: x[k] for k in x.files}, {k: y[k] for k in y.files}, rel)
        elif f.suffix == ".pkl":
            diffs += _same(pickle.loads(f.read_bytes()), pickle.loads(g.read_bytes()), rel)
        elif f.read_bytes() != g.read_bytes():
            diffs.append(f"{rel}: bytes differ")
    return compared, diffs


@pytest.mark.slow
def test_two_builds_agree_off_the_clock(quick_results, tmp_path):
    """A second quick build from empty, in another folder, beside the session's shared
    one: every computed output equal off the timing columns. Mutation: a run's stream
    seeded from the clock (or from the chunk) makes the Monte-Carlo outputs differ."""
    (tmp_path / "second").mkdir()
    wd = copy_workflow(tmp_path / "second")
    proc = run_snakemake(wd, "--cores", "2", "--configfile", "config/quick.yaml")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    # every file of the fresh build against the shared one (other slow tests add files to
    # the shared build, e.g. the README's study and the HTML report, whatever the order)
    compared, diffs = _compare(wd / "results" / "quick", quick_results / "results" / "quick")
    assert compared >= 50, compared
    assert not diffs, "\n".join(diffs[:40])
