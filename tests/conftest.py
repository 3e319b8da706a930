import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from opnav.snakeio import copy_workflow as _copy_workflow

REPO = Path(__file__).resolve().parents[1]


def copy_workflow(dst: Path) -> Path:
    """Copy what the workflow needs (not results/ or .snakemake/) into ``dst``."""
    return _copy_workflow(REPO, dst)


def run_snakemake(cwd: Path, *args: str, check: bool = False) -> subprocess.CompletedProcess:
    """Run snakemake in ``cwd``; its scripts import the ``opnav`` copy under ``cwd/src``."""
    cmd = [sys.executable, "-m", "snakemake", *args]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (str(Path(cwd) / "src"), os.environ.get("PYTHONPATH", "")) if p))
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=check, env=env)


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    return copy_workflow(tmp_path)


@pytest.fixture(scope="session")
def quick_results(tmp_path_factory) -> Path:
    """A scratch copy of the workflow after one complete quick-profile run (shared by
    the end-to-end test and the dry-run tests that need recorded provenance)."""
    wd = copy_workflow(tmp_path_factory.mktemp("quick"))
    proc = run_snakemake(wd, "--cores", "2", "--configfile", "config/quick.yaml")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    return wd


def dry_run_jobs(cwd: Path, *args: str) -> list[tuple[str, dict]]:
    """The jobs ``snakemake -n`` lists, as (rule, wildcards) pairs."""
    proc = run_snakemake(cwd, "-n", "--cores", "1", *args)
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    jobs = []
    for block in re.split(r"\n(?=(?:local)?rule \w+:\n)", proc.stdout):
        m = re.match(r"(?:local)?rule (\w+):\n", block.lstrip("\n"))
        if not m:
            continue
        wc = re.search(r"^    wildcards: (.*)$", block, re.M)
        pairs = dict(kv.split("=", 1) for kv in wc.group(1).split(", ")) if wc else {}
        jobs.append((m.group(1), pairs))
    return jobs
