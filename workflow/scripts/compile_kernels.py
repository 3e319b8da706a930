"""Fills numba's on-disk cache with a paper's kernels (rule compile_kernels, opnav.core.compiled)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import importlib
import sys

import numba

from opnav.core import compiled
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import write_json

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("compile_kernels", argv=sys.argv[1:], kpaper="landing")

with script_context(snakemake, console=True) as log:  # progress on the console too (a first build)
    package = f"opnav.{snakemake.wildcards.kpaper}"
    modules = tuple(snakemake.params.modules)
    for name in modules:  # each registers its warm-up on import
        importlib.import_module(name)
    here = compiled.warm(modules, progress=log.info)  # a line as each module starts and ends
    stats = compiled.cache_stats()
    # load times from the filled cache: benchmarks/bench_pipeline.py (a fresh process each job pays)
    log.info("kernels: %d signatures compiled and %d loaded (%.2f s)", stats["compiled"], stats["loaded"],
             sum(here.values()))
    # no timings: the same kernel set gives the same file
    write_json(snakemake.output[0], {"kernel_modules": list(modules),
                                     "kernel_set_digest": compiled.kernel_set_digest(package),
                                     "numba": numba.__version__})
