import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def copy_workflow(dst: Path) -> Path:
    """Copy what the workflow needs (not results/ or .snakemake/) into ``dst``."""
    for name in ("Snakefile", "config", "workflow", "src", "paper", "profiles"):
        p = REPO / name
        if p.is_dir():
            shutil.copytree(p, dst / name, ignore=shutil.ignore_patterns("__pycache__", "*.pdf"))
        elif p.exists():
            shutil.copy2(p, dst / name)
    return dst


def run_snakemake(cwd: Path, *args: str, check: bool = False) -> subprocess.CompletedProcess:
    """Run snakemake in ``cwd``; its scripts import the ``opnav`` copy under ``cwd/src``."""
    cmd = [sys.executable, "-m", "snakemake", *args]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (str(Path(cwd) / "src"), os.environ.get("PYTHONPATH", "")) if p))
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=check, env=env)


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    return copy_workflow(tmp_path)
