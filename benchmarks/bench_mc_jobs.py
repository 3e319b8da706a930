"""CPU seconds of paper B's Monte-Carlo jobs, one method at a time, as the pipeline flies them.

Description
-----------
For each (camera scenario, method) asked, the parameters of the real chunk job
(``opnav.core.snakeio.mock_snakemake("landing_mc_chunk", ...)``: the scenario's landing
config, whether the pick-ratio diagnostic runs), one untimed run (imports, kernel
loads, caches), then ``--runs`` runs timed by process CPU time
(``time.process_time``). Prints CPU seconds and planning calls per job. The per-job
view of ``benchmarks/job_costs.py`` without building the pipeline: to compare two
trees, run it with each tree's ``src`` on ``PYTHONPATH`` one after the other (a
git worktree of the old commit), on an idle machine. Use::

    python benchmarks/bench_mc_jobs.py --methods mineig,svd_w --scenarios interior,site-tilt
    PYTHONPATH=/tmp/old/src python benchmarks/bench_mc_jobs.py --methods mineig   # the old tree
"""

from __future__ import annotations

import argparse
import time


def job_cpu(scenario: str, method: str, runs: int, configfiles: list[str]) -> tuple[float, int]:
    """(CPU seconds, planning calls) of runs 1..runs of one chunk job, after an untimed run 0."""
    from opnav.landing.montecarlo import run_chunk
    from opnav.core.snakeio import mock_snakemake

    argv = ["--configfile", *configfiles] if configfiles else []
    sm = mock_snakemake("landing_mc_chunk", argv=argv, bscn=scenario, bmethod=method, bchunk="r0000-0000")
    from opnav.landing.setup import Setup

    setup = Setup.from_config(sm.params.landing)
    run_chunk(setup, method, [0], pick_ratio=False)
    t0 = time.process_time()
    d = run_chunk(setup, method, list(range(1, runs + 1)), pick_ratio=bool(sm.params.pick_ratio))
    return time.process_time() - t0, len(d.plan_index)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--methods", default="depth,svd,logdet,mineig,svd_w,gdop_w,cond_w")
    ap.add_argument("--scenarios", default="interior,site-tilt")
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--configfile", nargs="*", default=[], help="config overlays (as snakemake's)")
    a = ap.parse_args(argv)
    if a.runs < 1:
        ap.error("--runs must be at least 1")
    print(f"{'scenario':10s} {'method':8s} {'CPU s':>8s} {'calls':>6s}  ({a.runs} runs, warm)")
    for scn in a.scenarios.split(","):
        for m in a.methods.split(","):
            cpu, calls = job_cpu(scn, m, a.runs, a.configfile)
            print(f"{scn:10s} {m:8s} {cpu:8.2f} {calls:6d}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
