"""One parameter-study job: runs `params.runs` of every unit in `params.units` (paper B:
a method; paper A: variant__estimator) with one study value's simulation config
(opnav.studies; results keyed by that config's digest)."""

import sys

import pandas as pd

from opnav.core.snakeio import mock_snakemake, save_csv, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_runs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    w = snakemake.wildcards
    runs = list(snakemake.params.runs)
    if w.spaper == "landing":
        from opnav.landing.study import run_runs
    else:
        from opnav.approach.study import run_runs
    frames, shared = [], {}  # paper A: the estimators of a variant share its geometry and bounds
    for unit in snakemake.params.units:
        if w.spaper == "landing":
            frames.append(run_runs(snakemake.params.sim, unit, runs))
        else:
            variant, method = unit.split("__")
            frames.append(run_runs(snakemake.params.sim, variant, method, runs, shared=shared))
        log.info("%s %s %s: runs %d..%d", w.spaper, w.sdigest, unit, runs[0], runs[-1])
    # stamped with its rows and checksum: study_outputs refuses a cut or edited chunk
    save_csv(snakemake.output[0], pd.concat(frames, ignore_index=True))
