"""The SLURM profile never lets a job go out without a runtime and a memory, and never
waits silently on a cluster without accounting (issue 46 item 7)."""

import re

import yaml

from conftest import REPO


def _cluster_rules() -> set[str]:
    """Every rule of workflow/rules/*.smk that is not `localrule: True` (those go to SLURM),
    read from the rule files' text: a `rule NAME:` block up to the next rule."""
    out = set()
    for f in (REPO / "workflow" / "rules").glob("*.smk"):
        for block in filter(str.strip, re.split(r"(?m)^\s*(?=rule\b)", f.read_text())[1:]):
            m = re.match(r"rule\s+(\w+)\s*:", block)
            if not re.search(r"localrule:\s*True", block):
                # a rule named in `name:` (studies.smk) is local, or this reading misses it
                assert m, f"{f.name}: a cluster rule named in `name:` (give it resources and a name here)"
                out.add(m.group(1))
    return out


def test_every_cluster_rule_has_runtime_and_memory():
    """Mutation: deleting compile_kernels' line from the profile fails it (it went out with
    no runtime or memory in the SLURM run of issue 46)."""
    profile = yaml.safe_load((REPO / "profiles" / "slurm" / "config.yaml").read_text())
    res = profile["set-resources"]
    rules = _cluster_rules()
    assert {"compile_kernels", "landing_tuning", "landing_mc_chunk", "study_runs"} <= rules
    missing = sorted(r for r in rules if not {"runtime", "mem_mb"} <= set(res.get(r, {})))
    assert not missing, missing
    assert all(res[r]["runtime"] >= 1 and res[r]["mem_mb"] >= 100 for r in rules)


def test_status_comes_from_squeue_by_default():
    """sacct answers nothing on a cluster without accounting, and Snakemake then waits for
    ever after the jobs end: the profile asks squeue."""
    profile = yaml.safe_load((REPO / "profiles" / "slurm" / "config.yaml").read_text())
    assert profile["slurm-status-command"] == "squeue"
