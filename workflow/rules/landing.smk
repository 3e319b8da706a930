# Paper B: Mars powered descent and landmark selection (SPEC section B).

LANDING = res("landing")


rule landing_tables:
    """B-T1 and B-T2, rendered from the config."""
    input:
        src("landing/scenario.py", "tables.py", "published.py", "data/published.yaml"),
    output:
        t1=report_table(f"{LANDING}/B-T1_initial_state", "B-T1", "Paper B"),
        t2=report_table(f"{LANDING}/B-T2_error_bounds", "B-T2", "Paper B"),
    params:
        landing=cfg("landing", "initial_state", "mc"),
    log:
        f"{LANDING}/logs/landing_tables.log",
    localrule: True
    script:
        "../scripts/landing_tables.py"


ALL_TARGETS.extend(rules.landing_tables.output)
