"""Paper A's Monte-Carlo units (scenario variant, case group) may share one job
(``jobs.approach_mc_per_job``, rules ``approach_mc_pack*``, issue 47 item 2): speed only.
A unit flown after another in the same job writes what a job of its own writes, bit for
bit, each file holding its own unit; the quick profile flies its units in one job, the
full profile keeps one job per unit."""

import dataclasses
import pickle
import runpy

import numpy as np
import pytest
from conftest import REPO, copy_workflow, dry_run_jobs

from opnav.core.snakeio import mock_snakemake, stand_in

SCRIPT = REPO / "workflow" / "scripts" / "approach_mc.py"


def _same(a, b, path="") -> list[str]:
    """The paths at which two pickled Monte-Carlo results differ (arrays bit for bit; typed
    records field by field)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return [path]
        return [d for f in dataclasses.fields(a) for d in _same(getattr(a, f.name), getattr(b, f.name),
                                                                 f"{path}.{f.name}")]
    if isinstance(a, dict):
        if set(a) != set(b):
            return [path]
        return [d for k in a for d in _same(a[k], b[k], f"{path}.{k}")]
    if isinstance(a, (list, tuple)):
        if len(a) != len(b):
            return [path]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _same(x, y, f"{path}[{i}]")]
    x, y = np.asarray(a), np.asarray(b)
    if x.dtype.kind in "fc":
        return [] if x.shape == y.shape and np.array_equal(x, y, equal_nan=True) else [path]
    return [] if x.shape == y.shape and np.array_equal(x, y) else [path]


@pytest.mark.slow
def test_a_unit_in_a_pack_writes_what_its_own_job_writes(tmp_path):
    """The quick profile's pack (params from the workflow): its last unit flown alone and
    after the one before it, every scheme's pickle equal (swapping the pack's outputs, or a
    scheme's, fails this: the two units' results differ)."""
    pack = mock_snakemake("approach_mc_pack1", configfiles=[REPO / "config" / "quick.yaml"])
    p = pack.params
    units = [tuple(u) for u in p.units]
    assert len(units) >= 2 and len(pack.output) == len(units) * len(p.schemes)

    def job(idx, tag):
        outs = [str(tmp_path / tag / f"{units[i][0]}__{units[i][1]}__{s}.pkl") for i in idx for s in p.schemes]
        smk = stand_in(output=outs, log=[str(tmp_path / tag / "job.log")],
                       params={"approach": p.approach, "schemes": list(p.schemes),
                               "units": [list(units[i]) for i in idx]})
        runpy.run_path(str(SCRIPT), init_globals={"snakemake": smk})
        res = []
        for o in outs:
            with open(o, "rb") as fh:
                res.append(pickle.load(fh))
        return res

    n = len(p.schemes)
    alone = job([len(units) - 1], "alone")
    both = job([len(units) - 2, len(units) - 1], "pack")
    for a, b in zip(alone, both[n:]):
        assert not _same(a, b)
    assert _same(both[0], both[n]), "the two units flew the same results: a swap would go unseen"


@pytest.mark.slow
def test_quick_profile_packs_approach_units_full_profile_does_not(tmp_path):
    """Dry runs: quick has one approach_mc_pack job and no approach_mc job; the full profile
    has no pack and one approach_mc job per variant and group."""
    wd = tmp_path / "wf"
    wd.mkdir()
    copy_workflow(wd)
    quick = dry_run_jobs(wd, "--configfile", "config/quick.yaml")
    assert [r for r, _ in quick if r.startswith("approach_mc_pack")] == ["approach_mc_pack1"]
    assert not [r for r, _ in quick if r == "approach_mc"]
    full = dry_run_jobs(wd)
    assert not [r for r, _ in full if r.startswith("approach_mc_pack")]
    units = [(w["variant"], w["group"]) for r, w in full if r == "approach_mc"]
    assert len(units) == len(set(units)) >= 5
