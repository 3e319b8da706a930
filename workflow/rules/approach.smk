# Paper A: EM-EKF camera-misalignment estimation on Mars approach (SPEC section A).
# Simulation rules (Monte Carlo, convergence study, CRLB) write pickles under
# results/approach/work/; table and figure rules only read them.

from opnav.core.planvalues import accuracy_target_arcsec

APPROACH = res("approach")
A_WORK = f"{APPROACH}/work"
# Each rule's params hold only the approach keys it reads (editing another key reruns nothing):
# the scenario and cases (scenario.build_geometry, cases.table1_cases, pipeline.bound_curve) ...
A_SCENARIO = ("base_seed", "dt_s", "mars_elements", "geometry", "initial_error", "prior_sigma",
              "process_noise_diag", "camera", "truth_bias_arcsec", "theta_init_arcsec", "segments",
              "roll", "crlb", "stars")
# ... and the EM-EKF Monte Carlo on top of it (cases.run_cases).
A_EM = A_SCENARIO + ("n_seeds", "em", "nav_error")
A_GROUPS = ["size", "polarity", "initial", "pixel", "install"]
A_VARIANTS = config["approach"]["variants"]
A_METHODS = config["approach"]["methods"]
# Paper A's accuracy claim (arcsec): A-C1's target in the analysis plan, its one home (read without
# the report layer, opnav.core.planvalues); the rules that compute with it pass it as a param and list
# the plan as an input
A_PLAN = src("data/analysis_plan.yaml")[0]
A_TARGET = accuracy_target_arcsec(A_PLAN)
A_SRC = with_kernels("approach", src(
    "approach/dynamics.py", "approach/camera.py", "approach/kalman.py", "approach/ekf.py",
    "approach/smoother.py", "approach/em.py", "approach/augmented.py", "approach/crlb.py",
    "approach/setup.py", "approach/scenario.py", "approach/cases.py", "approach/pipeline.py", "approach/bounds.py",
    "approach/stars.py", "approach/consider.py"))


A_MC = {(v, g, m): f"{A_WORK}/mc/{v}__{g}__{m}.pkl"
        for v in A_VARIANTS for g in a_groups(v) for m in A_METHODS}
_a_seg, _a_grow = config["approach"]["segments"], config["approach"]["growing"]
if _a_grow["methods"] and (_a_seg["L"] * _a_seg["N"]) % _a_grow["N"]:
    config_exit(f"invalid config key 'approach.growing.N': {_a_grow['N']} does not divide approach.segments.L x N "
                f"= {_a_seg['L'] * _a_seg['N']}")  # checked before (opnav.core.checks.growing_problems)
# Table 1 again with growing windows (approach.growing), as its own rows: scheme "growing-<method>"
A_MC_GROWING = {(v, g, m): f"{A_WORK}/mc/{v}__{g}__growing-{m}.pkl"
                for v in A_VARIANTS for g in a_groups(v) for m in config["approach"]["growing"]["methods"]}
# every EM scheme of a Monte-Carlo job (rule approach_mc), in this order
A_SCHEMES = list(A_METHODS) + [f"growing-{m}" for m in config["approach"]["growing"]["methods"]]

# every scenario variant's name (one pattern, also approach_mc's when it refuses packed units)
_A_VARIANT_RE = "literal|prior|roll|reference-start|stars"


wildcard_constraints:
    variant=_A_VARIANT_RE,
    group="size|polarity|initial|pixel|install|headline|all",
    method="plain|squarem|growing-plain|growing-squarem",


# jobs.approach_mc_per_job > 1 (tiny profiles): the Monte Carlo's (variant, case group)
# units, in the order A_VARIANTS and a_groups list them, in packs of that many, one job per
# pack (rules approach_mc_pack1, ...) writing each unit's files as approach_mc does. Every
# unit's job gets the same params (A_EM, growing) and code, so an approach key or code edit
# reruns every unit either way; only adding a variant or group re-flies its pack-mates.
_A_K = config["jobs"]["approach_mc_per_job"]
# the keys a Monte-Carlo unit reads, alike in rule approach_mc and the packs (the growing schemes
# also read approach.growing)
_A_MC_APPROACH = cfg("approach", *A_EM, *(("growing",) if config["approach"]["growing"]["methods"] else ()))
A_MC_UNITS = [(v, g) for v in A_VARIANTS for g in a_groups(v)]
A_MC_PACKS = [A_MC_UNITS[i:i + _A_K] for i in range(0, len(A_MC_UNITS), _A_K)] if _A_K > 1 else []
# approach_mc's pattern refuses the packed units (a lookahead over "variant__group__")
_A_NOT_PACKED = "".join(f"(?!{v}__{g}__)" for p in A_MC_PACKS for v, g in p)


rule approach_mc:
    """Monte Carlo of one case group and scenario variant under every EM scheme (A_SCHEMES: sliding
    plain / SQUAREM, growing-<method>; seeds batched). One job for all schemes: they share the
    process start-up (about 0.7 CPU-s a job) and the geometry."""
    input:
        A_SRC,
        kernels=kernels("approach"),
    output:
        [f"{A_WORK}/mc/{{variant}}__{{group}}__{s}.pkl" for s in A_SCHEMES],
    wildcard_constraints:
        variant=f"{_A_NOT_PACKED}({_A_VARIANT_RE})",
    params:
        # the growing schemes also read approach.growing
        approach=_A_MC_APPROACH,
        schemes=A_SCHEMES,
    log:
        f"{APPROACH}/logs/mc_{{variant}}__{{group}}.log",
    benchmark:
        f"{APPROACH}/benchmarks/mc_{{variant}}__{{group}}.tsv"
    script:
        "../scripts/approach_mc.py"


for _i, _pack in enumerate(A_MC_PACKS, 1):

    rule:
        """Several (variant, case group) Monte Carlos in one job (jobs.approach_mc_per_job):
        each unit's schemes in turn, written as rule approach_mc writes them."""
        name:
            f"approach_mc_pack{_i}"
        input:
            A_SRC,
            kernels=kernels("approach"),
        output:
            [f"{A_WORK}/mc/{v}__{g}__{s}.pkl" for v, g in _pack for s in A_SCHEMES],
        params:
            approach=_A_MC_APPROACH,
            schemes=A_SCHEMES,
            units=[[v, g] for v, g in _pack],
        resources:  # SLURM: a dynamic rule has no profiles/slurm entry; approach_mc's per unit
            runtime=10 * len(_pack),
            mem_mb=1500,
        log:
            f"{APPROACH}/logs/mc_pack{_i}.log",
        benchmark:
            f"{APPROACH}/benchmarks/mc_pack{_i}.tsv"
        script:
            "../scripts/approach_mc.py"


rule approach_convergence:
    """Plain EM vs SQUAREM to the maximum-likelihood estimate on one window (headline case), every
    variant in one job (they share the process start-up, about 0.8 CPU-s a job)."""
    input:
        A_SRC,
        kernels=kernels("approach"),
    output:
        expand(f"{A_WORK}/conv/{{variant}}.pkl", variant=A_VARIANTS),
    params:
        approach=cfg("approach", *A_SCENARIO, "em", "convergence_study"),
        variants=A_VARIANTS,
    log:
        f"{APPROACH}/logs/conv.log",
    benchmark:
        f"{APPROACH}/benchmarks/conv.tsv"
    script:
        "../scripts/approach_convergence.py"


rule approach_crlb:
    """CRLB of (tx, ty) vs data length per variant (headline case), and the roll variant's bound
    against the roll rate with the rate that reaches the claimed accuracy in the published data."""
    input:
        A_SRC,
        src("core/published.py", "data/published.yaml", "approach/readings.py"),
        kernels=kernels("approach"),
        plan=A_PLAN,
    output:
        f"{A_WORK}/crlb.pkl",
    params:
        approach=cfg("approach", *A_SCENARIO, "variants", "roll_rate_study"),
        target=A_TARGET,
    log:
        f"{APPROACH}/logs/crlb.log",
    benchmark:
        f"{APPROACH}/benchmarks/crlb.tsv"
    script:
        "../scripts/approach_crlb.py"


rule approach_stars:
    """The stars variant (beyond the paper, real stars): the bound of (tx, ty, tz) and the
    estimates against stars per image, attitude knowledge and magnitude limit, and the attitude
    knowledge at which the bound reaches the target."""
    input:
        A_SRC + src("approach/alternatives.py", "approach/batch_ml.py"),
        kernels=kernels("approach"),
        plan=A_PLAN,
    output:
        f"{A_WORK}/stars.pkl",
    params:
        approach=cfg("approach", *A_EM, "growing", "alternatives"),
        target=A_TARGET,
    log:
        f"{APPROACH}/logs/stars.log",
    benchmark:
        f"{APPROACH}/benchmarks/stars.tsv"
    script:
        "../scripts/approach_stars.py"


rule approach_stars_outputs:
    """A-X6: the stars study's table and figure (bound, floor, EM-EKF against attitude knowledge
    and magnitude limit)."""
    input:
        stars=f"{A_WORK}/stars.pkl",
        plan=A_PLAN,
        code=src("approach/summaries.py", "approach/labels.py", "report/approach/star_plots.py", "core/figures.py", "core/tables.py",
                 "opnav.mplstyle"),
    output:
        table=report_table(f"{APPROACH}/A-X6_stars", "A-X6", "Paper A"),
        fig=report_figure(f"{APPROACH}/A-X6_stars", "A-X6", "Paper A"),
    params:
        target=A_TARGET,
    log:
        f"{APPROACH}/logs/stars_outputs.log",
    localrule: True
    script:
        "../scripts/approach_stars_outputs.py"


rule approach_tables:
    """A-T1 (Table 1 with published values), A-X1 table and verdict, A-summary.json."""
    input:
        mc=list(A_MC.values()) + list(A_MC_GROWING.values()),
        conv=expand(f"{A_WORK}/conv/{{variant}}.pkl", variant=A_VARIANTS),
        crlb=f"{A_WORK}/crlb.pkl",
        stars=f"{A_WORK}/stars.pkl" if "stars" in A_VARIANTS else [],
        nav_arc=f"{A_WORK}/nav_arc.pkl",
        plan=A_PLAN,
        code=src("approach/labels.py", "approach/summaries.py", "report/approach_text.py", "core/wording.py", "report/approach_views.py",
                 "report/approach/text.py",
                 "approach/readings.py", "approach/setup.py", "core/tables.py", "core/published.py", "data/published.yaml"),
    output:
        t1=report_table(f"{APPROACH}/A-T1_table1", "A-T1", "Paper A"),
        x1=report_table(f"{APPROACH}/A-X1_crlb", "A-X1", "Paper A"),
        verdict=f"{APPROACH}/A-X1_identifiability.md",
        summary=f"{APPROACH}/A-summary.json",
    params:
        approach=cfg("approach", "segments", "convergence_study", "crlb", "prior_sigma", "geometry", "em",
                     "camera"),
        target=A_TARGET,
        profile=config["profile"],
    log:
        f"{APPROACH}/logs/tables.log",
    localrule: True
    script:
        "../scripts/approach_tables.py"


rule approach_nav_arc:
    """The navigation error after compensation against arc length (nav_floor: variant, scheme, arcs;
    A-C7's would_take) and with the tz bias on and off (paper A: tz does not affect navigation)."""
    input:
        A_SRC + src("approach/navfloor.py", "approach/labels.py"),
        kernels=kernels("approach"),
    output:
        f"{A_WORK}/nav_arc.pkl",
    params:
        approach=cfg("approach", *A_EM, "growing", "nav_floor"),
    log:
        f"{APPROACH}/logs/nav_arc.log",
    benchmark:
        f"{APPROACH}/benchmarks/nav_arc.tsv"
    script:
        "../scripts/approach_nav_arc.py"


rule approach_nav_arc_outputs:
    """A-X7: the table and figure of the navigation error against arc length, the paper's limit
    drawn from the analysis plan (A-C7)."""
    input:
        nav_arc=f"{A_WORK}/nav_arc.pkl",
        plan=src("data/analysis_plan.yaml")[0],
        code=src("approach/summaries.py", "report/approach/plots.py", "report/approach/text.py", "core/figures.py",
                 "core/tables.py", "opnav.mplstyle",
                 "report/plan.py"),
    output:
        table=report_table(f"{APPROACH}/A-X7_nav_floor", "A-X7", "Paper A"),
        fig=report_figure(f"{APPROACH}/A-X7_nav_floor", "A-X7", "Paper A"),
    log:
        f"{APPROACH}/logs/nav_arc_outputs.log",
    localrule: True
    script:
        "../scripts/approach_nav_arc_outputs.py"


A_FIGURES = {"f4": ("A-F4", "bias_estimate"), "f5": ("A-F5", "nav_accuracy"),
             "f6": ("A-F6", "nav_error_compensation"), "x4": ("A-X4", "consistency")}


rule approach_figures:
    """A-F4, A-F5, A-F6 and A-X4 (NEES/NIS) for the headline case of every variant. One job
    for all variants: drawing a variant's four figures costs less than the start-up of a
    job's Python, matplotlib and pickles (about 0.65 CPU-s a job, measured)."""
    input:
        **{f"mc_{v}": a_headline_mc_of(v) for v in A_VARIANTS},
        code=src("report/approach/plots.py", "core/figures.py", "opnav.mplstyle", "data/published.yaml"),
    output:
        **{f"{key}_{v}": report_figure(f"{APPROACH}/{fid}_{name}_{v}", fid, "Paper A", v)
           for v in A_VARIANTS for key, (fid, name) in A_FIGURES.items()},
    params:
        variants=A_VARIANTS,
        segments=cfg("approach", "segments"),
    log:
        f"{APPROACH}/logs/figures.log",
    localrule: True
    script:
        "../scripts/approach_figures.py"


rule approach_x1_figure:
    """A-X1 figure: CRLB vs data per variant, EM errors, EM iterations plain vs SQUAREM."""
    input:
        crlb=f"{A_WORK}/crlb.pkl",
        conv=expand(f"{A_WORK}/conv/{{variant}}.pkl", variant=A_VARIANTS),
        x1=f"{APPROACH}/A-X1_crlb.csv",
        plan=A_PLAN,
        code=src("report/approach/plots.py", "core/figures.py", "opnav.mplstyle"),
    output:
        fig=report_figure(f"{APPROACH}/A-X1_crlb", "A-X1", "Paper A"),
    params:
        approach=cfg("approach", "segments"),
        target=A_TARGET,
    log:
        f"{APPROACH}/logs/x1_figure.log",
    localrule: True
    script:
        "../scripts/approach_x1_figure.py"
