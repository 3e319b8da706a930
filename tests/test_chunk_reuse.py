"""Raising the number of Monte-Carlo runs flies only the new runs, also when the last
chunk was partial (issue 30): a chunk job takes over the runs of an earlier, smaller
chunk beside it (``montecarlo.earlier_chunks``) when they were flown with the same
reuse key, and the chunk it writes is the one a fresh job would write."""


import numpy as np
import pytest

from conftest import REPO
from opnav.core.config import load_config
from opnav.landing.montecarlo import (chunk_label, chunks, earlier_chunks, load, run_chunk,
                                      run_chunk_reusing, save)
from landing_helpers import scenario_setups


@pytest.fixture(scope="module")
def landing():
    cfg = scenario_setups(load_config(REPO / "config" / "config.yaml",
                                      overlays=[REPO / "config" / "quick.yaml"])["landing"])["site-tilt"]
    # one batch per run: chunking changes no bit (test_landing_filter)
    return cfg.replace(mc=cfg.mc.replace(batch_size=1))


def _fly(folder, cfg, n_runs, runs_per_job, key="k1"):
    """The chunk jobs of ``n_runs`` (each as the workflow's job would run it): run indices flown."""
    flown = []
    for runs in chunks(n_runs, runs_per_job):
        path = folder / f"{chunk_label(runs)}.npz"
        if path.exists():            # Snakemake keeps an existing output: no job
            continue
        data, new = run_chunk_reusing(path, key, cfg, "depth", runs)
        save(path, data, "depth")
        flown += new
    return flown


def test_earlier_chunks_picks_disjoint_subsets(tmp_path):
    for label in ("r0000-0003", "r0000-0004", "r0004-0004", "r0006-0009", "r0000-0005", "notes"):
        (tmp_path / f"{label}.npz").write_bytes(b"")
    got = earlier_chunks(tmp_path / "r0000-0005.npz", range(6))
    assert [(p.name, r) for p, r in got] == [("r0000-0004.npz", [0, 1, 2, 3, 4])]
    got = earlier_chunks(tmp_path / "r0000-0007.npz", range(8))
    assert [p.name for p, _ in got] == ["r0000-0005.npz"]      # the largest; r0006-0009 is not inside
    assert earlier_chunks(tmp_path / "r0000-0002.npz", range(3)) == []


@pytest.mark.slow
def test_raising_n_runs_flies_only_the_new_runs(tmp_path, landing):
    """4 -> 6 -> 7 runs with 6 runs per job: the partial chunk r0000-0003 becomes
    r0000-0005 by flying runs 4 and 5 only, then r0006-0006 flies run 6; every chunk
    equals a fresh one bit for bit."""
    assert _fly(tmp_path, landing, 4, 6) == [0, 1, 2, 3]
    assert _fly(tmp_path, landing, 6, 6) == [4, 5]
    assert _fly(tmp_path, landing, 7, 6) == [6]
    fresh = run_chunk(landing, "depth", range(6)).arrays()
    got = load(tmp_path / "r0000-0005.npz").arrays()
    assert set(got) - {"method", "reuse_key"} == set(fresh)
    for k in fresh:
        x = np.asarray(fresh[k])
        assert np.array_equal(np.asarray(got[k]), x, equal_nan=x.dtype.kind == "f"), k


def test_runs_flown_with_another_config_are_flown_again(tmp_path, landing):
    """The negative control: an earlier chunk with another reuse key (another
    simulation config, method or diagnostics) is not taken over."""
    assert _fly(tmp_path, landing, 1, 6, key="old") == [0]
    assert _fly(tmp_path, landing, 2, 6, key="new") == [0, 1]  # run 0 flown again
