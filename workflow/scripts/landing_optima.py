"""B-C8's evidence: how many local minima the depth error has over the visible angles on each
side of the velocity, per recorded planning call of one camera scenario's depth Monte Carlo
(opnav.landing.optima)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import write_json
from opnav.landing import optima
from opnav.landing.descent import build_scenario
from opnav.landing.montecarlo import load
from opnav.landing.setup import Setup
from opnav.report.landing.equivalence_text import Worded
from opnav.report.landing.optima_text import optima_text

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_optima", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    scn = build_scenario(Setup.from_config(snakemake.params.landing))    # the edge: parsed once
    counts = optima.count_calls(scn, load(snakemake.input.mc), int(snakemake.params.n_grid),
                                int(snakemake.params.max_calls))
    out = optima.count_summary(counts, snakemake.wildcards.bscn)
    text = optima_text(out)
    write_json(snakemake.output[0], Worded(out, text))     # the count's keys and its sentence
    log.info("%s", text)
