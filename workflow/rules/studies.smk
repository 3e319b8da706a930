# Parameter studies (opnav.studies): config section `studies`, one YAML block each.
#   snakemake --cores 2 study_<name>                       one study (table + figure, one job)
#   snakemake --cores 2 studies                            every study
# Included after the paper rules: each paper's simulation view (B_SIM; paper A's
# scenario + EM + augmented-EKF keys) is what a swept value may change. A study
# value's runs are keyed by the digest of its simulation config, so identical
# simulations are flown once, and editing one study's values queues only the new
# values' jobs. Outputs: results/studies/<name>/.
from opnav.studies.captions import caption as _study_caption
from opnav.studies.planning import plan as _plan_studies
from opnav.studies.values import simulation_shapes as _simulation_shapes
from opnav.preflight import validate_study_value

STUDIES_DIR = res("studies")
STUDY_SHAPES = {
    # paper B: the Monte Carlo's view plus the replay budget of the planning times
    "landing": {**B_SIM, "timing": {"max_calls": config["landing"]["timing"]["max_calls"]}},
    "approach": cfg("approach", *A_SCENARIO, "em", "nav_error", "alternatives", "growing"),
}


# The shapes the rules pass must be those opnav.studies plans with (validate_config
# checked every study with them, before any rule file was read).
if STUDY_SHAPES != _simulation_shapes(config):
    raise RuntimeError("opnav.studies.values.SIM_KEYS differs from the rules' simulation keys (B_SIM, "
                       "A_SCENARIO): update it")
try:
    STUDIES = _plan_studies(config, validate_paper=validate_study_value)   # cached: check_config planned it
except ConfigError as exc:
    config_exit(exc)
STUDY_SIMS = {i.digest: i.sim for s in STUDIES.values() for i in s.instances}
STUDY_JOB_UNITS = _study_job_units(STUDIES)
STUDY_SRC = {"landing": B_SRC + src("landing/study.py", "landing/timing.py", "landing/timing_summary.py"),
             "approach": A_X2_SRC + src("approach/study.py")}


# jobs.study_values_per_job > 1 (tiny profiles): each paper's study values (simulation
# digests, in the order the studies list them) in packs of that many, one job per pack
# (rules study_runs_pack1, ...) flying every chunk of each; rule study_runs flies the rest.
_S_K = config["jobs"]["study_values_per_job"]
STUDY_PACKS = []
for _p in ("approach", "landing"):
    _d = list(dict.fromkeys(d for (pp, d, _) in STUDY_JOB_UNITS if pp == _p))
    STUDY_PACKS += [(_p, [u for u in STUDY_JOB_UNITS if u[0] == _p and u[1] in _d[i:i + _S_K]])
                    for i in range(0, len(_d), _S_K)] if _S_K > 1 else []
_S_PACKED = sorted({d for _, units in STUDY_PACKS for _, d, _ in units})


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
        sdigest="".join(f"(?!{d}(?![0-9a-f]))" for d in _S_PACKED) + "[0-9a-f]+",   # not in a pack
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


for _i, (_p, _units) in enumerate(STUDY_PACKS, 1):

    rule:
        """Several study values' jobs in one (jobs.study_values_per_job): each value's
        chunks in turn, each written as rule study_runs writes it."""
        name:
            f"study_runs_pack{_i}"
        input:
            STUDY_SRC[_p],
            kernels=kernels(_p),
        output:
            [f"{STUDIES_DIR}/runs/{_p}/{d}/{c}.csv" for _, d, c in _units],
        params:
            paper=_p,
            sims=[STUDY_SIMS[d] for _, d, _ in _units],
            runs=[chunk_runs(c) for _, _, c in _units],
            units=[STUDY_JOB_UNITS[u] for u in _units],
            labels=[f"{d} {c}" for _, d, c in _units],
        resources:  # SLURM: a dynamic rule has no profiles/slurm entry; study_runs' per value
            runtime=10 * len(_units),
            mem_mb=1000,
        log:
            f"{STUDIES_DIR}/logs/runs_pack{_i}.log",
        benchmark:
            f"{STUDIES_DIR}/benchmarks/runs_pack{_i}.tsv"
        script:
            "../scripts/study_runs.py"


STUDY_TARGETS = {}
for _name, _s in STUDIES.items():
    _dir = f"{STUDIES_DIR}/{_name}"
    _stem = f"{_dir}/{_s.id}_{_name}"
    _spec = canonical(_s.spec())
    _cap = _study_caption(_s.spec())
    _files = _study_runs(_s)

    # The table and the figure are one job (the figure is drawn from the table it
    # has just written, read back as the figure alone would read it): one start-up
    # of Python, pandas and matplotlib per study instead of two.
    rule:
        name:
            f"study_{_name}_outputs"
        input:
            runs=[f for f, _ in _files],
            code=src("studies/tables.py", "studies/metrics.py", "studies/values.py", "studies/captions.py", "core/wording.py",
                     "landing/study.py", "core/tables.py",
                     "report/study_plots.py", "core/figures.py",
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
