"""One parameter-study job: runs `params.runs` of one (variant and) method with one
study value's simulation config (opnav.studies; results keyed by that config's digest)."""

import sys

from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import atomic_target

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_runs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    w = snakemake.wildcards
    runs = list(snakemake.params.runs)
    if w.spaper == "landing":
        from opnav.landing.study import run_runs

        df = run_runs(snakemake.params.sim, w.sunit, runs)
    else:
        from opnav.approach.study import run_runs

        variant, method = w.sunit.split("__")
        df = run_runs(snakemake.params.sim, variant, method, runs)
    with atomic_target(snakemake.output[0]) as tmp:
        df.to_csv(tmp, index=False)
    log.info("%s %s %s: runs %d..%d", w.spaper, w.sdigest, w.sunit, runs[0], runs[-1])
