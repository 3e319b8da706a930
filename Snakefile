# opnav-repro: regenerate every table and figure of both papers.
#   snakemake --cores 2                               full reproduction
#   snakemake --cores 2 --configfile config/quick.yaml   tiny profile
# No science here: rules live in workflow/rules/, science in src/opnav/.
# `snakemake --lint` reports one item, on purpose: "Specify a conda environment
# or container for each rule". There is no conda here (`--sdm conda` does not
# work on the target machines); every rule runs in the one Python environment
# pinned by requirements.lock, whose versions rule `provenance` records.
from snakemake.utils import min_version

min_version("9.0")


# Every config file (this default and each --configfile, which Snakemake has read
# already, with YAML 1.1) through opnav's strict reader too (opnav.core.yamlfile, the
# one `opnav --config` uses): a key given twice, a non-string key, a YAML 1.1 form that
# YAML 1.2 reads otherwise (010, 1:30, yes/no/on/off, 1e-6), anchors, aliases and merge
# keys, __use_yte__, an unexpanded $VAR or a control character is refused in one line
# naming the file, the line and the key. (A file Snakemake cannot parse at all it refuses
# itself, before this file is read; a YTE template it has evaluated by then.)
# config_exit is the one way every config problem leaves the workflow.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(workflow.basedir) / "src"))
from opnav.core.errors import ConfigError  # noqa: E402
from opnav.core.yamlfile import read_config_file  # noqa: E402
from opnav.core.snakeio import config_exit  # noqa: E402
from opnav.core.console import quiet_job_headers  # noqa: E402

# Job headers on the console list no source files (a count instead) and cut a reason's
# file lists to three names (opnav.core.console): what reruns a job is unchanged.
quiet_job_headers([Path(workflow.basedir, d) for d in ("src", "workflow", "paper", "config")])

# A second --configfile replaces the first instead of adding to it (Snakemake's own
# parser): refused in one line, as every config problem.
from opnav.core.checks import configfile_flag_problem  # noqa: E402

if (_flags := configfile_flag_problem(sys.argv[1:])) is not None:
    config_exit(_flags)

_config_files = [Path(workflow.basedir, "config", "config.yaml")]
_config_files += list(getattr(getattr(workflow, "config_settings", None), "configfiles", None) or [])
try:
    for _f in _config_files:
        read_config_file(_f)
except ConfigError as exc:
    config_exit(exc)


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/kernels.smk"
include: "workflow/rules/approach.smk"
include: "workflow/rules/approach_extra.smk"
include: "workflow/rules/approach_peers.smk"
include: "workflow/rules/approach_custom.smk"
include: "workflow/rules/landing.smk"
include: "workflow/rules/landing_extra.smk"
include: "workflow/rules/landing_timing.smk"
include: "workflow/rules/studies.smk"
include: "workflow/rules/replication.smk"
include: "workflow/rules/paper.smk"


onstart:
    # A SLURM run without its status command is refused before any submission, and a
    # signal stops the build within seconds, saying so (opnav.core.runguard).
    from opnav.core.runguard import guard

    guard(workflow)
    # results_dir is this checkout's (and this profile's): its marker names them, and a
    # later parse from another checkout is refused (opnav.core.checks.owner_problems).
    # Written here, when jobs are about to run, so a dry run writes nothing.
    from opnav.core.checks import claim_results_dir

    claim_results_dir(config["results_dir"], workflow.basedir, config)
    # Every job is a fresh interpreter that imports the package. Where bytecode
    # caching is off (PYTHONDONTWRITEBYTECODE, set on some CI images) each job would
    # compile it again (~0.1-0.2 CPU-s a job): compile it once per run instead.
    import compileall
    import opnav

    compileall.compile_dir(str(Path(opnav.__file__).parent), quiet=1)
    # The jobs' libraries (numpy, scipy, pandas, matplotlib, numba) imported once for the build,
    # not once per job: a local build's jobs run in forks of one server (opnav.core.jobserver).
    from opnav.core import jobserver

    jobserver.start(workflow)


# Snakemake's scheduler re-checks its job-rate limit with a timer per scheduling round
# (a pending timer, restarted at every round, for each finished job: thousands of rounds
# in a quick run; snakemake/snakemake#3744). profiles/default checks it every 10 s,
# and these handlers cancel the timers still pending, which would hold the exit.
onsuccess:
    stop_rate_limit_timers()
    from opnav.core import jobserver

    jobserver.stop()


onerror:
    stop_rate_limit_timers()
    from opnav.core import jobserver

    jobserver.stop()
    from opnav.core.runguard import interrupted_exit

    interrupted_exit()  # after a signal: "interrupted", not "a job did not complete"


rule all:
    default_target: True
    input:
        final_outputs(),
