# Compiled kernels (opnav.core.compiled): numba's on-disk cache is filled by one job per
# paper (KERNEL_PAPERS: the kernel modules its package registers and the core's; the two run
# side by side, each printing its progress to the console: a first build is not silent)
# before any job that calls them, so the other jobs only load it (none compiles).
# Its inputs are the kernel modules' sources (opnav.core.compiled.kernel_sources, read at
# parse time without importing numba): editing one reruns the job, which recompiles
# (a package's cache entries are keyed by its kernel set and the core's). The jobs that call kernels take its
# output as `kernels=kernels(paper)`: it orders them after this job; their own src()
# inputs hold the same kernel modules, so a recompile reruns no job an edit would not.


rule compile_kernels:
    """Compiles a paper's registered kernels once (opnav.core.compiled.warm) into numba's
    on-disk cache; the console and the log give each module's compile (or, cache filled,
    load) seconds as it goes; the output (no timings) names the kernel set."""
    input:
        lambda wc: kernel_src(wc.kpaper),
    output:
        res("kernels", "{kpaper}.json"),
    params:
        modules=lambda wc: kernel_modules(wc.kpaper),
    log:
        res("kernels", "logs", "compile_{kpaper}.log"),
    wildcard_constraints:
        kpaper="|".join(KERNEL_PAPERS),
    message:
        "rule compile_kernels (kpaper={wildcards.kpaper}): compiling this paper's numba kernels into the "
        "on-disk cache, first build only: 15-40 CPU-s per paper (src/opnav/data/compile_cpu_s.json); a line per module "
        "as it starts and ends, with its CPU, below and in its log (measured: docs/dev/performance-log.md)"
    script:
        "../scripts/compile_kernels.py"
