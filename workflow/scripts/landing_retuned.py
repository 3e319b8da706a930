"""The retuned filter of one camera scenario on the held-out runs (opnav.landing.tuning:
the scale chosen on the tuning runs, flown on the Monte Carlo's own runs) beside the paper
tuning's Monte Carlo: its record (JSON) and the NEES table."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.landing.montecarlo import load, nees_consistency
from opnav.report.landing.summary import nees_table
from opnav.landing.setup import Setup
from opnav.landing.tuning import HeldOut, TuningReport, errors, retuned_record
from opnav.core.snakeio import load_json, mock_snakemake, script_context
from opnav.core.tables import write_json, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_retuned", argv=sys.argv[1:], bscn="interior")

with script_context(snakemake) as log:
    scn = snakemake.wildcards.bscn
    d = load(snakemake.input.mc)
    n = d.n_runs
    rec = retuned_record(TuningReport.from_json(load_json(snakemake.input.tuning)), scn, Setup.from_config(snakemake.params.landing),
                         snakemake.params.method, n, HeldOut(nees_consistency(d), errors(d)))
    write_json(snakemake.output.record, rec)
    table = nees_table(rec)
    write_table(table, snakemake.output.table,
                caption=(f"B-T3 NEES ({scn} camera): {snakemake.params.method} with the paper's filter tuning "
                         "(flown by default) and with the bearing-noise scale retuned on the tuning runs alone "
                         f"(closest to the band's centre). Columns: mean NEES on the {rec.tuning_n_runs} tuning "
                         f"runs; held-out mean NEES and share of filter times in the 95 % band on the {n} "
                         "Monte-Carlo runs; the reading; median position errors at the last landmark update and "
                         "at touchdown."))
    log.info("NEES %s:\n%s", scn, table.to_string())
