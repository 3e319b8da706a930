import os
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
