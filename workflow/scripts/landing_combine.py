"""Gather per-scenario summaries of paper B into one JSON: ``scenarios`` (by
name, with each scenario's camera), ``headline_scenario``, and the headline
scenario's keys also at the top level (the manuscript's default numbers)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.report.landing.summary import combine_scenarios
from opnav.core.snakeio import load_json, mock_snakemake, script_context
from opnav.core.tables import write_json

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_summary_all", argv=sys.argv[1:])

with script_context(snakemake) as log:
    names = list(snakemake.params.scenarios)
    parts = {n: load_json(p) for n, p in zip(names, snakemake.input.parts)}
    write_json(snakemake.output[0], combine_scenarios(parts, snakemake.params.headline,
                                                      dict(snakemake.params.cameras)))
    log.info("%s: scenarios %s, headline %s", snakemake.output[0], names, snakemake.params.headline)
