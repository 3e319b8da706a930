"""Byte-identical rebuilds and reruns that follow changes (dry-run job lists)."""

import hashlib
import re
import shutil
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import yaml

from conftest import run_snakemake
from opnav import figures

TARGET = "results/landing/B-T1_initial_state.csv"


def _digest(paths):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def _planned_rules(workdir: Path, *args: str) -> set[str]:
    proc = run_snakemake(workdir, "-n", "--cores", "1", *args)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return set(re.findall(r"^rule (\w+):", proc.stdout, flags=re.M))


def test_figure_save_is_byte_identical(tmp_path):
    def make(stem):
        with figures.style():
            fig, ax = plt.subplots()
            ax.plot(np.arange(10), np.arange(10) ** 2)
            ax.set_xlabel("time [s]")
            return figures.save(fig, tmp_path / stem)

    a = make("a")
    b = make("b")
    for pa, pb in zip(a, b):
        assert pa.read_bytes() == pb.read_bytes(), pa.suffix
    assert b"CreationDate" not in a[0].read_bytes()


def test_tables_rebuild_byte_identical(workdir):
    out = workdir / "results" / "landing"
    assert run_snakemake(workdir, "--cores", "1", TARGET).returncode == 0
    first = _digest(sorted(out.glob("B-T*")))
    shutil.rmtree(workdir / "results")
    assert run_snakemake(workdir, "--cores", "1", TARGET).returncode == 0
    assert _digest(sorted(out.glob("B-T*"))) == first


def test_reruns_follow_params_and_modules(workdir):
    assert run_snakemake(workdir, "--cores", "1", TARGET).returncode == 0
    assert _planned_rules(workdir, TARGET) == set()

    # a parameter the rule uses -> it reruns
    cfg_path = workdir / "config" / "config.yaml"
    original = cfg_path.read_text()
    cfg = yaml.safe_load(original)
    cfg["landing"]["mc"]["bounds"]["r_m"] = 500.0
    cfg_path.write_text(yaml.safe_dump(cfg))
    assert _planned_rules(workdir, TARGET) == {"landing_tables"}

    # a parameter it does not use -> nothing reruns
    cfg = yaml.safe_load(original)
    cfg["approach"]["base_seed"] = cfg["approach"]["base_seed"] + 1
    cfg_path.write_text(yaml.safe_dump(cfg))
    assert _planned_rules(workdir, TARGET) == set()

    # a module the rule uses -> it reruns
    cfg_path.write_text(original)
    mod = workdir / "src" / "opnav" / "landing" / "scenario.py"
    mod.write_text(mod.read_text() + "\n# edited\n")
    assert _planned_rules(workdir, TARGET) == {"landing_tables"}
