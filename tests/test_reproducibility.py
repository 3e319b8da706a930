"""Byte-identical rebuilds and reruns that follow changes (dry-run job lists)."""

import hashlib
import os

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml

from conftest import REPO, dry_run_jobs, dry_run_jobs_many, run_snakemake
from opnav.core import figures
from opnav.core.config import load_config

QUICK = ("--configfile", "config/quick.yaml")
QUICK_TARGET = "results/quick/landing/B-T1_initial_state.csv"


def _digest(paths):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


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


def test_a_layout_solved_once_for_both_formats_is_the_one_each_format_gets_alone(tmp_path):
    """figures.save solves a constrained layout once for the PDF and the PNG (then saves
    without the engine): the PNG is the one saved alone with the engine, and the layout
    did move the axes (a long label needs room)."""
    def make(layout=True):
        with figures.style():
            fig, axs = plt.subplots(1, 2, constrained_layout=layout)
            for ax in axs:
                ax.plot(np.arange(10), np.arange(10) ** 2)
                ax.set_ylabel("a long label\nover two lines [m/s]")
            return fig

    both = figures.save(make(), tmp_path / "both")
    alone = figures.save(make(), [tmp_path / "alone.png"])
    assert both[1].read_bytes() == alone[0].read_bytes()
    fig, plain = make(), make(layout=False)
    figures.save(fig, tmp_path / "moved")
    moved = np.abs(fig.axes[0].get_position().extents - plain.axes[0].get_position().extents).max()
    assert fig.get_layout_engine() is None and moved > 0.02


@pytest.mark.slow
def test_tables_rebuild_byte_identical(quick_results):
    """B-T1/B-T2 deleted from the shared quick build and rebuilt: the same bytes.
    (Their mtimes are put back, so the later tests on that build see it as it was.)"""
    out = quick_results / "results" / "quick" / "landing"
    files = sorted(f for t in ("B-T1_*", "B-T2_*") for f in out.glob(t))
    first, mtimes = _digest(files), {f: f.stat().st_mtime_ns for f in files}
    assert len(first) == 8, first                  # two tables, three formats each, the CSVs' checksums
    for f in files:
        f.unlink()
    proc = run_snakemake(quick_results, "--cores", "1", QUICK_TARGET, *QUICK)
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    assert _digest(files) == first
    for f, ns in mtimes.items():
        os.utime(f, ns=(ns, ns))


@pytest.mark.slow
def test_reruns_follow_params_and_modules(quick_results):
    """On the shared quick build, B-T1's dry-run job list after an edit: a parameter
    landing_tables uses reruns it, one it does not use reruns nothing, and so does an
    edit of a module it depends on (restored afterwards, mtime included)."""
    base_seed = load_config(overlays=[REPO / "config" / "quick.yaml"])["approach"]["base_seed"]
    overlays = {"nothing": {}, "used": {"landing": {"mc": {"bounds": {"r_m": 500.0}}}},
                "unused": {"approach": {"base_seed": base_seed + 1}}}
    args = []
    for name, overlay in overlays.items():
        path = quick_results / f"rerun-{name}.yaml"
        path.write_text(yaml.safe_dump(overlay))
        args.append((QUICK_TARGET, *QUICK, str(path)))
    planned = {name: {r for r, _ in jobs} for name, jobs in
               zip(overlays, dry_run_jobs_many(quick_results, args))}
    assert planned == {"nothing": set(), "used": {"landing_tables"}, "unused": set()}

    # a module the rule uses -> it reruns
    mod = quick_results / "src" / "opnav" / "landing" / "scenario.py"
    text, st = mod.read_text(), mod.stat()
    try:
        mod.write_text(text + "\n# edited\n")
        assert {r for r, _ in dry_run_jobs(quick_results, QUICK_TARGET, *QUICK)} == {"landing_tables"}
    finally:
        mod.write_text(text)
        os.utime(mod, ns=(st.st_atime_ns, st.st_mtime_ns))
