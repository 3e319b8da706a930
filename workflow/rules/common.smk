# Shared helpers: config validation, output paths, and the final outputs (final_outputs).
import opnav.approach, opnav.landing  # noqa: E402,F401  each registers its kernel modules
from opnav.core import compiled as _compiled  # noqa: E402
from opnav.core.errors import ConfigError  # noqa: E402
from opnav.preflight import check_config  # noqa: E402
from opnav.core.snakeio import compact_params_change_reasons  # noqa: E402

# "Params have changed" reasons name the changed keys, not whole config sections.
compact_params_change_reasons()

# Every config problem before any job, in one pass, one line each naming the key (and
# the study or scenario): the schema (defaults filled in place, finite numbers, strict
# integers), the cross-key physics checks of opnav.core.checks (camera scenarios, growing
# windows, headline scenario, results_dir), every parameter study's values, and the
# job-graph bounds (limits), before the DAG is built: the same function the `opnav`
# CLI uses (opnav.preflight: the core's checks, then each paper's physics checks, then
# the studies). config_exit (Snakefile) is the one way out for them.
try:
    check_config(config, root=workflow.basedir, workdir=Path.cwd(), workflow=True)
except ConfigError as exc:
    config_exit(exc)

RESULTS = config["results_dir"]

report: "../report/workflow.rst"
SRC = Path(workflow.basedir) / "src" / "opnav"



def stop_rate_limit_timers():
    """Cancel the scheduler's pending job-rate re-check timers (threading.Timer, not
    daemon threads: Python would wait for them at exit); see the Snakefile."""
    import threading

    for t in threading.enumerate():
        if isinstance(t, threading.Timer):
            t.cancel()


def res(*parts):
    """Path under the results directory."""
    return str(Path(RESULTS, *parts))


# Compiled kernels (kernels.smk): the modules each paper package registers
# (opnav.core.compiled.register_kernel_modules, read without importing numba) and the core's.
KERNEL_PAPERS = ("approach", "landing")


def kernel_modules(paper):
    """The registered kernel modules the jobs of ``paper`` (KERNEL_PAPERS) run: the core's
    (opnav.core.rotations, ...) and those its package registered."""
    return list(_compiled.kernel_modules(f"opnav.{paper}"))


def kernel_src(paper):
    """opnav/core/compiled.py, opnav/core/numba_adapter.py and the source files of kernel_modules(paper)."""
    return [str(p) for p in _compiled.kernel_sources(f"opnav.{paper}")]


def with_kernels(paper, files):
    """``files`` and kernel_src(paper), each once: a module its package registered
    is an input of its paper's rules (editing it reruns them) without being named there."""
    return list(dict.fromkeys([*files, *kernel_src(paper)]))


def kernels(paper):
    """Input of a rule whose jobs call ``paper``'s compiled kernels: rule compile_kernels'
    output for that paper (it orders the job after the cache is filled). A plain input,
    not ancient(): the job's src inputs hold the same kernel modules (with_kernels), so a
    recompile reruns only jobs an edit reruns anyway; as ancient(), a job whose own src
    changed was not scheduled in the run that recompiled (Snakemake 9.27: an edit of
    landing/montecarlo.py plus a pending compile_kernels ran compile_kernels alone, and
    the stale Monte Carlo was kept until the next invocation)."""
    return res("kernels", f"{paper}.json")


def src(*modules):
    """The package modules a rule depends on, so editing one reruns the rule."""
    return [str(SRC / m) for m in modules]


def canonical(value):
    """A deep copy with dict keys sorted, so `params:` compare equal whatever the
    key order in the YAML (Snakemake compares params by their text)."""
    if isinstance(value, dict):
        return {k: canonical(value[k]) for k in sorted(value)}
    if isinstance(value, (list, tuple)):
        return [canonical(v) for v in value]
    return value


from opnav.core.planvalues import with_plan_values  # noqa: E402


def cfg(section, *keys):
    """The config values that a rule's params hold, sorted (canonical), with the analysis plan's
    numbers the paper code computes with inside the sub-sections that use them (their one home
    is the plan; carried in params, a change of one reruns the rule: opnav.core.planvalues);
    e.g. cfg("landing", "mc", "initial_state") -> {"initial_state": ..., "mc": ...}."""
    sec = config[section]
    return canonical(with_plan_values(section, {k: sec[k] for k in keys} if keys else sec))


def table_outputs(stem):
    """A table is written as CSV, LaTeX and Markdown."""
    return [f"{stem}.csv", f"{stem}.tex", f"{stem}.md"]


def figure_outputs(stem):
    """A figure is written as PDF and PNG."""
    return [f"{stem}.pdf", f"{stem}.png"]


def _caption(caption_id):
    path = Path(workflow.basedir) / "workflow" / "report" / f"{caption_id}.rst"
    if not path.is_file():
        raise FileNotFoundError(f"missing report caption {path} for output id {caption_id}")
    return str(path)


def report_table(stem, caption_id, category, subcategory=None):
    """Table outputs; the CSV goes into `snakemake --report` with its caption, under its
    output id as subcategory unless one is given (never the report's catch-all "Other")."""
    csv, tex, md = table_outputs(stem)
    if (Path(workflow.basedir) / "workflow" / "report" / f"{caption_id}.table.rst").is_file():
        caption_id += ".table"  # the table's own caption where a figure shares its id
    return [report(csv, caption=_caption(caption_id), category=category,
                   subcategory=subcategory or caption_id), tex, md]


def report_figure(stem, caption_id, category, subcategory=None):
    """Figure outputs; the PNG goes into `snakemake --report` with its caption, under its
    output id as subcategory unless one is given."""
    pdf, png = figure_outputs(stem)
    return [pdf, report(png, caption=_caption(caption_id), category=category,
                        subcategory=subcategory or caption_id)]


def result_outputs():
    """Every final table, figure and summary of both papers and of the parameter studies
    (not the manuscript's own files): what the manuscript floats and macros draw from.
    Reads the rules at call time, so call it once the rule files are included."""
    a = [*rules.approach_tables.output, *rules.approach_x1_figure.output,
         *rules.approach_figures.output,
         *rules.approach_x2_tables.output.table, rules.approach_x2_tables.output.summary,
         *rules.approach_x2_figure.output]
    if "stars" in config["approach"]["variants"]:
        a += [*rules.approach_stars_outputs.output.table, *rules.approach_stars_outputs.output.fig]
    a += [*rules.approach_nav_arc_outputs.output.table, *rules.approach_nav_arc_outputs.output.fig]
    if A_CUSTOM:    # your own estimators (approach_custom.smk)
        a += [*rules.approach_custom_outputs.output.table, *rules.approach_custom_outputs.output.fig]
    if HAVE_BSK:
        a += [*rules.approach_peer_tables.output.table, rules.approach_peer_tables.output.summary,
              *rules.approach_peer_figure.output]
    b = [*rules.landing_tables.output, *rules.landing_true_states.output,
         *expand(rules.landing_single.output.f5, bscn=B_SCENARIOS),
         *expand([*rules.landing_summary.output.f6, *rules.landing_summary.output.f7], bscn=B_SCENARIOS),
         *expand(rules.landing_timing_replays.output.f7o, bscn=B_SCENARIOS),
         *expand(rules.landing_summary.output.t3, bscn=B_SCENARIOS),
         *rules.landing_summary_all.output,
         *expand(rules.landing_x1_summary.output.f, bscn=B_SCENARIOS),
         *expand(rules.landing_x1_summary.output.t, bscn=B_SCENARIOS),
         *rules.landing_x1_summary_all.output]
    studies = [t for ts in STUDY_TARGETS.values() for t in ts]
    return [str(t) for t in a + b + studies]


def final_outputs():
    """Everything `rule all` builds: result_outputs(), the manuscript's generated inputs
    and, with LaTeX and paper.build_pdf, the PDF. The one list of final outputs."""
    out = result_outputs() + [str(f) for outs in PAPER_INPUTS for f in outs]
    if config["paper"]["build_pdf"] and HAVE_LATEX:
        out.append(str(rules.paper_pdf.output[0]))
    return out


# Helpers of the rule files, kept here so no .smk file mixes rules and functions
# (snakemake --lint). They read globals those files define, at call time.


# approach.smk
def a_groups(variant):
    if variant not in config["approach"]["table1_variants"]:
        return ["headline"]
    return A_GROUPS if config["approach"]["scatter"] == "group" else ["all"]


# approach.smk
def a_headline_mc_of(variant):
    """The headline group's Monte-Carlo pickles of a variant: every sliding scheme and every
    growing one (A_MC_GROWING, approach.smk)."""
    g = a_groups(variant)[0]  # the group holding T1-01
    return [A_MC[(variant, g, m)] for m in A_METHODS] + [
        p for (v, gg, m), p in A_MC_GROWING.items() if v == variant and gg == g]


# paper.smk
def _floats(part):
    """The part's final figures (PDF) and tables (.tex), in id order; then its parameter
    studies' (studies.smk), whose captions are generated beside them."""
    prefix = str(Path(RESULTS, part)) + os.sep
    keep = [t for t in _targets if t.startswith(prefix) and t.endswith((".pdf", ".tex"))]
    own = sorted(keep, key=lambda p: (Path(p).stem.split("_")[0][2:3] != "T", Path(p).stem))
    studies = [t for name, s in sorted(STUDIES.items(), key=lambda kv: (kv[1].id, kv[0]))
               if s.paper == part for t in STUDY_TARGETS[name] if t.endswith((".pdf", ".tex"))]
    return own + studies


# studies.smk
def _study_units(s):
    return [f"{v}__{m}" if v else m for v, m in s.units]


# studies.smk
def _study_runs(s):
    """(chunk file, instance label) for every run chunk of every value of study s: one
    job per (simulation config, chunk) flies every method (and variant) of the studies
    that share that simulation, so a job's start-up is paid once per value, not per method."""
    chunks = [chunk_label(c) for c in mc_chunks(s.runs, s.runs_per_job)]
    return [(f"{STUDIES_DIR}/runs/{s.paper}/{i.digest}/{c}.csv", i.label)
            for i in s.instances for c in chunks]


# studies.smk
def _study_job_units(studies):
    """(paper, digest, chunk) -> the sorted methods (paper A: variant__method) that job
    flies: the union over the studies reading that chunk."""
    out = {}
    for s in studies.values():
        for i in s.instances:
            for c in mc_chunks(s.runs, s.runs_per_job):
                out.setdefault((s.paper, i.digest, chunk_label(c)), set()).update(_study_units(s))
    return {k: sorted(v) for k, v in out.items()}
