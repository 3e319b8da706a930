"""Out-of-sample filter tuning of paper B (opnav.landing.tuning): the candidates on
a separate seed stream in every camera scenario, the one tuning for all, checked
against the configured landing.filter."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.landing.setup import Setup, Tuning
from opnav.landing.tuning import tuning_report
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import write_json

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_tuning", argv=sys.argv[1:])

with script_context(snakemake) as log:
    # the edge: paper B's config parsed once (every scenario's setup, the tuning section)
    out = tuning_report({n: Setup.from_config(c) for n, c in snakemake.params.scenarios.items()},
                        Tuning.from_config(snakemake.params.tuning))
    write_json(snakemake.output[0], out)
    log.info("tuning: chosen %s (configured %s, matches: %s)", out.chosen, out.configured, out.config_matches)
