# Paper A, beyond the paper: A-X2 (EM-EKF against the augmented EKF and batch ML).
# The A-X3 ablations (pixel noise, segment length) and the A-X5 sensitivity sweeps
# (prior sigma, range, roll rate) are parameter studies (config `studies`, studies.smk).
# Uses approach.smk's names (APPROACH, A_WORK, A_SCENARIO, A_EM, A_SRC, A_MC, A_METHODS, a_groups):
# include it after approach.smk.

A_X2_SRC = A_SRC + src("approach/batch_ml.py", "approach/alternatives.py")
A_X2_VARIANTS = config["approach"]["table1_variants"]


# One job per variant, every Table-1 case ("all", whatever approach.scatter says): the cases
# share the batch-ML NLP builds and their JIT compilation (one build per pixel noise).
A_X2 = {v: f"{A_WORK}/x2/{v}__all.pkl" for v in A_X2_VARIANTS}


rule approach_x2_group:
    """Augmented EKF and batch ML (CasADi + IPOPT) on the Table-1 cases of a group (A_X2: all
    of them) and variant, same seeds as the EM-EKF Monte Carlo; the headline group also times the EM-EKF."""
    input:
        A_X2_SRC,
        kernels=kernels("approach"),
    output:
        f"{A_WORK}/x2/{{variant}}__{{group}}.pkl",
    params:
        approach=cfg("approach", *A_EM, "alternatives", "methods"),
    log:
        f"{APPROACH}/logs/x2_{{variant}}__{{group}}.log",
    benchmark:
        f"{APPROACH}/benchmarks/x2_{{variant}}__{{group}}.tsv"
    script:
        "../scripts/approach_x2_group.py"


rule approach_x2_tables:
    """A-X2 table (per variant and method) and A-X2-summary.json; long form per case in work/."""
    input:
        x2=list(A_X2.values()),
        mc=[A_MC[(v, g, m)] for v in A_X2_VARIANTS for g in a_groups(v) for m in A_METHODS],
        code=src("approach/alternatives_summary.py", "report/approach/text.py", "approach/labels.py", "approach/summaries.py", "approach/setup.py",
                 "core/tables.py", "report/approach_views.py"),
    output:
        table=report_table(f"{APPROACH}/A-X2_alternatives", "A-X2", "Paper A"),
        long=f"{A_WORK}/x2/A-X2_alternatives_cases.csv",
        summary=f"{APPROACH}/A-X2-summary.json",
    params:
        approach=cfg("approach", "segments", "alternatives"),
        profile=config["profile"],
    log:
        f"{APPROACH}/logs/x2_tables.log",
    localrule: True
    script:
        "../scripts/approach_x2_tables.py"


rule approach_x2_figure:
    """A-X2 figure: error, spread and CRLB, navigation error, data needed and run time per method."""
    input:
        long=f"{A_WORK}/x2/A-X2_alternatives_cases.csv",
        code=src("report/approach/plots.py", "approach/alternatives_summary.py", "core/figures.py", "opnav.mplstyle"),
    output:
        fig=report_figure(f"{APPROACH}/A-X2_alternatives", "A-X2", "Paper A"),
    log:
        f"{APPROACH}/logs/x2_figure.log",
    localrule: True
    script:
        "../scripts/approach_x2_figure.py"
