"""benchmarks/slurm_resources.py: measured benchmark rows -> the SLURM profile's block."""

import importlib.util
import math

import pandas as pd

from conftest import REPO

_spec = importlib.util.spec_from_file_location("slurm_resources", REPO / "benchmarks" / "slurm_resources.py")
sr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(sr)


def _rows(*rows):
    return pd.DataFrame(rows, columns=["rule", "files", "max_s", "max_rss_mb", "max_cpu_ratio"])


def test_margins_threads_and_unmeasured_rules():
    nan = float("nan")
    m = _rows(("long", 3, 600.0, 1000.0, 0.97),      # 10 min, 1 GB, one core
              ("blas", 2, 30.0, 400.0, 1.9),         # two cores busy
              ("short", 1, 1.0, nan, nan),           # too short to read a ratio from
              ("none", 0, nan, nan, nan))
    res = sr.resources(m)
    assert res["long"] == {"runtime": 2 * 10 + 5, "mem_mb": math.ceil((1.5 * 1000 + 500) / 100) * 100}
    assert res["blas"]["threads"] == 2 and res["blas"]["runtime"] == 10      # floor of 10 min
    assert "threads" not in res["long"] and "threads" not in res["short"]
    assert res["short"]["mem_mb"] == 2000                                    # RSS unknown: 1 GB assumed
    assert res["none"]["measured"] is False
    block = sr.render(res, "4 files")
    assert block.startswith(sr.BEGIN) and block.endswith(sr.END)
    assert "  none: {runtime: 30, mem_mb: 2000}  # not measured" in block
    assert "set-threads:\n  blas: 2\n" in block


def test_update_profile_replaces_only_the_measured_block(tmp_path):
    prof = tmp_path / "config.yaml"
    prof.write_text(f"executor: slurm\n{sr.BEGIN} old\nset-resources: {{}}\n{sr.END}\nretries: 1\n")
    sr.update_profile(prof, sr.render({"r": {"runtime": 12, "mem_mb": 900}}, "1 file"))
    text = prof.read_text()
    assert text.startswith("executor: slurm\n") and text.endswith("retries: 1\n")
    assert "  r: {runtime: 12, mem_mb: 900}" in text and "old" not in text
