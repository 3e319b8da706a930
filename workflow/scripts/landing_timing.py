"""Planning time by replay of one camera scenario (opnav.landing.timing).

Rule ``landing_timing_replays`` (alone on the machine): ``landing.timing.n_replays`` independent
replays of the compiled calls the timing claims read, each in a fresh process
(``timing.replays_in_processes``), with each call's evaluations timed alone (the decomposition),
and B-F7's overhead curve (main sample only).
Rule ``landing_timing`` (an ordinary job, beside others, not waiting for the replays): the other
variants (calls of milliseconds: the information baselines, the LAPACK SVD, the pickers, the
paper's definition on its subset) once, on the same calls. The consumers read both
(``timing.load`` of the list merges them, ``timing.merge``).
"""

from opnav.core.jobserver import delegate

# the replays' rule takes every core only to run alone; its timed processes are fresh (started here)
delegate(any_threads=True)  # in a local build the job runs in the build's job server (opnav.core.jobserver)

import sys
import tempfile

from opnav.core import published
from opnav.landing import timing, timing_summary
from opnav.report.landing import timing_text
from opnav.landing.setup import Setup
from opnav.core.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md); --replays: the replays
    _rule = "landing_timing_replays" if "--replays" in sys.argv else "landing_timing"
    sys.argv = [a for a in sys.argv if a != "--replays"]
    snakemake = mock_snakemake(_rule, argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    p = snakemake.params
    mc = dict(zip(p.flown, snakemake.input.mc))
    setup = Setup.from_config(p.landing)    # the edge: paper B's config parsed once
    if snakemake.rule.endswith("_replays"):
        spec = timing.replay_spec(setup, mc, p.replayed, int(p.max_calls), alt=False, decompose=True,
                                  best_of=timing.REPLAY_BEST_OF)
        with tempfile.TemporaryDirectory() as tmp:
            reps = timing.replays_in_processes(spec, len(snakemake.output.replays), tmp, log)
        for r, path in zip(reps, snakemake.output.replays):
            timing.save(path, r)
        tm = timing.merge(reps)
        ev = timing_summary.planning_time_evidence(tm, published.load()["paper_b"]["depth_time_reduction_vs_svd_pct"])
        log.info("%s", timing_text.method_text(tm))
        log.info("reductions between replays (mean, sd): %s; shared part at the published reduction: %.3f us",
                 {k: (round(v.mean, 2), round(v.sd_between, 2)) for k, v in ev.reduction_pct.items()},
                 ev.shared_us_at_published)
        if "f7o" in snakemake.output.keys():
            from opnav.core import figures
            from opnav.report.landing import timing_plots

            figures.save(timing_plots.fig_overhead_curve(ev, snakemake.wildcards.bscn), snakemake.output.f7o)
    else:
        spec = timing.replay_spec(setup, mc, p.methods, int(p.max_calls), alt=list(p.alt), main=list(p.main),
                                  max_calls_paper=int(p.max_calls_paper), warm_compiled=False)
        tm = timing.run_spec(spec)
        timing.save(snakemake.output[0], tm)
        log.info("%s", timing_text.method_text(tm))
        log.info("%s", timing_text.summary_frame(tm).to_string())
