# Paper B: Mars powered descent and landmark selection (SPEC section B).

LANDING = res("landing")


rule landing_tables:
    """B-T1 and B-T2, rendered from the config."""
    input:
        src("report/landing/tables.py", "landing/scenario.py", "landing/setup.py", "core/sections.py",
            "landing/trajectory.py", "core/tables.py",
            "core/published.py", "data/published.yaml"),
    output:
        t1=report_table(f"{LANDING}/B-T1_initial_state", "B-T1", "Paper B"),
        t2=report_table(f"{LANDING}/B-T2_error_bounds", "B-T2", "Paper B"),
    params:
        landing=cfg("landing", "initial_state", "mc", "duration_s", "gravity_mps2", "yaw_deg",
                    "terminal_accel_mps2"),
    log:
        f"{LANDING}/logs/landing_tables.log",
    localrule: True
    script:
        "../scripts/landing_tables.py"


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

from opnav.landing.setup import Setup as _BSetup, scenario_sections

try:
    B_SCENARIO_CFG = scenario_sections(config["landing"])
    B_HEADLINE = _BSetup.from_config(config["landing"]).headline()
except ValueError as exc:
    config_exit(exc)  # checked before (opnav.core.checks): the one way out, should it happen
# Camera scenarios (landing.scenarios): each flies its own Monte Carlo under
# results/landing/mc/{bscn}/ and gets its own B-F5, B-F6, B-F7, B-T3, B-X1 (file
# stems end in _{bscn}, as paper A's variants); B-summary.json gathers them all,
# the headline scenario's numbers also at its top level.
B_SCENARIOS = list(B_SCENARIO_CFG)
B_METHODS = list(config["landing"]["mc"]["methods"])
# your own landmark-selection metrics (landing.custom_methods, opnav.landing.methods; docs/usage.md,
# "Your own method"): flown beside B_METHODS on every run of every scenario, shown in B-T3, B-F6,
# B-F7, the end-phase table and B-X1, and timed; not in the replication (no verdict reads them).
# Only their own jobs see their entries (b_sim): registering one reruns no built-in method's job.
from opnav.landing.methods import source_files as b_custom_files

B_CUSTOM_CFG = config["landing"].get("custom_methods") or {}
B_CUSTOM = list(B_CUSTOM_CFG)
B_TABLE_METHODS = B_METHODS + B_CUSTOM   # B-T3's rows
_BEQ = config["landing"]["equivalence"]
# the equivalence test's methods, reference and negative controls beyond B_METHODS
B_EQ_METHODS = [m for m in dict.fromkeys([_BEQ["reference"], *_BEQ["methods"], *_BEQ["controls"]])
                if m not in B_METHODS]
B_CHUNKS = [chunk_label(c) for c in mc_chunks(config["landing"]["mc"]["n_runs"],
                                               config["landing"]["mc"]["runs_per_job"])]
_B_SIM_KEYS = ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu", "camera",
               "landmarks", "filter", "planner")
B_SIMS = {s: canonical({**{k: c[k] for k in _B_SIM_KEYS},
                        "mc": {k: config["landing"]["mc"][k] for k in ("base_seed", "bounds")}})
          for s, c in B_SCENARIO_CFG.items()}
# B-X2 ablations sweep values of landing.camera itself (fov_deg), so they fly the
# base camera with no scenario overlay (e.g. 45 deg FOV with interior's 10 deg tilt
# would lose the site)
B_SIM = canonical({**{k: config["landing"][k] for k in _B_SIM_KEYS},
                   "mc": {k: config["landing"]["mc"][k] for k in ("base_seed", "bounds")}})
B_SRC = with_kernels("landing", src(
    "landing/trajectory.py", "landing/imu.py", "landing/camera.py", "landing/landmarks.py",
    "landing/measurement.py", "landing/ekf.py", "landing/planning/reference.py",
    "landing/planner.py", "landing/methods.py", "core/registry.py", "landing/descent.py", "landing/montecarlo.py", "landing/scenario.py",
    "landing/depth_map.py", "landing/metrics.py", "landing/casadi_model.py", "core/rotations.py",
    "landing/setup.py", "core/sections.py"))
B_SCN_RE = "|".join(B_SCENARIOS)


def b_sim(scn, methods=()):
    """B_SIMS[scn], with the landing.custom_methods entries of the custom methods among ``methods``."""
    own = {m: B_CUSTOM_CFG[m] for m in methods if m in B_CUSTOM_CFG}
    return canonical({**B_SIMS[scn], "custom_methods": own}) if own else B_SIMS[scn]


def b_custom_src(methods):
    """The files the custom methods among ``methods`` live in (an edit re-flies them)."""
    return b_custom_files({m: B_CUSTOM_CFG[m] for m in methods if m in B_CUSTOM_CFG})


# B-X1's runs per scenario (landing.extra.n_runs): the methods only B-X1 flies fly runs
# 0..n-1 (their cost is set by the edge calls' planned posteriors, not by the paper's sample)
# (its names are landing.scenarios' own: opnav.core.checks refuses any other)
_BX1_RUNS = config["landing"]["extra"].get("n_runs", {})


def b_runs(scn, method):
    """Runs flown by ``method`` in scenario ``scn``: landing.mc.n_runs, or, for a method only
    B-X1 flies, landing.extra.n_runs[scn] where set (never more)."""
    n = config["landing"]["mc"]["n_runs"]
    if method not in B_TABLE_METHODS and method not in B_EQ_METHODS and scn in _BX1_RUNS:
        n = min(n, int(_BX1_RUNS[scn]))
    return n


def b_chunks(scn, method):
    """The chunk labels of ``method``'s Monte Carlo in scenario ``scn`` (:func:`b_runs`)."""
    if b_runs(scn, method) == config["landing"]["mc"]["n_runs"]:
        return B_CHUNKS
    return [chunk_label(c) for c in mc_chunks(b_runs(scn, method), config["landing"]["mc"]["runs_per_job"])]


def b_mc(scn, methods):
    """Each method's Monte Carlo in scenario ``scn``: the gathered file, or the one chunk
    itself when one job flies every run (no gather job to start: ``montecarlo.stack_runs``
    already holds the runs and their planning calls in run order, as gathered)."""
    out = []
    for m in methods:
        ch = b_chunks(scn, m)
        out.append(f"{LANDING}/mc/{scn}/chunks/{m}/{ch[0]}.npz" if len(ch) == 1 else f"{LANDING}/mc/{scn}/{m}.npz")
    return out


# landing.mc.methods_per_job > 1 (tiny profiles): the Monte Carlo's methods (paper,
# B-X1 extras, equivalence controls, in that order) in packs of that many, one job per
# pack, scenario and chunk (rules landing_mc_pack1, ...) that flies each method's chunk in
# turn and writes the same files as landing_mc_chunk, which flies the methods in no pack.
_B_K = config["landing"]["mc"]["methods_per_job"]
B_MC_METHODS = list(dict.fromkeys([*B_TABLE_METHODS, *config["landing"]["extra"]["methods"], *B_EQ_METHODS]))
B_PACKS = [B_MC_METHODS[i:i + _B_K] for i in range(0, len(B_MC_METHODS), _B_K)] if _B_K > 1 else []
_B_PACKED = [m for p in B_PACKS for m in p]


rule landing_mc_chunk:
    """One Monte-Carlo job: runs of one planning method in one camera scenario (scatter)."""
    input:
        B_SRC,
        lambda wc: b_custom_src([wc.bmethod]),
        kernels=kernels("landing"),
    output:
        f"{LANDING}/mc/{{bscn}}/chunks/{{bmethod}}/{{bchunk}}.npz",
    wildcard_constraints:
        bscn=B_SCN_RE,
        bmethod="".join(f"(?!{m}(?![a-z0-9_-]))" for m in _B_PACKED) + "[a-z][a-z0-9_-]*",   # not in a pack
        bchunk=CHUNK_PATTERN,
    params:
        landing=lambda wc: b_sim(wc.bscn, [wc.bmethod]),
        runs=lambda wc: chunk_runs(wc.bchunk),
        # the pick-ratio diagnostic scores every detected landmark once more per planning
        # call (half an information metric's descent); only B-T3 (landing.mc.methods) shows it
        pick_ratio=lambda wc: wc.bmethod in B_METHODS,
        # runs flown per batch (speed and memory only: the numbers do not depend on it)
        batch_size=config["landing"]["mc"]["batch_size"],
    # the longest jobs, and the timing replay waits for them: started first, so
    # that no core idles at the end of a run (speed only)
    priority: 10
    log:
        f"{LANDING}/logs/mc_{{bscn}}_{{bmethod}}_chunk{{bchunk}}.log",
    benchmark:
        f"{LANDING}/benchmarks/mc_{{bscn}}_{{bmethod}}_chunk{{bchunk}}.tsv"
    script:
        "../scripts/landing_mc_chunk.py"


for _i, _pack in enumerate(B_PACKS, 1):

    rule:
        """One Monte-Carlo job for several methods (landing.mc.methods_per_job): each
        method's chunk of runs in one camera scenario, one method after the other."""
        name:
            f"landing_mc_pack{_i}"
        input:
            B_SRC,
            b_custom_src(_pack),
            kernels=kernels("landing"),
        output:
            [f"{LANDING}/mc/{{bscn}}/chunks/{m}/{{bchunk}}.npz" for m in _pack],
        wildcard_constraints:
            bscn=B_SCN_RE,
            bchunk=CHUNK_PATTERN,
        params:
            landing=lambda wc, _pack=_pack: b_sim(wc.bscn, _pack),
            runs=lambda wc: chunk_runs(wc.bchunk),
            methods=_pack,
            pick_ratio=[m in B_METHODS for m in _pack],
            batch_size=config["landing"]["mc"]["batch_size"],
        priority: 10
        resources:  # SLURM: a dynamic rule has no profiles/slurm entry; landing_mc_chunk's per method
            runtime=10 * len(_pack),
            mem_mb=1400,
        log:
            f"{LANDING}/logs/mc_{{bscn}}_pack{_i}_chunk{{bchunk}}.log",
        benchmark:
            f"{LANDING}/benchmarks/mc_{{bscn}}_pack{_i}_chunk{{bchunk}}.tsv"
        script:
            "../scripts/landing_mc_chunk.py"


rule landing_mc_gather:
    """All runs of one method in one scenario, in run order (gather)."""
    input:
        lambda wc: [f"{LANDING}/mc/{wc.bscn}/chunks/{wc.bmethod}/{c}.npz" for c in b_chunks(wc.bscn, wc.bmethod)],
    output:
        f"{LANDING}/mc/{{bscn}}/{{bmethod}}.npz",
    wildcard_constraints:
        bscn=B_SCN_RE,
        bmethod="[a-z][a-z0-9_-]*",
    log:
        f"{LANDING}/logs/mc_{{bscn}}_{{bmethod}}_gather.log",
    localrule: True
    script:
        "../scripts/landing_mc_gather.py"


rule landing_true_states:
    """B-F4: the truth trajectory (the same in every camera scenario)."""
    input:
        src("landing/trajectory.py", "landing/setup.py", "core/sections.py", "report/landing/plots.py",
            "core/figures.py", "opnav.mplstyle"),
    output:
        f4=report_figure(f"{LANDING}/B-F4_true_states", "B-F4", "Paper B"),
    params:
        landing=cfg("landing", "duration_s", "gravity_mps2", "initial_state", "yaw_deg",
                    "terminal_accel_mps2"),
    log:
        f"{LANDING}/logs/true_states.log",
    localrule: True
    script:
        "../scripts/landing_true_states.py"


rule landing_single:
    """The single descent of one scenario and B-F5 (depth-error maps)."""
    input:
        B_SRC,
        src("report/landing/plots.py", "core/figures.py", "opnav.mplstyle"),
        kernels=kernels("landing"),
    output:
        summary=f"{LANDING}/single/summary_{{bscn}}.json",
        f5=report_figure(f"{LANDING}/B-F5_depth_error_map_{{bscn}}", "B-F5", "Paper B", "{bscn}"),
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: canonical({**B_SIMS[wc.bscn], "single": config["landing"]["single"],
                                      "figures": config["landing"]["figures"]}),
    log:
        f"{LANDING}/logs/single_{{bscn}}.log",
    benchmark:
        f"{LANDING}/benchmarks/single_{{bscn}}.tsv"
    script:
        "../scripts/landing_single.py"


rule landing_tuning:
    """Out-of-sample filter tuning: every candidate on runs of landing.tuning's own seed
    stream in every camera scenario; the one tuning for all, checked against the config."""
    input:
        B_SRC,
        src("landing/tuning.py", "landing/setup.py", "core/sections.py"),
        kernels=kernels("landing"),
    output:
        f"{LANDING}/tuning.json",
    params:
        scenarios=B_SIMS,
        tuning=canonical(config["landing"]["tuning"]),
    log:
        f"{LANDING}/logs/tuning.log",
    benchmark:
        f"{LANDING}/benchmarks/tuning.tsv"
    script:
        "../scripts/landing_tuning.py"


rule landing_retuned:
    """The filter retuned on the tuning runs alone (landing.tuning: per camera, the bearing-noise
    scale closest to the NEES band's centre) flown on the Monte Carlo's own runs by the tuning
    method, beside the paper tuning's Monte Carlo: the held-out NEES of both (B-T3 NEES table)."""
    input:
        B_SRC,
        src("landing/tuning.py", "report/landing/summary.py", "report/landing/timing_text.py", "landing/setup.py", "core/sections.py"),
        tuning=f"{LANDING}/tuning.json",
        mc=lambda wc: b_mc(wc.bscn, [config["landing"]["tuning"]["method"]])[0],
        kernels=kernels("landing"),
    output:
        record=f"{LANDING}/retuned/{{bscn}}.json",
        table=table_outputs(f"{LANDING}/B-T3_nees_{{bscn}}"),
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        landing=lambda wc: B_SIMS[wc.bscn],
        method=config["landing"]["tuning"]["method"],
    # a few CPU-s (300 descents of one method; 1.0-1.2 CPU-s a job in the quick profile)
    localrule: True
    log:
        f"{LANDING}/logs/retuned_{{bscn}}.log",
    benchmark:
        f"{LANDING}/benchmarks/retuned_{{bscn}}.tsv"
    script:
        "../scripts/landing_retuned.py"


rule landing_summary:
    """B-T3 of one scenario beside the published 29.03 %, its summary JSON (with the
    equivalence test of "almost the same accuracy" and its negative controls), and B-F6
    (3-sigma envelopes per axis) and B-F7 (planning-time box plots): one job reads the
    scenario's Monte Carlo and planning times once for the table and the figures."""
    input:
        mc=lambda wc: b_mc(wc.bscn, B_TABLE_METHODS),
        mc_eq=lambda wc: b_mc(wc.bscn, B_EQ_METHODS),
        timing=lambda wc: expand(B_TIMING, bscn=wc.bscn),   # replays + other (landing_timing.smk)
        single=f"{LANDING}/single/summary_{{bscn}}.json",
        tuning=f"{LANDING}/tuning.json",
        retuned=f"{LANDING}/retuned/{{bscn}}.json",   # the retuned filter's held-out NEES beside the paper's
        plan=src("data/analysis_plan.yaml")[0],  # B-C1's margin and same-pick threshold, B-C2's step
        code=with_kernels("landing", src(
            "landing/montecarlo.py", "landing/timing.py", "landing/timing_summary.py", "landing/scenario.py", "report/landing/plots.py",
            "report/landing/summary.py", "report/landing/timing_text.py", "landing/accuracy.py", "landing/equivalence.py",
            "landing/tuning.py",
            "landing/ranking.py", "landing/trajectory.py",
            "landing/setup.py", "core/sections.py",
            "core/tables.py", "core/figures.py", "opnav.mplstyle", "core/published.py", "data/published.yaml")),
        kernels=kernels("landing"),
    output:
        t3=report_table(f"{LANDING}/B-T3_summary_{{bscn}}", "B-T3", "Paper B"),
        summary=f"{LANDING}/summaries/B-summary_{{bscn}}.json",
        end_phase=table_outputs(f"{LANDING}/B-T3_end_phase_{{bscn}}"),
        f6=report_figure(f"{LANDING}/B-F6_nav_error_envelopes_{{bscn}}", "B-F6", "Paper B", "{bscn}"),
        f7=report_figure(f"{LANDING}/B-F7_planning_time_{{bscn}}", "B-F7", "Paper B", "{bscn}"),
    wildcard_constraints:
        bscn=B_SCN_RE,
    params:
        methods=B_TABLE_METHODS,
        eq_methods=B_EQ_METHODS,
        custom=canonical(B_CUSTOM_CFG),    # legend names and colours of your own methods
        equivalence=canonical(_BEQ),
        converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
        eval_path=config["landing"]["planner"]["eval_path"],
        landing=cfg("landing", "duration_s", "gravity_mps2", "initial_state", "yaw_deg",
                    "terminal_accel_mps2"),
        # the vision cut-off (the end-phase table counts what it does in truth)
        cutoff={k: config["landing"]["filter"][k] for k in ("min_update_altitude_m", "update_altitude_margin_m")},
    log:
        f"{LANDING}/logs/summary_{{bscn}}.log",
    localrule: True
    script:
        "../scripts/landing_summary.py"


rule landing_summary_all:
    """B-summary.json: every scenario's summary, the headline's also at the top level."""
    input:
        parts=expand(f"{LANDING}/summaries/B-summary_{{bscn}}.json", bscn=B_SCENARIOS),
        code=src("report/landing/summary.py", "report/landing/timing_text.py"),
    output:
        f"{LANDING}/B-summary.json",
    params:
        scenarios=B_SCENARIOS,
        headline=B_HEADLINE,
        cameras={s: canonical(c["camera"]) for s, c in B_SCENARIO_CFG.items()},
    log:
        f"{LANDING}/logs/summary_all.log",
    localrule: True
    script:
        "../scripts/landing_combine.py"
