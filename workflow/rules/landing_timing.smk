# Paper B planning time by replay (opnav.landing.timing): the planning inputs recorded by
# every method's Monte Carlo of a camera scenario are replayed through every method's
# planning call, one call at a time, interleaved across methods in one process. B-F7,
# B-T3 and the B-X1 time columns read its output, not the descents' clocks.
# Two jobs per scenario (issue 53):
# * landing_timing_replays, alone on the machine: the compiled calls the timing claims read
#   (landing.mc.methods: B-C4, B-C9; microseconds), landing.timing.n_replays times, each replay
#   a fresh process, each call's evaluations timed alone too (the shared part / evaluations split),
#   and B-F7's overhead curve;
# * landing_timing, an ordinary job beside others (it does not wait for the replays): every other
#   variant once on the same calls (milliseconds: the B-X1 information baselines, the LAPACK SVD,
#   the pickers, and the paper's definition on landing.timing.max_calls_paper of them).
# The consumers read both (timing.load of the list merges them).
# Included after landing_extra.smk (reuses LANDING, B_SIMS, B_SRC, X1_METHODS, b_mc).
from opnav.landing.timing import timed_methods

_BT = config["landing"]["timing"]
# the methods timed: B-X1's flown ones and a real (LAPACK) SVD of the same H beside svd's
# closed form (timed only: B-C4's "SVD"); the replication's timing times the same list
# and your own methods (landing.custom_methods), timed once on the built-in methods' recorded calls
# (paired; a registration changes no call the timing claims read)
B_TIMED = timed_methods(X1_METHODS) + B_CUSTOM
# replayed n_replays times (compiled path): the timing claims' methods
B_REPLAYED = list(B_METHODS)
TIMING_CODE = B_SRC + src("landing/timing.py", "landing/timing_summary.py")
# what a consumer of one scenario's planning times reads, {bscn} left to expand: the replays, then
# the variants timed once (timing.load of the list merges them); landing.smk's and
# landing_extra.smk's rules read it through a function (this file is included after theirs)
B_TIMING = [f"{LANDING}/timing/{{bscn}}/replay{r}.npz" for r in range(_BT["n_replays"])] + [
    f"{LANDING}/timing/{{bscn}}/other.npz"]


def all_cores() -> int:
    """Every core this run was given (``--cores``): a timing replay takes them all, so no other
    job runs beside it; 1 where a run gives none (a script run by hand parses the workflow
    without ``--cores``, and Snakemake refuses to read ``workflow.cores`` then)."""
    from snakemake.exceptions import WorkflowError

    try:
        return int(workflow.cores)
    except WorkflowError:
        return 1


rule landing_timing_replays:
    """Independent replays (separate processes) of the compiled calls the timing claims read, and
    B-F7's overhead curve from them."""
    input:
        mc=lambda wc: b_mc(wc.bscn, X1_METHODS),
        code=TIMING_CODE + src("report/landing/timing_plots.py", "core/figures.py", "opnav.mplstyle",
                               "data/published.yaml"),
        kernels=kernels("landing"),
    output:
        replays=[f"{LANDING}/timing/{{bscn}}/replay{r}.npz" for r in range(_BT["n_replays"])],
        f7o=report_figure(f"{LANDING}/B-F7_overhead_{{bscn}}", "B-F7.overhead", "Paper B", "{bscn}"),
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: B_SIMS[wc.bscn],
        flown=X1_METHODS,
        replayed=B_REPLAYED,
        max_calls=_BT["max_calls"],
    priority: 10        # on the critical path (speed only)
    # the replay times microsecond calls by thread CPU: it runs with no other job beside it
    # (more busy processes than cores read the interior depth call at 4.5-4.7 us instead of
    # 3.0-3.2, and its saving against SVD at 17-22 % instead of 27-29 %; docs/dev/performance-log.md)
    threads: all_cores()
    log:
        f"{LANDING}/logs/timing_replays_{{bscn}}.log",
    benchmark:
        f"{LANDING}/benchmarks/timing_replays_{{bscn}}.tsv"
    script:
        "../scripts/landing_timing.py"


rule landing_timing:
    """Planning times of the other variants on the same recorded planning calls of one scenario,
    timed once beside other jobs (milliseconds a call), not waiting for the replays."""
    input:
        mc=lambda wc: b_mc(wc.bscn, X1_METHODS),
        code=TIMING_CODE + b_custom_src(B_TIMED),
        kernels=kernels("landing"),
    output:
        f"{LANDING}/timing/{{bscn}}/other.npz",
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: b_sim(wc.bscn, B_TIMED),   # with your own methods' entries
        flown=X1_METHODS,
        methods=B_TIMED,
        main=[m for m in B_TIMED if m not in B_REPLAYED],
        alt=B_TIMED,
        max_calls=_BT["max_calls"],
        max_calls_paper=_BT["max_calls_paper"],
    priority: 10        # the longest timing job (site-tilt): started as soon as its Monte Carlo is
    log:
        f"{LANDING}/logs/timing_{{bscn}}.log",
    benchmark:
        f"{LANDING}/benchmarks/timing_{{bscn}}.tsv"
    script:
        "../scripts/landing_timing.py"
