"""A-X8: the registered misalignment estimators' table (every Table-1 case, scored against the
truth and the bound of the data used) and convergence figure (headline case)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.approach import estimator_summary
from opnav.report.approach import estimator_plots
from opnav.approach.estimators import colors
from opnav.core import figures
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_custom_outputs", argv=sys.argv[1:])

with script_context(snakemake) as log:
    res = [r for p in snakemake.input.runs for r in load_pickle(p)["results"]]
    df = estimator_summary.long_frame(res)
    write_table(df, snakemake.output.table,
                caption=("A-X8: your own misalignment estimators (approach.custom_estimators) on every Table-1 "
                         "case, growing windows after N0 from the variant's start: final estimate (mean, sd over "
                         "seeds) and its error about the truth (arcsec), the Cramér-Rao bound of the data it used "
                         "(bound_, at the truth) and the RMS error in units of it (err_over_bound_), the "
                         "estimator's own sigma where it returns a covariance, data to converge (median, "
                         "samples), navigation error before and after compensation (mean, km) and run time per "
                         "call (s, this machine)."))
    own = snakemake.params.custom
    figures.save(estimator_plots.fig_convergence(estimator_summary.curves(res),
                                                 figures.own_colors(list(own), colors(own))),
                 snakemake.output.fig)
    log.info("A-X8:\n%s", df.to_string())
