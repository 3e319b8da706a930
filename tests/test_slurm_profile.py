"""The SLURM profile never lets a job go out without a runtime and a memory, and never
waits silently on a cluster without accounting (issue 46 item 7)."""

import re

import yaml

from conftest import REPO


def _rule_blocks():
    """(file, name or None, text) of every rule of workflow/rules/*.smk: a `rule NAME:` (or a
    `rule:` named in its `name:`, made in a loop) block up to the next rule."""
    for f in (REPO / "workflow" / "rules").glob("*.smk"):
        for block in filter(str.strip, re.split(r"(?m)^\s*(?=rule\b)", f.read_text())[1:]):
            m = re.match(r"rule\s+(\w+)\s*:", block)
            yield f.name, m.group(1) if m else None, block


def _cluster_rules() -> set[str]:
    """The named rules that are not `localrule: True` (those go to SLURM)."""
    return {name for _, name, block in _rule_blocks()
            if name and not re.search(r"localrule:\s*True", block)}


def test_a_rule_made_in_a_loop_carries_its_own_resources():
    """A rule named in `name:` (one per study, per method pack) cannot have a profile entry:
    if it goes to SLURM, it declares runtime and mem_mb itself."""
    bad = [f"{f}: {block.splitlines()[0:4]}" for f, name, block in _rule_blocks()
           if name is None and not re.search(r"localrule:\s*True", block)
           and not re.search(r"resources:.*?runtime=.*?mem_mb=", block, re.S)]
    assert not bad, bad


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
