"""Do a build's claims.csv and evidence.csv agree? (issue 52's Done-when, on a real build)

1. Re-score: the evidence rows the extractors wrote (every role but ``derived``, which the
   scorer itself adds) scored again by this checkout's plan and scorer; each claim's verdict and
   cause must equal the build's claims.csv.
2. Quoted numbers: every number in a claim row's cause, would_take, ours (as written, best,
   replication), bound and named is an estimate, lo or hi of one of that claim's evidence rows,
   a published value (or a plan margin times it), or a number of the plan
   (:func:`opnav.report.claims.unquoted_numbers`, the rule tests/test_claims.py checks on
   hand-made summaries), applied to the build. With ``--rescored`` the derived
   rows are the re-scoring's (this checkout's scorer), else the build's own.

Use::

    python benchmarks/claims_agree.py results/paper
    python benchmarks/claims_agree.py results/paper --rescored

Prints the claims that differ and the numbers found in no row, then a one-line count; exit 1 if
any.
"""

from __future__ import annotations

import argparse
import sys

import pandas as pd

from opnav.report import approach_claims, landing_claims  # noqa: F401  (register the quantities)
from opnav.report import claims as C
from opnav.report.evidence import read_csv


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paper", help="a build's results/paper folder (claims.csv, evidence.csv)")
    ap.add_argument("--rescored", action="store_true", help="check quotes against the re-scoring's derived rows")
    a = ap.parse_args(argv)
    plan = C.load_plan()
    ev = list(read_csv(f"{a.paper}/evidence.csv"))
    cl = pd.read_csv(f"{a.paper}/claims.csv").fillna("")
    base = [e for e in ev if e.role != "derived"]
    replicated = set(cl.loc[cl["verdict_replication"] != "", "claim_id"])   # as the build judged them
    rows, js, _ = C.build(plan, base, replicated)
    if a.rescored:
        ev = base + C.derived_rows(js)
    got = {r.claim_id: r for r in rows}
    differ = 0
    for _, c in cl.iterrows():
        r = got.get(c.claim_id)
        if r is None or r.verdict != c.verdict or r.cause != c.cause:
            differ += 1
            print("differs:", c.claim_id, c.verdict, "->", r.verdict if r else "no row")
    missing = C.unquoted_numbers(plan, C.records(cl), ev)
    for m in missing:
        print(m)
    missing = len(missing)
    print(f"{len(cl)} claims: {len(cl) - differ} re-scored alike, {differ} differ; "
          f"quoted numbers in no evidence row: {missing}")
    return 1 if differ or missing else 0


if __name__ == "__main__":
    sys.exit(main())
