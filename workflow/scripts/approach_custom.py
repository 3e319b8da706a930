"""A-X8: every registered misalignment estimator (approach.custom_estimators) on the Table-1 cases
of one variant (one Snakemake job)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach.estimators import run_variant
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_custom", argv=sys.argv[1:], variant="roll")

with script_context(snakemake) as log:
    res = run_variant(snakemake.params.approach, snakemake.wildcards.variant, log=log)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], {"variant": snakemake.wildcards.variant, "results": res})
