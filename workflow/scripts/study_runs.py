"""One parameter-study job: runs `params.runs` of every unit in `params.units` (paper B:
a method; paper A: variant__estimator) with one study value's simulation config
(opnav.studies; results keyed by that config's digest); or, in a pack (rules
study_runs_pack*, jobs.study_values_per_job), several such (value, chunk) jobs in turn,
one output each."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

import pandas as pd

from opnav.core.snakeio import mock_snakemake, save_csv, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("study_runs", argv=sys.argv[1:])


def fly(paper: str, sim: dict, units: list[str], runs: list[int], label: str, log) -> pd.DataFrame:
    """Every unit's runs at one value: the table rule study_runs writes."""
    if paper == "landing":
        from opnav.landing.setup import Setup
        from opnav.landing.study import run_runs

        sim = Setup.from_config(sim)  # the edge: paper B's config parsed once
    else:
        from opnav.approach.setup import Setup
        from opnav.approach.study import run_runs

        sim = Setup.from_config(sim)  # the edge: paper A's config parsed once
    frames, shared = [], {}  # paper A: the estimators of a variant share its geometry and bounds
    for unit in units:
        if paper == "landing":
            frames.append(run_runs(sim, unit, runs))
        else:
            variant, method = unit.split("__")
            frames.append(run_runs(sim, variant, method, runs, shared=shared))
        log.info("%s %s %s: runs %d..%d", paper, label, unit, runs[0], runs[-1])
    return pd.concat(frames, ignore_index=True)


with script_context(snakemake) as log:
    p = snakemake.params
    if hasattr(p, "sims"):  # a pack: its outputs in the order of its (value, chunk) jobs
        jobs = list(zip(p.sims, p.units, p.runs, p.labels, snakemake.output, strict=True))
        paper = p.paper
    else:
        w = snakemake.wildcards
        jobs, paper = [(p.sim, p.units, p.runs, w.sdigest, snakemake.output[0])], w.spaper
    for sim, units, runs, label, out in jobs:
        # stamped with its rows and checksum: study_outputs refuses a cut or edited chunk
        save_csv(out, fly(paper, sim, list(units), list(runs), label, log))
