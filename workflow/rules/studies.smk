# Parameter studies (opnav.studies): config section `studies`, one YAML block each.
#   snakemake --cores 2 study_<name>                       one study (table + figure, one job)
#   snakemake --cores 2 studies                            every study
# Included after the paper rules: each paper's simulation view (B_SIM; paper A's
# scenario + EM + augmented-EKF keys) is what a swept value may change. A study
# value's runs are keyed by the digest of its simulation config, so identical
# simulations are flown once, and editing one study's values queues only the new
# values' jobs. Outputs: results/studies/<name>/.
from opnav import studies as _studies
from opnav.preflight import validate_study_value

STUDIES_DIR = res("studies")
STUDY_SHAPES = {
    # paper B: the Monte Carlo's view plus the replay budget of the planning times
    "landing": {**B_SIM, "timing": {"max_calls": config["landing"]["timing"]["max_calls"]}},
    "approach": cfg("approach", *A_SCENARIO, "em", "nav_error", "alternatives", "growing"),
}


# The shapes the rules pass must be those opnav.studies plans with (validate_config
# checked every study with them, before any rule file was read).
if STUDY_SHAPES != _studies.simulation_shapes(config):
    raise RuntimeError("opnav.studies.SIM_KEYS differs from the rules' simulation keys (B_SIM, "
                       "A_SCENARIO): update it")
try:
    STUDIES = _studies.plan(config, validate_paper=validate_study_value)   # cached: check_config planned it
except ConfigError as exc:
    config_exit(exc)
STUDY_SIMS = {i.digest: i.sim for s in STUDIES.values() for i in s.instances}
STUDY_JOB_UNITS = _study_job_units(STUDIES)
STUDY_SRC = {"landing": B_SRC + src("landing/study.py"),
             "approach": A_X2_SRC + src("approach/study.py")}


rule study_runs:
    """One study job: a chunk of runs at one value (simulation config), every method
    (paper A: variant and estimator) that a study of that value compares."""
    input:
        lambda wc: STUDY_SRC[wc.spaper],
        kernels=lambda wc: kernels(wc.spaper),
    output:
        f"{STUDIES_DIR}/runs/{{spaper}}/{{sdigest}}/{{schunk}}.csv",
    wildcard_constraints:
        spaper="approach|landing",
        sdigest="[0-9a-f]+",
        schunk=CHUNK_PATTERN,
    params:
        sim=lambda wc: STUDY_SIMS[wc.sdigest],
        runs=lambda wc: chunk_runs(wc.schunk),
        units=lambda wc: STUDY_JOB_UNITS[(wc.spaper, wc.sdigest, wc.schunk)],
    log:
        f"{STUDIES_DIR}/logs/runs_{{spaper}}_{{sdigest}}_{{schunk}}.log",
    benchmark:
        f"{STUDIES_DIR}/benchmarks/runs_{{spaper}}_{{sdigest}}_{{schunk}}.tsv"
    script:
        "../scripts/study_runs.py"


STUDY_TARGETS = {}
for _name, _s in STUDIES.items():
    _dir = f"{STUDIES_DIR}/{_name}"
    _stem = f"{_dir}/{_s.id}_{_name}"
    _spec = canonical(_s.spec())
    _cap = _studies.caption(_s.spec())
    _files = _study_runs(_s)

    # The table and the figure are one job (the figure is drawn from the table it
    # has just written, read back as the figure alone would read it): one start-up
    # of Python, pandas and matplotlib per study instead of two.
    rule:
        name:
            f"study_{_name}_outputs"
        input:
            runs=[f for f, _ in _files],
            code=src("studies.py", "landing/study.py", "core/tables.py", "report/study_plots.py", "core/figures.py",
                     "opnav.mplstyle"),
        output:
            table=[report(f"{_stem}.csv", caption=_caption("study"), category="Studies",
                          subcategory=_name), f"{_stem}.tex", f"{_stem}.md"],
            runs=f"{_dir}/runs.csv",
            caption=f"{_dir}/{_s.id}.rst",
            slopes=table_outputs(f"{_stem}_slopes") if _s.slopes else [],
            fig=[f"{_stem}.pdf", report(f"{_stem}.png", caption=_caption("study"), category="Studies",
                                        subcategory=_name)],
        params:
            study=_spec,
            labels=[lab for _, lab in _files],
            caption=_cap,
            converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
        log:
            f"{STUDIES_DIR}/logs/{_name}_outputs.log",
        localrule: True
        script:
            "../scripts/study_outputs.py"

    STUDY_TARGETS[_name] = [*table_outputs(_stem), *(table_outputs(f"{_stem}_slopes") if _s.slopes else []),
                            f"{_dir}/runs.csv", f"{_dir}/{_s.id}.rst", *figure_outputs(_stem)]

    rule:
        name:
            f"study_{_name}"
        input:
            STUDY_TARGETS[_name],
        localrule: True


rule studies:
    """Every study of the config (tables and figures)."""
    input:
        [t for ts in STUDY_TARGETS.values() for t in ts],
    localrule: True
