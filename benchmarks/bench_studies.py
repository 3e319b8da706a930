"""Parameter studies (opnav.studies): wall time, jobs run, and what an edit re-queues.

Description
-----------
In a scratch copy of the workflow (``opnav.core.snakeio.copy_workflow``), with the
config of ``--config`` (default: the quick profile, whose other studies are small):

1. runs a 3-value landing study (``landing.imu.sigma_a_mps2``; methods depth and
   svd; ``--runs`` paired runs per value and method, 25 per job) with one command,
   ``snakemake --cores 2 study_bench --configfile <config> bench.yaml``, and prints
   the wall time and the jobs run (by rule);
2. edits one of its three values and prints the jobs the dry run lists;
3. raises its runs by half and prints the jobs the dry run lists (only new runs);
4. with a second study declared beside it, edits that one's values and prints
   the jobs the dry run lists (the target: only that study's).

Use::

    python benchmarks/bench_studies.py                 # 3 values x 2 methods x 100 runs
    python benchmarks/bench_studies.py --runs 20       # smaller
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
from opnav.core.snakeio import copy_workflow  # noqa: E402

VALUES = [2.5e-4, 5.0e-4, 1.0e-3]


def _study(values, runs, name="bench", key="landing.imu.sigma_a_mps2"):
    return {name: {"paper": "landing", "vary": {key: values}, "methods": ["depth", "svd"],
                   "runs": runs, "runs_per_job": 25,
                   "metrics": ["final_pos_err_m", "rms_pos_err_m", "mean_nees_pos"]}}


def _snakemake(wd: Path, *args: str) -> tuple[float, str]:
    env = dict(os.environ, PYTHONPATH=str(wd / "src"))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "snakemake", *args], cwd=wd, env=env,
                          capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit(proc.stdout[-3000:] + proc.stderr[-3000:])
    return dt, proc.stdout + proc.stderr


def _jobs(log: str) -> collections.Counter:
    return collections.Counter(re.findall(r"^(?:local)?rule (\w+):", log, flags=re.M))


def _show(title: str, jobs: collections.Counter) -> None:
    print(f"{title}: {sum(jobs.values())} jobs  " + ", ".join(f"{r} x{n}" for r, n in sorted(jobs.items())))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="config/quick.yaml", help="config overlay (default: quick profile)")
    ap.add_argument("--runs", type=int, default=100, help="paired runs per value and method")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench_studies_") as tmp:
        wd = copy_workflow(REPO, Path(tmp))
        bench = wd / "bench.yaml"
        bench.write_text(yaml.safe_dump({"studies": _study(VALUES, args.runs)}))
        cfg = ["--configfile", args.config, str(bench)]
        wall, log = _snakemake(wd, "--cores", "2", "study_bench", *cfg)
        print(f"study 'bench': 3 values x 2 methods x {args.runs} runs (landing.imu.sigma_a_mps2), "
              f"--cores 2, one command: {wall:.1f} s wall")
        _show("  jobs run", _jobs(log))

        edited = wd / "edit.yaml"
        edited.write_text(yaml.safe_dump({"studies": {"bench": {"vary": {
            "landing.imu.sigma_a_mps2": [VALUES[0], VALUES[1], 2.0e-3]}}}}))
        _, log = _snakemake(wd, "-n", "--cores", "1", "study_bench", *cfg, str(edited))
        _show("edit one value (1.0e-3 -> 2.0e-3), dry run lists", _jobs(log))

        more = wd / "more.yaml"
        more.write_text(yaml.safe_dump({"studies": {"bench": {"runs": args.runs + args.runs // 2}}}))
        _, log = _snakemake(wd, "-n", "--cores", "1", "study_bench", *cfg, str(more))
        _show(f"raise runs {args.runs} -> {args.runs + args.runs // 2}, dry run lists", _jobs(log))

        # a second study beside it: editing it lists only its jobs (whole pipeline as target)
        two = wd / "two.yaml"
        other = _study([1.0e-5, 2.78e-5], 4, name="gyro", key="landing.imu.sigma_w_degps")
        other["gyro"]["runs_per_job"] = 2
        two.write_text(yaml.safe_dump({"studies": {**_study(VALUES, args.runs), **other}}))
        _snakemake(wd, "--cores", "2", "studies", "--configfile", args.config, str(two))
        two_edit = wd / "two_edit.yaml"
        two_edit.write_text(yaml.safe_dump({"studies": {"gyro": {"vary": {
            "landing.imu.sigma_w_degps": [1.0e-5, 5.0e-5]}}}}))
        _, log = _snakemake(wd, "-n", "--cores", "1", "studies", "--configfile", args.config,
                            str(two), str(two_edit))
        _show("two studies, edit one value of 'gyro', dry run of every study lists", _jobs(log))
    return 0


if __name__ == "__main__":
    sys.exit(main())
