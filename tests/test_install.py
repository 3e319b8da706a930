"""``pip install .`` (not editable) gives a working ``opnav`` without the checkout.

Builds a wheel from a copy of the sources, installs it into a temporary venv
that sees the already-installed dependencies of the running interpreter
(``--no-deps``, ``--no-build-isolation``: no network), and runs the installed
command from a folder outside any checkout, where only package data can supply
the schemas, defaults, published values and figure style.

The running interpreter may itself be a venv (how most users run README's test
command): ``--system-site-packages`` would then see the base interpreter's
packages, not the venv's, so the nested venv gets the running interpreter's
site-packages folders through a ``.pth`` file instead (plain paths: their own
``.pth`` files, e.g. an editable install of this checkout, are not run).
"""

import json
import os
import site
import shutil
import subprocess
import sys
import zipfile

import pytest

from pathlib import Path

from conftest import REPO

pytestmark = pytest.mark.slow


def _run(cmd, cwd, env):
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=300)


def _outer_site_dirs() -> list[str]:
    """The running interpreter's site-packages folders (a venv's, and its base's when the
    venv sees them), as on its ``sys.path``, without this checkout's ``src``."""
    dirs = [*site.getsitepackages(), site.getusersitepackages()]
    dirs += [p for p in sys.path if p.endswith(("site-packages", "dist-packages"))]
    src = str(REPO / "src")
    return [d for d in dict.fromkeys(dirs) if os.path.isdir(d) and d != src]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src-copy"
    src.mkdir()
    for name in ["pyproject.toml", "README.md", "LICENSE"]:
        if (REPO / name).exists():
            shutil.copy2(REPO / name, src / name)
    shutil.copytree(REPO / "src", src / "src",
                    ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    wheels = tmp / "dist"
    r = _run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "--no-build-isolation",
              "-w", str(wheels), "-q"], tmp, env)
    assert r.returncode == 0, r.stderr
    (wheel,) = wheels.glob("opnav_repro-*.whl")
    venv = tmp / "venv"
    # no pip inside the venv (ensurepip is most of a venv's cost): this pip installs into it
    r = _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], tmp, env)
    assert r.returncode == 0, r.stderr
    bindir = venv / ("Scripts" if os.name == "nt" else "bin")
    r = _run([str(bindir / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
             tmp, env)
    assert r.returncode == 0, r.stderr
    (Path(r.stdout.strip()) / "outer-env.pth").write_text("\n".join(_outer_site_dirs()) + "\n")
    r = _run([sys.executable, "-m", "pip", "--python", str(bindir / "python"), "install", "-q",
              "--no-deps", "--no-index", "--force-reinstall", str(wheel)], tmp, env)
    assert r.returncode == 0, r.stderr
    outside = tmp / "elsewhere"
    outside.mkdir()
    return dict(wheel=wheel, bin=bindir, cwd=outside, env=env)


def test_wheel_ships_its_package_data(installed):
    names = set(zipfile.ZipFile(installed["wheel"]).namelist())
    for f in ["opnav/schemas/config.schema.yaml", "opnav/schemas/approach.schema.yaml",
              "opnav/schemas/landing.schema.yaml", "opnav/data/published.yaml",
              "opnav/opnav.mplstyle"]:
        assert f in names


def test_installed_cli_runs_outside_a_checkout(installed):
    env, cwd, bindir = installed["env"], installed["cwd"], installed["bin"]
    r = _run([str(bindir / "python"), "-c", "import opnav; print(opnav.__file__)"], cwd, env)
    assert str(installed["bin"].parent) in r.stdout, r.stdout + r.stderr  # the venv's copy
    r = _run([str(bindir / "opnav"), "--help"], cwd, env)
    assert r.returncode == 0 and "approach" in r.stdout and "landing" in r.stdout, r.stderr
    r = _run([str(bindir / "opnav"), "landing", "--method", "depth", "--seed", "0"], cwd, env)
    assert r.returncode == 0, r.stderr
    installed_out = json.loads(r.stdout)
    # The installed command uses the schema defaults; the checkout's uses
    # config/config.yaml: the same descent, the same numbers.
    here = subprocess.run([sys.executable, "-m", "opnav.cli", "landing", "--method", "depth",
                           "--seed", "0"], cwd=REPO, capture_output=True, text=True,
                          env=dict(env, PYTHONPATH=str(REPO / "src")), timeout=300)
    assert here.returncode == 0, here.stderr
    checkout_out = json.loads(here.stdout)
    drop = {"median_plan_time_us"}  # a clock
    assert {k: v for k, v in installed_out.items() if k not in drop} == \
        {k: v for k, v in checkout_out.items() if k not in drop}
