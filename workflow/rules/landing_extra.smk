# Paper B beyond the paper (SPEC B.4 B-X1). The B-X2 ablations (field of view,
# observations per landmark) are parameter studies (config `studies`, studies.smk),
# which fly landing.camera without scenario overlay (B_SIM).
# Included right after landing.smk: reuses its LANDING, B_SIM(S), B_SRC, B_METHODS,
# B_SCENARIOS and its Monte-Carlo wildcard rules (an extra method is one more gathered
# results/landing/mc/{scenario}/{method}.npz, same runs, same seeds).

_BX = config["landing"]["extra"]
X1_METHODS = list(B_METHODS) + [m for m in _BX["methods"] if m not in B_METHODS]
# B-X1's rows: those and your own methods (landing.custom_methods), on the same paired runs
X1_ALL = X1_METHODS + [m for m in B_CUSTOM if m not in X1_METHODS]


rule landing_x1_summary:
    """B-X1 of one scenario: all methods on the paired Monte Carlo, envelopes, ranking, JSON."""
    input:
        mc=lambda wc: b_mc(wc.bscn, X1_ALL),
        timing=lambda wc: expand(B_TIMING, bscn=wc.bscn),   # replays + other (landing_timing.smk)
        code=with_kernels("landing", src("landing/ranking.py", "landing/montecarlo.py", "landing/timing.py",
                                         "landing/timing_summary.py", "report/landing/plots.py", "report/landing/timing_text.py",
                                         "report/landing/ranking_text.py", "landing/records.py",
                                         "core/tables.py", "core/figures.py", "opnav.mplstyle")),
        kernels=kernels("landing"),
    output:
        f=report_figure(f"{LANDING}/B-X1_envelopes_{{bscn}}", "B-X1", "Paper B", "beyond"),
        t=report_table(f"{LANDING}/B-X1_ranking_{{bscn}}", "B-X1", "Paper B"),
        summary=f"{LANDING}/summaries/B-X1-summary_{{bscn}}.json",
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        methods=X1_ALL,
        custom=canonical(B_CUSTOM_CFG),    # legend names and colours of your own methods
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
        code=src("report/landing/summary.py", "report/landing/timing_text.py"),
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
