"""Per-rule SLURM resources from measured benchmark TSVs.

Reads every ``benchmark:`` file of the workflow's cluster rules (non-local
rules) under a results folder, and writes their ``set-resources`` into
``profiles/slurm/config.yaml`` between the ``# BEGIN measured`` / ``# END
measured`` markers:

* ``runtime`` (min) = ceil(runtime_factor x the longest measured wall time) +
  runtime_pad_min, at least runtime_min_min;
* ``mem_mb`` = ceil(mem_factor x the largest measured max RSS) + mem_pad_mb,
  rounded up to 100 MB;
* ``threads`` (``set-threads``) only for a rule whose jobs used more than one
  core: ceil of the largest CPU time / wall time ratio measured, when that
  ratio exceeds ``multi_core_ratio`` (1.5; BLAS threads of a large matrix
  product, say). Every rule of this workflow is single-threaded by design.

Run after a full-profile run on the machine class of the cluster nodes::

    snakemake --cores 2                       # writes results/*/benchmarks/*.tsv
    python benchmarks/slurm_resources.py      # prints the table, updates the profile

Rules are matched to their files by the rule's own benchmark pattern (read
from the workflow via the Snakemake API), so renaming a benchmark file needs
no edit here. A rule with no benchmark file keeps ``default-resources``.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

import pandas as pd

REPO_SRC = Path(__file__).resolve().parents[1] / "src"
if str(REPO_SRC) not in sys.path:
    sys.path.insert(0, str(REPO_SRC))
from opnav.core.snakeio import benchmark_table  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
BEGIN, END = "# BEGIN measured", "# END measured"


def cluster_rules(repo: Path, configfiles: list[Path]) -> dict[str, str]:
    """{rule name: benchmark regex or None} for every rule that runs on the cluster."""
    from snakemake.api import SnakemakeApi
    from snakemake.settings.types import (ConfigSettings, OutputSettings, ResourceSettings,
                                          StorageSettings)

    with SnakemakeApi(OutputSettings()) as api:
        wf = api.workflow(resource_settings=ResourceSettings(),
                          config_settings=ConfigSettings(configfiles=configfiles),
                          storage_settings=StorageSettings(),
                          snakefile=repo / "Snakefile", workdir=repo)
        w = wf._workflow
        return {r.name: (r.benchmark.regex().pattern if r.benchmark is not None else None)
                for r in w.rules if r.name not in w._localrules and not r.norun}


def measure(rules: dict[str, str], workdir: Path) -> pd.DataFrame:
    """Per rule: number of benchmark files, longest wall time (s), largest max RSS (MB).

    Files are matched, relative to the run's working directory, against each
    rule's benchmark pattern (which carries the configured results folder)."""
    files = [p.relative_to(workdir).as_posix() for p in workdir.rglob("*.tsv")
             if "benchmarks" in p.parts and ".snakemake" not in p.parts]
    rows = []
    nan = float("nan")
    for name, pattern in sorted(rules.items()):
        tsvs = [f for f in files if re.fullmatch(pattern, f)] if pattern else []
        if not tsvs:
            rows.append({"rule": name, "files": 0, "max_s": nan, "max_rss_mb": nan, "max_cpu_ratio": nan})
            continue
        # a job the build's job server ran: its CPU and peak memory from its log (the benchmark
        # file measured its client process only; opnav.core.snakeio.benchmark_table)
        df = pd.concat([benchmark_table(workdir / f) for f in tsvs])
        rss = pd.to_numeric(df["max_rss"], errors="coerce")
        cpu = pd.to_numeric(df.get("cpu_time", pd.Series(dtype=float)), errors="coerce")
        # jobs under ~2 s are all start-up: their CPU/wall ratio says nothing of threads
        long = df["s"] >= 2.0
        ratio = (cpu[long] / df["s"][long]).max() if long.any() and cpu[long].notna().any() else nan
        rows.append({"rule": name, "files": len(tsvs), "max_s": float(df["s"].max()),
                     "max_rss_mb": float(rss.max()) if rss.notna().any() else nan,
                     "max_cpu_ratio": float(ratio)})
    return pd.DataFrame(rows, columns=["rule", "files", "max_s", "max_rss_mb", "max_cpu_ratio"])


#: For a cluster rule without a benchmark file (not measured).
UNMEASURED = {"runtime": 30, "mem_mb": 2000}


def resources(m: pd.DataFrame, runtime_factor=2.0, runtime_pad_min=5, runtime_min_min=10,
              mem_factor=1.5, mem_pad_mb=500, multi_core_ratio=1.5) -> dict[str, dict[str, int]]:
    """Runtime (min), memory (MB) and, for multi-core rules, threads per rule from its
    measurements, with margins."""
    out = {}
    for r in m.itertuples():
        if r.files == 0:
            out[r.rule] = dict(UNMEASURED, measured=False)
            continue
        runtime = max(runtime_min_min, math.ceil(runtime_factor * r.max_s / 60.0) + runtime_pad_min)
        rss = r.max_rss_mb if math.isfinite(r.max_rss_mb) else 1000.0
        mem = int(math.ceil((mem_factor * rss + mem_pad_mb) / 100.0) * 100)
        out[r.rule] = {"runtime": int(runtime), "mem_mb": mem}
        ratio = getattr(r, "max_cpu_ratio", float("nan"))
        if math.isfinite(ratio) and ratio > multi_core_ratio:
            out[r.rule]["threads"] = int(math.ceil(ratio))
    return out


def render(res: dict[str, dict[str, int]], source: str) -> str:
    lines = [BEGIN + f" by benchmarks/slurm_resources.py from {source}; do not edit by hand",
             "set-resources:"]
    for rule, kv in sorted(res.items()):
        note = "  # not measured (no benchmark file)" if kv.get("measured") is False else ""
        lines.append(f"  {rule}: {{runtime: {kv['runtime']}, mem_mb: {kv['mem_mb']}}}{note}")
    threads = {rule: kv["threads"] for rule, kv in sorted(res.items()) if "threads" in kv}
    if threads:
        lines.append("set-threads:")
        lines += [f"  {rule}: {n}" for rule, n in threads.items()]
    lines.append(END)
    return "\n".join(lines)


def update_profile(profile: Path, block: str) -> None:
    text = profile.read_text()
    pat = re.compile(re.escape(BEGIN) + r".*?" + re.escape(END), re.S)
    if not pat.search(text):
        raise SystemExit(f"{profile}: no '{BEGIN}' ... '{END}' block to replace")
    profile.write_text(pat.sub(lambda _: block, text))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workdir", default=str(REPO), help="folder the run was made in (holds its results/)")
    ap.add_argument("--configfile", nargs="*", default=[], help="config overlays the run used")
    ap.add_argument("--profile", default=str(REPO / "profiles" / "slurm" / "config.yaml"))
    ap.add_argument("--label", default="", help="what was measured, e.g. 'full profile, 2-core VM'")
    ap.add_argument("--dry", action="store_true", help="print only, do not update the profile")
    args = ap.parse_args(argv)
    workdir = Path(args.workdir).resolve()
    if not workdir.is_dir():
        print(f"slurm_resources: folder not found: {workdir}", file=sys.stderr)
        return 2
    rules = cluster_rules(REPO, [Path(c) for c in args.configfile])
    m = measure(rules, workdir)
    if not m["files"].any():
        print(f"slurm_resources: no benchmark files of {sorted(rules)} under {workdir}", file=sys.stderr)
        return 2
    res = resources(m)
    print(m.assign(runtime_min=[res[r]["runtime"] for r in m["rule"]],
                   mem_mb=[res[r]["mem_mb"] for r in m["rule"]],
                   threads=[res[r].get("threads", 1) for r in m["rule"]]).to_string(index=False))
    block = render(res, f"{m['files'].sum()} benchmark files" + (f" ({args.label})" if args.label else ""))
    if not args.dry:
        update_profile(Path(args.profile), block)
        print(f"updated {args.profile}")
    else:
        print(block)
    return 0


if __name__ == "__main__":
    sys.exit(main())
