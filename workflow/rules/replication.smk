# The replication sample (issue 42): the Monte Carlo the claims' verdicts read, flown again
# on an independent seed base (config `replication`: base seeds + seed_offset), and the
# planning-time replay timed a second time. No new science: the same scripts as the main
# sample with other seeds and sizes; results/replication/ holds it. paper_claims re-judges
# the claims on it (verdict_replication; 'unstable' where the two verdicts differ).
# Included after landing_timing.smk (reuses A_*, B_*, B_REPLAYED, TIMING_CODE, _BT, all_cores, b_mc)
# and before paper.smk.
from opnav.landing.montecarlo import chunk_label as _rep_label, chunk_runs as _rep_runs

REP_CFG = config["replication"]
REP = res("replication")
REPLICATION_SUMMARIES = {}

if REP_CFG["enabled"]:
    _rep_a = {**cfg("approach"), "base_seed": config["approach"]["base_seed"] + REP_CFG["seed_offset"],
              "n_seeds": REP_CFG["approach_n_seeds"]}
    _REP_A_KEYS = A_EM + (("growing",) if config["approach"]["growing"]["methods"] else ())
    REP_A_MC = [f"{REP}/approach/mc/{v}__headline__{s}.pkl" for v in A_VARIANTS for s in A_SCHEMES]
    REP_B_CHUNK = _rep_label(range(REP_CFG["landing_n_runs"]))
    # what the replication flies (its Monte Carlo rules below): the timing claims' methods and
    # the controls; its timing replays the recorded calls of those and times the claims' methods
    REP_B_FLOWN = list(dict.fromkeys([*B_METHODS, *B_EQ_METHODS]))
    REP_B_SIMS = {s: canonical({**c, "mc": {**c["mc"], "base_seed": c["mc"]["base_seed"] + REP_CFG["seed_offset"]}})
                  for s, c in B_SIMS.items()}

    REPLICATION_SUMMARIES = {"rep_summary_A": f"{REP}/approach/A-summary.json",
                             "rep_a_table1": f"{REP}/approach/A-T1_table1.csv",
                             "rep_summary_B": f"{REP}/landing/B-summary.json"}

    rule replication_approach_mc:
        """Paper A's headline case, every variant and EM scheme, on the replication's seeds."""
        input:
            A_SRC,
            kernels=kernels("approach"),
        output:
            [f"{REP}/approach/mc/{{variant}}__{{group}}__{s}.pkl" for s in A_SCHEMES],
        wildcard_constraints:
            group="headline",
        params:
            approach=canonical({k: _rep_a[k] for k in _REP_A_KEYS}),
            schemes=A_SCHEMES,
        log:
            f"{REP}/logs/approach_mc_{{variant}}__{{group}}.log",
        benchmark:
            f"{REP}/benchmarks/approach_mc_{{variant}}__{{group}}.tsv"
        script:
            "../scripts/approach_mc.py"

    rule replication_approach_tables:
        """A-T1 (headline rows) and A-summary of the replication sample (bounds and convergence
        study from the main sample: they do not depend on the noise seeds' draw)."""
        input:
            mc=REP_A_MC,
            conv=expand(f"{A_WORK}/conv/{{variant}}.pkl", variant=A_VARIANTS),
            crlb=f"{A_WORK}/crlb.pkl",
            stars=f"{A_WORK}/stars.pkl" if "stars" in A_VARIANTS else [],
            plan=A_PLAN,
            code=src("approach/labels.py", "approach/summaries.py", "report/approach_text.py", "core/wording.py", "report/approach_views.py",
                     "report/approach/text.py",
                     "approach/setup.py", "core/tables.py"),
        output:
            t1=table_outputs(f"{REP}/approach/A-T1_table1"),
            x1=table_outputs(f"{REP}/approach/A-X1_crlb"),
            verdict=f"{REP}/approach/A-X1_identifiability.md",
            summary=f"{REP}/approach/A-summary.json",
        params:
            approach=cfg("approach", "segments", "convergence_study", "crlb", "prior_sigma", "geometry", "em"),
            target=A_TARGET,
            profile=config["profile"],
        log:
            f"{REP}/logs/approach_tables.log",
        localrule: True
        script:
            "../scripts/approach_tables.py"

    rule replication_landing_mc:
        """Paper B's compared methods and controls in one camera scenario, on the replication's seeds."""
        input:
            B_SRC,
            kernels=kernels("landing"),
        output:
            f"{REP}/landing/mc/{{bscn}}/chunks/{{bmethod}}/{{bchunk}}.npz",
        wildcard_constraints:
            bscn=B_SCN_RE,
            bmethod="[a-z][a-z0-9_-]*",
            bchunk=CHUNK_PATTERN,
        params:
            landing=lambda wc: REP_B_SIMS[wc.bscn],
            runs=lambda wc: _rep_runs(wc.bchunk),
            pick_ratio=lambda wc: wc.bmethod in B_METHODS,
            batch_size=config["landing"]["mc"]["batch_size"],
        priority: 10
        log:
            f"{REP}/logs/landing_mc_{{bscn}}_{{bmethod}}_{{bchunk}}.log",
        benchmark:
            f"{REP}/benchmarks/landing_mc_{{bscn}}_{{bmethod}}_{{bchunk}}.tsv"
        script:
            "../scripts/landing_mc_chunk.py"

    rule replication_landing_timing_replays:
        """The replication's independent replays (separate processes, alone on the machine) of the
        compiled calls its timing claims read (B-C4, B-C9: landing.mc.methods), on the main
        sample's recorded calls of the methods the replication flies (what varies is the clock)."""
        input:
            mc=lambda wc: b_mc(wc.bscn, REP_B_FLOWN),
            code=TIMING_CODE + src("data/published.yaml"),
            kernels=kernels("landing"),
        output:
            replays=[f"{REP}/landing/timing/{{bscn}}/replay{r}.npz" for r in range(_BT["n_replays"])],
        wildcard_constraints:
            bscn=B_SCN_RE,
        params:
            landing=lambda wc: B_SIMS[wc.bscn],
            flown=REP_B_FLOWN,
            replayed=B_REPLAYED,
            max_calls=_BT["max_calls"],
        threads: all_cores()     # alone, as the main replays (landing_timing.smk)
        log:
            f"{REP}/logs/landing_timing_replays_{{bscn}}.log",
        benchmark:
            f"{REP}/benchmarks/landing_timing_replays_{{bscn}}.tsv"
        script:
            "../scripts/landing_timing.py"

    rule replication_landing_timing:
        """The paper's definition of the replicated timing claims' methods on its subset of the
        calls (B-C4's other path), timed once beside other jobs: only what the replicated timing
        claims read (B-X1's methods and the LAPACK SVD are the main replay's)."""
        input:
            mc=lambda wc: b_mc(wc.bscn, REP_B_FLOWN),
            code=TIMING_CODE,
            kernels=kernels("landing"),
        output:
            f"{REP}/landing/timing/{{bscn}}/other.npz",
        wildcard_constraints:
            bscn=B_SCN_RE,
        params:
            landing=lambda wc: B_SIMS[wc.bscn],
            flown=REP_B_FLOWN,
            methods=B_REPLAYED,
            main=[],
            alt=B_REPLAYED,
            max_calls=_BT["max_calls"],
            max_calls_paper=_BT["max_calls_paper"],
        log:
            f"{REP}/logs/landing_timing_{{bscn}}.log",
        benchmark:
            f"{REP}/benchmarks/landing_timing_{{bscn}}.tsv"
        script:
            "../scripts/landing_timing.py"

    rule replication_landing_summary:
        """B-T3 and the summary JSON of one scenario on the replication sample."""
        input:
            mc=lambda wc: [f"{REP}/landing/mc/{wc.bscn}/chunks/{m}/{REP_B_CHUNK}.npz" for m in B_METHODS],
            mc_eq=lambda wc: [f"{REP}/landing/mc/{wc.bscn}/chunks/{m}/{REP_B_CHUNK}.npz" for m in B_EQ_METHODS],
            timing=[*rules.replication_landing_timing_replays.output.replays, *rules.replication_landing_timing.output],
            single=f"{LANDING}/single/summary_{{bscn}}.json",
            tuning=f"{LANDING}/tuning.json",
            plan=src("data/analysis_plan.yaml")[0],  # B-C1's margin and same-pick threshold, B-C2's step
            code=src("landing/montecarlo.py", "landing/timing.py", "landing/timing_summary.py", "report/landing/summary.py", "report/landing/timing_text.py", "landing/accuracy.py", "landing/equivalence.py",
                     "landing/ranking.py", "landing/trajectory.py"),
        output:
            t3=table_outputs(f"{REP}/landing/B-T3_summary_{{bscn}}"),
            summary=f"{REP}/landing/summaries/B-summary_{{bscn}}.json",
            end_phase=table_outputs(f"{REP}/landing/B-T3_end_phase_{{bscn}}"),
            f6=figure_outputs(f"{REP}/landing/B-F6_nav_error_envelopes_{{bscn}}"),
            f7=figure_outputs(f"{REP}/landing/B-F7_planning_time_{{bscn}}"),
        wildcard_constraints:
            bscn=B_SCN_RE,
        params:
            methods=B_METHODS,
            eq_methods=B_EQ_METHODS,
            equivalence=canonical(_BEQ),
            converged_pos_err_m=config["landing"]["mc"]["converged_pos_err_m"],
            eval_path=config["landing"]["planner"]["eval_path"],
            landing=cfg("landing", "duration_s", "gravity_mps2", "initial_state", "yaw_deg",
                        "terminal_accel_mps2"),
            cutoff={k: config["landing"]["filter"][k] for k in ("min_update_altitude_m", "update_altitude_margin_m")},
        log:
            f"{REP}/logs/landing_summary_{{bscn}}.log",
        localrule: True
        script:
            "../scripts/landing_summary.py"

    rule replication_landing_summary_all:
        """B-summary.json of the replication sample."""
        input:
            parts=expand(f"{REP}/landing/summaries/B-summary_{{bscn}}.json", bscn=B_SCENARIOS),
            code=src("report/landing/summary.py", "report/landing/timing_text.py"),
        output:
            f"{REP}/landing/B-summary.json",
        params:
            scenarios=B_SCENARIOS,
            headline=B_HEADLINE,
            cameras={s: canonical(c["camera"]) for s, c in B_SCENARIO_CFG.items()},
        log:
            f"{REP}/logs/landing_summary_all.log",
        localrule: True
        script:
            "../scripts/landing_combine.py"
