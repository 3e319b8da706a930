"""B-X1: every planning method (paper's four + extra) on the same paired Monte
Carlo: 3-sigma envelopes figure, ranking table with paired comparison against
the reference (depth), and B-X1-summary.json for the manuscript macros."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import dataclasses
import json
import sys

from opnav.core import figures
from opnav.landing import timing
from opnav.report.landing import plots
from opnav.report.landing.ranking_text import worded_headline
from opnav.report.landing.timing_text import method_text
from opnav.landing.methods import colors as method_colors, labels as method_labels
from opnav.landing.montecarlo import first_runs, load
from opnav.landing.ranking import headline, ranking_table
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import json_ready, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_x1_summary", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    methods = list(snakemake.params.methods)
    data = {m: load(p) for m, p in zip(methods, snakemake.input.mc)}
    n_runs = min(d.n_runs for d in data.values())   # the paired runs all flew
    data = {m: first_runs(d, n_runs) for m, d in data.items()}
    ref = snakemake.params.extra["reference"]
    n_boot = int(snakemake.params.extra["n_boot"])
    rtol = float(snakemake.params.extra["tie_rtol"])
    conv = float(snakemake.params.converged_pos_err_m)
    tm = timing.load(snakemake.input.timing)     # planning times by replay, not the descents'
    df = ranking_table(data, tm, reference=ref, n_boot=n_boot, seed=0, rtol=rtol,
                       converged_pos_err_m=conv)
    write_table(df, snakemake.output.t,
                caption=(f"B-X1: all planning methods on the same paired Monte Carlo, runs 0-{n_runs - 1} "
                         f"({n_runs} runs: landing.extra.n_runs for this camera, sized by the information "
                         "baselines' cost). They are ranked by mean position error at the last landmark update "
                         "(rank_accuracy; ties share a rank) and by median planning-call CPU time (rank_time; "
                         f"methods within {100 * rtol:g} % of each other share the best rank). Paired differences "
                         f"method minus {ref} of the per-run position errors (m) are given at the last landmark "
                         "update (lastlm), as RMS over the landmark phase (lmrms) and over the descent, and at "
                         f"touchdown (final). Each has 95 % paired-t and bootstrap ({n_boot} resamples) intervals; "
                         f"converged: final position error below {conv:g} m. " + method_text(tm)))
    t = next(iter(data.values())).t
    own = getattr(snakemake.params, "custom", None) or {}    # your own methods' legend names and colours
    figures.save(plots.fig_nav_error_envelopes(t, data, method_labels(own),
                                               figures.own_colors(list(own), method_colors(own))),
                 snakemake.output.f)
    out = worded_headline(dataclasses.replace(headline(df, ref), n_boot=n_boot))
    with open(snakemake.output.summary, "w") as fh:      # the file edge: the record's fields as keys
        json.dump(json_ready(out), fh, indent=2, sort_keys=True)
    log.info("B-X1:\n%s", df.to_string())
