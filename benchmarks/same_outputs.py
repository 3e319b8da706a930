"""Same outputs? Every CSV and JSON of two builds' folders compared value by value.

    python benchmarks/same_outputs.py OLD_RESULTS NEW_RESULTS [--parts approach paper] [--rtol 1e-12]

For each part (a sub-folder of the results: ``approach``, ``paper``, ``landing``, ...) every
``*.csv`` and ``*.json`` present in either build is read (CSV with pandas, JSON parsed) and
compared: the same columns / keys, the same texts, numbers equal to ``rtol`` (NaN equals NaN,
null equals null). Run-time measurements differ between builds by nature and are skipped: CSV
columns and JSON keys naming a time (``runtime``, ``_s_per_``, ``seconds``, ``wall``, ``cpu``,
``elapsed``), and the provenance files. Prints one line per file that differs (with its first
differences) and ends with ``same outputs: K of N files``. Exit code 1 when a file differs.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

import pandas as pd

TIME = re.compile(r"runtime|run time|_s_per_|seconds|wall|cpu|elapsed|_time_s|time_us|_us$|_us_|timing|build_s", re.I)
SKIP_FILES = re.compile(r"provenance|benchmarks/|logs/|\.sha256$")


def _same_value(a, b, rtol: float) -> bool:
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isnan(a) and math.isnan(b):
            return True
        return a == b or abs(a - b) <= rtol * max(abs(a), abs(b))
    return a == b


def diff_json(a, b, rtol: float, path: str = "") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for k in sorted(set(a) | set(b)):
            if TIME.search(str(k)):
                continue
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'new' if k not in a else 'old'}")
                continue
            out += diff_json(a[k], b[k], rtol, f"{path}.{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} vs {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in diff_json(x, y, rtol, f"{path}[{i}]")]
    return [] if _same_value(a, b, rtol) else [f"{path}: {a!r} vs {b!r}"]


def diff_csv(pa: Path, pb: Path, rtol: float) -> list[str]:
    a, b = pd.read_csv(pa), pd.read_csv(pb)
    out = []
    if list(a.columns) != list(b.columns):
        out.append(f"columns differ: only old {sorted(set(a.columns) - set(b.columns))}, "
                   f"only new {sorted(set(b.columns) - set(a.columns))}")
    if len(a) != len(b):
        return out + [f"rows {len(a)} vs {len(b)}"]
    for c in [c for c in a.columns if c in b.columns and not TIME.search(c)]:
        for i, (x, y) in enumerate(zip(a[c].tolist(), b[c].tolist())):
            if isinstance(x, float) and isinstance(y, float):
                ok = _same_value(x, y, rtol)
            else:
                ok = (pd.isna(x) and pd.isna(y)) or x == y
            if not ok:
                out.append(f"row {i} {c}: {x!r} vs {y!r}")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--parts", nargs="*", default=["approach", "paper"])
    ap.add_argument("--rtol", type=float, default=1e-12)
    a = ap.parse_args(argv)
    old, new = Path(a.old), Path(a.new)
    files = sorted({p.relative_to(root) for root in (old, new) for part in a.parts
                    for ext in ("csv", "json") for p in (root / part).rglob(f"*.{ext}")})
    bad = 0
    for rel in files:
        if SKIP_FILES.search(str(rel)):
            continue
        po, pn = old / rel, new / rel
        if not po.exists() or not pn.exists():
            print(f"{rel}: only in {'new' if not po.exists() else 'old'}")
            bad += 1
            continue
        d = (diff_csv(po, pn, a.rtol) if rel.suffix == ".csv"
             else diff_json(json.loads(po.read_text()), json.loads(pn.read_text()), a.rtol))
        if d:
            bad += 1
            print(f"{rel}: {len(d)} differences; " + "; ".join(d[:4]))
    n = sum(1 for r in files if not SKIP_FILES.search(str(r)))
    print(f"same outputs: {n - bad} of {n} files")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
