# Paper B beyond the paper (SPEC B.4 B-X1) and one-value ablations (B-X2).
# Included right after landing.smk: reuses its LANDING, B_SIM(S), B_SRC, B_METHODS,
# B_SCENARIOS and its Monte-Carlo wildcard rules (an extra method is one more gathered
# results/landing/mc/{scenario}/{method}.npz, same runs, same seeds). The ablations
# fly landing.camera without scenario overlay (B_SIM).
from opnav.landing.ablation import SWEEPS as _B_SWEEPS, value_label as _b_value_label

_BX = config["landing"]["extra"]
X1_METHODS = list(B_METHODS) + [m for m in _BX["methods"] if m not in B_METHODS]


rule landing_x1_summary:
    """B-X1 of one scenario: all methods on the paired Monte Carlo, envelopes, ranking, JSON."""
    input:
        mc=lambda wc: b_mc(wc.bscn, X1_METHODS),
        code=src("landing/ranking.py", "landing/montecarlo.py", "landing/plots.py", "tables.py",
                 "figures.py", "opnav.mplstyle"),
    output:
        f=report_figure(f"{LANDING}/B-X1_envelopes_{{bscn}}", "B-X1", "Paper B", "beyond"),
        t=report_table(f"{LANDING}/B-X1_ranking_{{bscn}}", "B-X1", "Paper B"),
        summary=f"{LANDING}/summaries/B-X1-summary_{{bscn}}.json",
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        methods=X1_METHODS,
        extra=canonical(config["landing"]["extra"]),
        converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
    log:
        f"{LANDING}/logs/x1_summary_{{bscn}}.log",
    localrule: True
    script:
        "../scripts/landing_x1_summary.py"


rule landing_x1_summary_all:
    """B-X1-summary.json: every scenario's B-X1 summary, the headline's also at the top level."""
    input:
        parts=expand(f"{LANDING}/summaries/B-X1-summary_{{bscn}}.json", bscn=B_SCENARIOS),
    output:
        f"{LANDING}/B-X1-summary.json",
    params:
        scenarios=B_SCENARIOS,
        headline=B_HEADLINE,
        cameras={s: canonical(c["camera"]) for s, c in B_SCENARIO_CFG.items()},
    log:
        f"{LANDING}/logs/x1_summary_all.log",
    localrule: True
    script:
        "../scripts/landing_combine.py"


ALL_TARGETS.extend(expand(rules.landing_x1_summary.output.f, bscn=B_SCENARIOS))
ALL_TARGETS.extend(expand(rules.landing_x1_summary.output.t, bscn=B_SCENARIOS))
ALL_TARGETS.extend(rules.landing_x1_summary_all.output)


# ---------------------------------------------------------------- ablations
# Sweep "fov" changes landing.camera.fov_deg, "obs" landing.filter.obs_per_landmark
# (opnav.landing.ablation.SWEEPS); each value flies runs 0..n_runs-1 with the main
# Monte Carlo's seeds (run index only), scattered over (sweep, value, chunk) jobs.
_BA = config["landing"]["ablation"]
ABL_METHODS = list(_BA["methods"])
ABL_VALUES = {s: {_b_value_label(s, v): v for v in _BA[_B_SWEEPS[s][0]]} for s in _B_SWEEPS}
ABL_CHUNKS = [chunk_label(c) for c in mc_chunks(_BA["n_runs"], _BA["runs_per_job"])]


rule landing_ablation_chunk:
    """One ablation job: runs of every ablation method at one swept value (scatter)."""
    input:
        B_SRC,
        src("landing/ablation.py"),
    output:
        [f"{LANDING}/ablation/{{bsweep}}/{{bvalue}}/{m}_{{bchunk}}.npz" for m in ABL_METHODS],
    wildcard_constraints:
        bsweep="|".join(_B_SWEEPS),
        bvalue="[0-9][0-9.]*",
        bchunk=CHUNK_PATTERN,
    params:
        landing=B_SIM,
        methods=ABL_METHODS,
        value=lambda wc: ABL_VALUES[wc.bsweep][wc.bvalue],
        runs=lambda wc: chunk_runs(wc.bchunk),
    log:
        f"{LANDING}/logs/ablation_{{bsweep}}_{{bvalue}}_{{bchunk}}.log",
    benchmark:
        f"{LANDING}/benchmarks/ablation_{{bsweep}}_{{bvalue}}_{{bchunk}}.tsv"
    script:
        "../scripts/landing_ablation_chunk.py"


rule landing_ablation_fov:
    """B-X2: camera field of view swept (table + figure)."""
    input:
        runs=_abl_chunks("fov"),
        code=src("landing/ablation.py", "landing/montecarlo.py", "tables.py", "figures.py",
                 "opnav.mplstyle"),
    output:
        t=report_table(f"{LANDING}/B-X2_ablation_fov", "B-X2", "Paper B"),
        f=report_figure(f"{LANDING}/B-X2_ablation_fov", "B-X2", "Paper B", "ablation"),
    params:
        sweep="fov",
        values=list(ABL_VALUES["fov"].values()),
        methods=ABL_METHODS,
        default=config["landing"]["camera"]["fov_deg"],
        converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
    log:
        f"{LANDING}/logs/ablation_fov.log",
    localrule: True
    script:
        "../scripts/landing_ablation.py"


rule landing_ablation_obs:
    """B-X2: observations per landmark swept (table + figure)."""
    input:
        runs=_abl_chunks("obs"),
        code=src("landing/ablation.py", "landing/montecarlo.py", "tables.py", "figures.py",
                 "opnav.mplstyle"),
    output:
        t=report_table(f"{LANDING}/B-X2_ablation_obs", "B-X2", "Paper B"),
        f=report_figure(f"{LANDING}/B-X2_ablation_obs", "B-X2", "Paper B", "ablation"),
    params:
        sweep="obs",
        values=list(ABL_VALUES["obs"].values()),
        methods=ABL_METHODS,
        default=config["landing"]["filter"]["obs_per_landmark"],
        converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
    log:
        f"{LANDING}/logs/ablation_obs.log",
    localrule: True
    script:
        "../scripts/landing_ablation.py"


ALL_TARGETS.extend(rules.landing_ablation_fov.output)
ALL_TARGETS.extend(rules.landing_ablation_obs.output)
