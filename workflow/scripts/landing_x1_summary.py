"""B-X1: every planning method (paper's four + extra) on the same paired Monte
Carlo: 3-sigma envelopes figure, ranking table with paired comparison against
the reference (depth), and B-X1-summary.json for the manuscript macros."""

import json

from opnav import figures
from opnav.landing import plots, timing
from opnav.landing.montecarlo import load
from opnav.landing.ranking import headline, ranking_table
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_table

if "snakemake" not in globals():  # standalone debugging run
    _m = ["depth", "svd", "gdop", "cond", "logdet", "mineig", "random", "center"]
    snakemake = mock_snakemake(
        input={"mc": [f"results/landing/mc/site-tilt/{m}.npz" for m in _m],
               "timing": "results/landing/timing/site-tilt.npz"},
        output={"f": ["results/landing/B-X1_envelopes_site-tilt.pdf", "results/landing/B-X1_envelopes_site-tilt.png"],
                "t": ["results/landing/B-X1_ranking_site-tilt.csv"],
                "summary": "results/landing/summaries/B-X1-summary_site-tilt.json"})
    snakemake.params = type("P", (), {"methods": _m,
                                      "extra": {"reference": "depth", "n_boot": 2000,
                                                "tie_rtol": 1e-3},
                                      "converged_pos_err_m": 100.0})()

with script_context(snakemake) as log:
    methods = list(snakemake.params.methods)
    data = {m: load(p) for m, p in zip(methods, snakemake.input.mc)}
    ref = snakemake.params.extra["reference"]
    n_boot = int(snakemake.params.extra["n_boot"])
    rtol = float(snakemake.params.extra["tie_rtol"])
    conv = float(snakemake.params.converged_pos_err_m)
    tm = timing.load(snakemake.input.timing)     # planning times by replay, not the descents'
    df = ranking_table(data, tm, reference=ref, n_boot=n_boot, seed=0, rtol=rtol,
                       converged_pos_err_m=conv)
    write_table(df, snakemake.output.t,
                caption=(f"B-X1: all planning methods on the same paired Monte Carlo, ranked by mean "
                         f"RMS position error (rank_accuracy) and by median planning-call CPU time "
                         f"(rank_time; methods within {100 * rtol:g} % of each other share the best "
                         f"rank); paired differences method minus "
                         f"{ref} of the per-run RMS and final position errors (m) with 95 % paired-t "
                         f"and bootstrap ({n_boot} resamples) intervals; converged: final position "
                         f"error below {conv:g} m. " + timing.method_text(tm)))
    t = next(iter(data.values()))["t"]
    figures.save(plots.fig_nav_error_envelopes(t, data), snakemake.output.f)
    out = headline(df, ref)
    out["n_boot"] = n_boot
    with open(snakemake.output.summary, "w") as fh:
        json.dump(out, fh, indent=2, sort_keys=True)
    log.info("B-X1:\n%s", df.to_string())
