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
# already) through opnav's own loader too: a key given twice or an alias bomb (which
# Snakemake's loader accepts) is refused naming the file and line. (A file Snakemake
# cannot parse at all it refuses itself, before this file is read.) config_exit is the
# one way every config problem leaves the workflow.
import sys
from pathlib import Path

sys.path.insert(0, str(Path(workflow.basedir) / "src"))
from opnav.core.config import ConfigError, read_config_file  # noqa: E402
from opnav.core.snakeio import config_exit  # noqa: E402

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
include: "workflow/rules/landing.smk"
include: "workflow/rules/landing_extra.smk"
include: "workflow/rules/landing_timing.smk"
include: "workflow/rules/studies.smk"
include: "workflow/rules/replication.smk"
include: "workflow/rules/paper.smk"


onstart:
    # Every job is a fresh interpreter that imports the package. Where bytecode
    # caching is off (PYTHONDONTWRITEBYTECODE, set on some CI images) each job would
    # compile it again (~0.1-0.2 CPU-s a job): compile it once per run instead.
    import compileall
    import opnav

    compileall.compile_dir(str(Path(opnav.__file__).parent), quiet=1)


# Snakemake's scheduler re-checks its job-rate limit with a timer per scheduling round
# (a pending timer, restarted at every round, for each finished job: thousands of rounds
# in a quick run; snakemake/snakemake#3744). profiles/default checks it every 10 s,
# and these handlers cancel the timers still pending, which would hold the exit.
onsuccess:
    stop_rate_limit_timers()


onerror:
    stop_rate_limit_timers()


rule all:
    default_target: True
    input:
        final_outputs(),
