"""One Monte-Carlo job may fly several methods (``landing.mc.methods_per_job``, rules
``landing_mc_pack*``, issue 47 item 2): speed only. A method flown after others in the
same job writes the chunk a job of its own writes, bit for bit; the pack's outputs follow
its methods; and the quick profile's dry run has one Monte-Carlo job per camera scenario
where the full profile keeps one per scenario and method."""

import copy
import runpy

import numpy as np
import pytest

from conftest import REPO, dry_run_jobs, copy_workflow
from opnav.core.config import load_config
from opnav.core.snakeio import stand_in
from opnav.landing.montecarlo import load
from opnav.landing.setup import scenario_sections

SCRIPT = REPO / "workflow" / "scripts" / "landing_mc_chunk.py"
#: the keys of the rule's params.landing (landing.smk's B_SIMS)
SIM_KEYS = ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu", "camera",
            "landmarks", "filter", "planner")


@pytest.fixture(scope="module")
def sim():
    c = scenario_sections(load_config(REPO / "config" / "config.yaml",
                                     overlays=[REPO / "config" / "quick.yaml"])["landing"])["interior"]
    out = {k: copy.deepcopy(c[k]) for k in SIM_KEYS}
    out["mc"] = {k: c["mc"][k] for k in ("base_seed", "bounds")}
    return out


def _job(tmp_path, sim, methods, tag):
    """The script as Snakemake runs a pack job of ``methods`` (one run, index 1)."""
    outs = [str(tmp_path / tag / m / "r0001-0001.npz") for m in methods]
    smk = stand_in(input=[str(SCRIPT)], output=outs, log=[str(tmp_path / tag / "job.log")],
                   params={"landing": sim, "runs": [1], "methods": list(methods),
                           "pick_ratio": [True] * len(methods), "batch_size": 0})
    runpy.run_path(str(SCRIPT), init_globals={"snakemake": smk})
    return {m: load(o).arrays() for m, o in zip(methods, outs)}


def _same(a: dict, b: dict) -> None:
    assert set(a) == set(b)
    for k in a:
        x, y = np.asarray(a[k]), np.asarray(b[k])
        assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), k


def test_a_method_in_a_pack_writes_what_its_own_job_writes(tmp_path, sim):
    """svd alone, then svd after depth in one job: the same arrays (and each file holds
    its own method: swapping the pack's outputs fails this)."""
    alone = _job(tmp_path, sim, ["svd"], "alone")["svd"]
    pack = _job(tmp_path, sim, ["depth", "svd"], "pack")
    assert str(pack["depth"]["method"]) == "depth" and str(pack["svd"]["method"]) == "svd"
    _same(alone, pack["svd"])
    differ = [k for k in pack["svd"] if k != "method" and not np.array_equal(
        np.asarray(pack["depth"][k]), np.asarray(pack["svd"][k]), equal_nan=np.asarray(pack["svd"][k]).dtype.kind == "f")]
    assert differ, "depth and svd flew the same descent: the comparison above would not see a swap"


@pytest.mark.slow
def test_quick_profile_packs_methods_full_profile_does_not(tmp_path):
    """Dry runs: quick has one pack job per camera scenario flying every Monte-Carlo method
    and no per-method job; the full profile has no pack and one job per scenario and method."""
    wd = tmp_path / "wf"
    wd.mkdir()
    copy_workflow(wd)
    quick = dry_run_jobs(wd, "--configfile", "config/quick.yaml")
    packs = [w for r, w in quick if r.startswith("landing_mc_pack")]
    assert {w["bscn"] for w in packs} == {"site-tilt", "interior"} and len(packs) == 2, packs
    assert not [r for r, _ in quick if r == "landing_mc_chunk"]
    full = dry_run_jobs(wd)
    assert not [r for r, _ in full if r.startswith("landing_mc_pack")]
    chunks = [w for r, w in full if r == "landing_mc_chunk"]
    assert len(chunks) == len({(w["bscn"], w["bmethod"]) for w in chunks}) >= 2 * 4


@pytest.mark.slow
def test_a_study_value_in_a_pack_writes_what_its_own_job_writes(tmp_path):
    """jobs.study_values_per_job: a landing study pack of the quick profile packed 8 a job (its params from
    the workflow), its second value flown alone and after the first: the same table (and
    each file holds its own value: swapping the pack's outputs fails this)."""
    import pandas as pd

    from opnav.core.snakeio import load_csv, mock_snakemake

    script = REPO / "workflow" / "scripts" / "study_runs.py"
    packed = tmp_path / "packed.yaml"   # the quick profile with study values packed 8 a job
    packed.write_text("jobs: {study_values_per_job: 8}\n")
    pack = next(sm for sm in (mock_snakemake(f"study_runs_pack{i}", configfiles=[REPO / "config" / "quick.yaml", packed])
                              for i in (1, 2)) if sm.params.paper == "landing")
    p = pack.params
    assert len(p.sims) >= 2 and p.sims[0] != p.sims[1]

    def job(idx, tag):
        outs = [str(tmp_path / tag / f"{i}.csv") for i in idx]
        smk = stand_in(output=outs, log=[str(tmp_path / tag / "job.log")],
                       params={"paper": "landing", "sims": [p.sims[i] for i in idx], "units": [p.units[i] for i in idx],
                               "runs": [p.runs[i] for i in idx], "labels": [p.labels[i] for i in idx]})
        runpy.run_path(str(script), init_globals={"snakemake": smk})
        return [load_csv(o) for o in outs]

    (alone,) = job([1], "alone")
    first, second = job([0, 1], "pack")
    timed = [c for c in alone if c.endswith("_us")]   # measured planning times (wall, CPU): never equal twice
    assert timed and len(timed) < len(alone.columns) // 4, timed
    pd.testing.assert_frame_equal(alone.drop(columns=timed), second.drop(columns=timed))
    assert not first.drop(columns=timed).equals(second.drop(columns=timed))
