# Paper B: Mars powered descent and landmark selection (SPEC section B).

LANDING = res("landing")


rule landing_tables:
    """B-T1 and B-T2, rendered from the config."""
    input:
        src("landing/scenario.py", "landing/trajectory.py", "tables.py", "published.py",
            "data/published.yaml"),
    output:
        t1=report_table(f"{LANDING}/B-T1_initial_state", "B-T1", "Paper B"),
        t2=report_table(f"{LANDING}/B-T2_error_bounds", "B-T2", "Paper B"),
    params:
        landing=cfg("landing", "initial_state", "mc", "duration_s", "gravity_mps2", "yaw_deg"),
    log:
        f"{LANDING}/logs/landing_tables.log",
    localrule: True
    script:
        "../scripts/landing_tables.py"


ALL_TARGETS.extend(rules.landing_tables.output)


# ---------------------------------------------------------------- simulation
# Every result-relevant value reaches the rules through `params:` (B_SIM); the
# Monte Carlo is scattered over (method, chunk) jobs and gathered per method.
# A new planning method is a new name in landing.mc.methods (table-driven
# dispatch in opnav.landing.planner). Wildcards are named bmethod/bchunk so the
# other parts' global wildcard constraints do not apply.
# Chunks are kept (not temp) and named by their run indices (montecarlo.chunk_label):
# a run's random stream depends on its index only, so raising landing.mc.n_runs flies
# only the new runs, and no chunk's params mention n_runs.
from opnav.landing.montecarlo import CHUNK_PATTERN, chunk_label, chunk_runs, chunks as mc_chunks

B_METHODS = list(config["landing"]["mc"]["methods"])
B_CHUNKS = [chunk_label(c) for c in mc_chunks(config["landing"]["mc"]["n_runs"],
                                               config["landing"]["mc"]["runs_per_job"])]
B_SIM = cfg("landing", "duration_s", "gravity_mps2", "initial_state", "yaw_deg", "imu", "camera",
            "landmarks", "filter", "planner")
B_SIM["mc"] = canonical({k: config["landing"]["mc"][k] for k in ("base_seed", "bounds")})
B_SRC = src("landing/trajectory.py", "landing/imu.py", "landing/camera.py", "landing/landmarks.py",
            "landing/measurement.py", "landing/ekf.py", "landing/depth_error.py",
            "landing/planner.py", "landing/descent.py", "landing/montecarlo.py",
            "landing/metrics.py", "landing/casadi_model.py")
B_MC = {m: f"{LANDING}/mc/{m}.npz" for m in B_METHODS}


rule landing_mc_chunk:
    """One Monte-Carlo job: runs of one planning method (scatter)."""
    input:
        B_SRC,
    output:
        f"{LANDING}/mc/chunks/{{bmethod}}/{{bchunk}}.npz",
    wildcard_constraints:
        bmethod="[a-z][a-z0-9_-]*",
        bchunk=CHUNK_PATTERN,
    params:
        landing=B_SIM,
        runs=lambda wc: chunk_runs(wc.bchunk),
    log:
        f"{LANDING}/logs/mc_{{bmethod}}_chunk{{bchunk}}.log",
    benchmark:
        f"{LANDING}/benchmarks/mc_{{bmethod}}_chunk{{bchunk}}.tsv"
    script:
        "../scripts/landing_mc_chunk.py"


rule landing_mc_gather:
    """All runs of one method, in run order (gather)."""
    input:
        lambda wc: [f"{LANDING}/mc/chunks/{wc.bmethod}/{c}.npz" for c in B_CHUNKS],
    output:
        f"{LANDING}/mc/{{bmethod}}.npz",
    wildcard_constraints:
        bmethod="[a-z][a-z0-9_-]*",
    log:
        f"{LANDING}/logs/mc_{{bmethod}}_gather.log",
    localrule: True
    script:
        "../scripts/landing_mc_gather.py"


rule landing_single:
    """The headline single descent, B-F4 (true states) and B-F5 (depth-error map)."""
    input:
        B_SRC,
        src("landing/plots.py", "figures.py", "opnav.mplstyle"),
    output:
        summary=f"{LANDING}/single/summary.json",
        f4=report_figure(f"{LANDING}/B-F4_true_states", "B-F4", "Paper B"),
        f5=report_figure(f"{LANDING}/B-F5_depth_error_map", "B-F5", "Paper B"),
    params:
        landing=canonical({**B_SIM, "single": config["landing"]["single"],
                           "figures": config["landing"]["figures"]}),
    log:
        f"{LANDING}/logs/single.log",
    script:
        "../scripts/landing_single.py"


rule landing_mc_figures:
    """B-F6 (3-sigma envelopes per axis) and B-F7 (planning-time box plots)."""
    input:
        mc=[B_MC[m] for m in B_METHODS],
        code=src("landing/plots.py", "landing/montecarlo.py", "figures.py", "opnav.mplstyle",
                 "published.py", "data/published.yaml"),
    output:
        f6=report_figure(f"{LANDING}/B-F6_nav_error_envelopes", "B-F6", "Paper B"),
        f7=report_figure(f"{LANDING}/B-F7_planning_time", "B-F7", "Paper B"),
    params:
        methods=B_METHODS,
    log:
        f"{LANDING}/logs/mc_figures.log",
    localrule: True
    script:
        "../scripts/landing_mc_figures.py"


rule landing_summary:
    """B-T3 beside the published 29.03 %, and B-summary.json for the manuscript."""
    input:
        mc=[B_MC[m] for m in B_METHODS],
        single=rules.landing_single.output.summary,
        code=src("landing/montecarlo.py", "tables.py", "published.py", "data/published.yaml"),
    output:
        t3=report_table(f"{LANDING}/B-T3_summary", "B-T3", "Paper B"),
        summary=f"{LANDING}/B-summary.json",
    params:
        methods=B_METHODS,
        yaw_ratio=0.5,
        converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
    log:
        f"{LANDING}/logs/summary.log",
    localrule: True
    script:
        "../scripts/landing_summary.py"


ALL_TARGETS.extend(rules.landing_single.output.f4)
ALL_TARGETS.extend(rules.landing_single.output.f5)
ALL_TARGETS.extend(rules.landing_mc_figures.output)
ALL_TARGETS.extend(rules.landing_summary.output)
