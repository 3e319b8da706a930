# Paper B planning time by replay (opnav.landing.timing): the planning inputs recorded by
# every method's Monte Carlo of a camera scenario are replayed through every method's
# planning call, one call at a time, interleaved across methods in one process. B-F7,
# B-T3 and the B-X1 time columns read its output, not the descents' clocks.
# Included after landing_extra.smk (reuses LANDING, B_SIMS, B_SRC, X1_METHODS, b_mc).
from opnav.landing.timing import timed_methods

# the methods timed: B-X1's flown ones and a real (LAPACK) SVD of the same H beside svd's
# closed form (timed only: B-C4's "SVD"); the replication's timing times the same list
B_TIMED = timed_methods(X1_METHODS)


def all_cores() -> int:
    """Every core this run was given (``--cores``): a timing replay takes them all, so no other
    job runs beside it; 1 where a run gives none (a script run by hand parses the workflow
    without ``--cores``, and Snakemake refuses to read ``workflow.cores`` then)."""
    from snakemake.exceptions import WorkflowError

    try:
        return int(workflow.cores)
    except WorkflowError:
        return 1


rule landing_timing:
    """Planning times of every method on the same recorded planning calls of one scenario."""
    input:
        mc=lambda wc: b_mc(wc.bscn, X1_METHODS),
        code=B_SRC + src("landing/timing.py", "landing/timing_summary.py"),
        kernels=kernels("landing"),
    output:
        f"{LANDING}/timing/{{bscn}}.npz",
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: B_SIMS[wc.bscn],
        methods=B_TIMED,
        max_calls=config["landing"]["timing"]["max_calls"],
        max_calls_paper=config["landing"]["timing"]["max_calls_paper"],
    priority: 10        # a long job on the critical path (speed only)
    # the replay times microsecond calls by thread CPU: it runs with no other job beside it
    # (more busy processes than cores read the interior depth call at 4.5-4.7 us instead of
    # 3.0-3.2, and its saving against SVD at 17-22 % instead of 27-29 %; docs/performance.md)
    threads: all_cores()
    log:
        f"{LANDING}/logs/timing_{{bscn}}.log",
    benchmark:
        f"{LANDING}/benchmarks/timing_{{bscn}}.tsv"
    script:
        "../scripts/landing_timing.py"
