# Paper A, your own misalignment estimators (approach.custom_estimators, opnav.approach.estimators;
# docs/usage.md, "Your own method"): every Table-1 case of every table1_variant, on growing windows,
# scored against the truth and the bound of the data used: A-X8 (table and convergence figure).
# Built only when one is registered (result_outputs). Uses approach.smk's names (APPROACH, A_WORK,
# A_EM, A_SRC): include it after approach.smk.
from opnav.approach.estimators import source_files as a_custom_files

A_CUSTOM = config["approach"].get("custom_estimators") or {}
A_CUSTOM_VARIANTS = config["approach"]["table1_variants"]


rule approach_custom:
    """Every registered estimator on the Table-1 cases of one variant (one job)."""
    input:
        A_SRC,
        src("approach/estimators.py", "core/registry.py"),
        a_custom_files(A_CUSTOM),
        kernels=kernels("approach"),
    output:
        f"{A_WORK}/custom/{{variant}}.pkl",
    params:
        approach=cfg("approach", *A_EM, "custom_estimators"),
    log:
        f"{APPROACH}/logs/custom_{{variant}}.log",
    benchmark:
        f"{APPROACH}/benchmarks/custom_{{variant}}.tsv"
    script:
        "../scripts/approach_custom.py"


rule approach_custom_outputs:
    """A-X8: the registered estimators' A-T1-style table (every case) and convergence figure
    (headline case)."""
    input:
        runs=expand(f"{A_WORK}/custom/{{variant}}.pkl", variant=A_CUSTOM_VARIANTS),
        code=src("approach/estimator_summary.py", "report/approach/estimator_plots.py", "approach/summaries.py",
                 "core/tables.py", "core/figures.py", "opnav.mplstyle"),
    output:
        table=report_table(f"{APPROACH}/A-X8_custom_estimators", "A-X8", "Paper A"),
        fig=report_figure(f"{APPROACH}/A-X8_custom_estimators", "A-X8", "Paper A"),
    params:
        custom=canonical(A_CUSTOM),
    log:
        f"{APPROACH}/logs/custom_outputs.log",
    localrule: True
    script:
        "../scripts/approach_custom_outputs.py"
