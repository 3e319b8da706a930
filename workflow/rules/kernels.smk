# Compiled kernels (opnav.compiled): numba's on-disk cache is filled by this one job
# before any job that calls a kernel, so parallel jobs only load it (none compiles).
# Its inputs are the kernel modules' sources (opnav.compiled.kernel_sources, read at
# parse time without importing numba): editing one reruns this job, which recompiles
# every kernel (the cache is keyed by the whole kernel set). The jobs that call kernels
# take its output as `kernels=kernels()`, an ancient() input: it orders them after this
# job, and their own src() inputs decide whether they rerun.


rule compile_kernels:
    """Compiles every registered kernel once (opnav.compiled.warm) into numba's on-disk
    cache; the log gives each module's compile (or load) seconds and its load seconds
    from a fresh interpreter; the output (no timings) names the kernel set."""
    input:
        KERNEL_SRC,
    output:
        KERNELS_JSON,
    log:
        res("kernels", "logs", "compile_kernels.log"),
    script:
        "../scripts/compile_kernels.py"
