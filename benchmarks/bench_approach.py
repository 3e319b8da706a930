"""Paper-A benchmark (printed figures, not a timed test).

    python benchmarks/bench_approach.py                       # EM iteration timings
    python benchmarks/bench_approach.py --before 870b400      # jobs: CPU-s before/after + equality
    python benchmarks/bench_approach.py --before 870b400 --quick --mc all --x2 roll literal
    python benchmarks/bench_approach.py --against /work/main/results --mc all --x2 literal roll
    python benchmarks/bench_approach.py --workflow            # also the whole part-A workflow

``--before REV``: every job named by ``--mc`` (``variant:group``: every EM scheme, one
job now and one per scheme before; ``variant:group:scheme``; or ``all`` for every
Monte-Carlo job of the profile) and ``--x2`` (variants) runs in its own process,
once with the package of git revision ``REV`` (``git archive``) and once with this
checkout's, one after the other, as the workflow's jobs would (one process each; an
A-X2 variant is one job now, its case groups were one job each before; likewise
the EM schemes of a Monte-Carlo job). It prints
the CPU seconds of each, of the job's work (after the imports; children included:
the JIT compiler) and of its whole process (start-up and imports included), their
ratios, and the largest relative difference between the two results (run-time
fields aside), which must be 0 or round-off.

``--against RESULTS``: the same jobs with this checkout only, against the work pickles
of a finished run of that profile; "before" is the ``cpu_time`` of its benchmark files.

``--kernels``: the CPU time of the compiled window passes of the EM-EKF (filter,
position smoother, E-step, one EM map) per window length and seed count; with
``--before REV`` beside REV's (numpy) versions and their ratios.

Without either: the CPU time of one EM iteration (EKF + smoother + E/M step)
on a 250-sample segment per seed count, and with ``--workflow`` the wall time of
``snakemake --cores 2`` for every part-A output from an empty results directory
(in a temporary copy of the workflow).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import resource
import subprocess
import sys
import tarfile
import tempfile
import time
from io import BytesIO
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

# one job, run in a fresh interpreter: argv = kind spec quick out.pkl; prints {"cpu_s": ...}
_JOB = r"""
import json, os, pickle, sys, time
kind, spec, quick, out = sys.argv[1:5]
from opnav.core.config import load_config
from opnav.approach.setup import Setup
cfg = load_config(overlays=["config/quick.yaml"] if quick == "1" else [])["approach"]
setup = Setup.from_config(cfg)
t0 = os.times()
if kind == "mc":  # variant:group:scheme, or variant:group = every scheme in one process (as the job now)
    from opnav.approach.pipeline import run_group
    v, g, *m = spec.split(":")
    schemes = m or list(cfg["methods"]) + [f"growing-{x}" for x in cfg["growing"]["methods"]]
    res, shared = [], {}
    for sch in schemes:
        mode, _, meth = sch.rpartition("-")
        try:  # the schemes of a job share the simulation (run_group's shared=, since this change)
            res.extend(run_group(setup, v, g, meth, mode or "sliding", shared=shared))
        except TypeError:
            res.extend(run_group(setup, v, g, meth, mode or "sliding"))
else:
    from opnav.approach import alternatives as alt, scenario as sc
    v, g = spec.split(":")
    res = alt.run_group_alternatives(setup, v, g, geo=sc.build_geometry(setup, v))
t1 = os.times()
cpu = (t1.user - t0.user) + (t1.system - t0.system) + (t1.children_user - t0.children_user) \
    + (t1.children_system - t0.children_system)
with open(out, "wb") as fh:
    pickle.dump(res, fh)
print(json.dumps({"cpu_s": cpu}))
"""


# the compiled window passes against the numpy they replaced: argv = samples seeds (comma lists)
_KERNELS = r"""
import json, sys, time
import numpy as np
from opnav.approach import em, ekf, smoother, scenario as sc
from opnav.approach.setup import Setup
from opnav.core.config import load_config
cfg = Setup.from_config(load_config()["approach"])
rows = []
for n in map(int, sys.argv[1].split(",")):
    geo = sc.build_geometry(cfg, "roll", n=n)
    Rvar = sc.measurement_variance(geo, cfg, cfg.camera.sigma3_px)
    win = geo.window(Rvar)
    for S in map(int, sys.argv[2].split(",")):
        z, _ = sc.simulate(geo, Rvar, sc.rad(cfg.truth_bias_arcsec), sc.seed_streams(1, 1, range(S)))
        theta, x0 = np.full((S, 3), 1e-5), np.zeros((S, 6))
        em.em_map(theta, z, x0, geo.P0, win, 1e-6)  # warm-up (loads the kernels)
        f = ekf.run_filter(z, theta, x0, geo.P0, win, predicted=False)
        s = smoother.bryson_frazier(f, win, ekf.POS)
        reps = max(3, int(4000 / (n * S)))
        def best(fn):
            t = []
            for _ in range(reps):
                t0 = time.process_time(); fn(); t.append(time.process_time() - t0)
            return min(t)
        rows.append({"samples": n, "seeds": S,
                     "filter": best(lambda: ekf.run_filter(z, theta, x0, geo.P0, win, predicted=False)),
                     "smoother": best(lambda: smoother.bryson_frazier(f, win, ekf.POS)),
                     "estep": best(lambda: em.estep(z, s, win)),
                     "em_map": best(lambda: em.em_map(theta, z, x0, geo.P0, win, 1e-6))})
print(json.dumps(rows))
"""


def kernel_timing(src: Path, samples: str, seeds: str) -> list[dict]:
    """Best-of CPU seconds of the EKF window pass, the position Bryson-Frazier smoother, the
    E-step and one whole EM map, per window length and seed count, with the package ``src``."""
    p = subprocess.run([sys.executable, "-c", _KERNELS, samples, seeds], cwd=REPO, check=True,
                       capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(src)))
    return json.loads(p.stdout.strip().splitlines()[-1])


def compare_kernels(rev: str | None, samples: str, seeds: str) -> None:
    """:func:`kernel_timing` of this checkout, and of ``rev`` beside it with the ratios."""
    parts = ("filter", "smoother", "estep", "em_map")
    with tempfile.TemporaryDirectory() as d:
        before = kernel_timing(_export_src(rev, Path(d)), samples, seeds) if rev else None
    after = kernel_timing(REPO / "src", samples, seeds)
    print("CPU ms (best of repeats), roll geometry" + (f"; before = {rev}, after = this checkout" if rev else ""))
    print(f"{'samples':>7s} {'seeds':>5s} " + " ".join(f"{p:>22s}" for p in parts))
    for i, a in enumerate(after):
        cells = []
        for p in parts:
            if before:
                b = before[i][p]
                cells.append(f"{b * 1e3:8.2f} ->{a[p] * 1e3:8.2f} {a[p] / b:4.2f}")
            else:
                cells.append(f"{a[p] * 1e3:22.2f}")
        print(f"{a['samples']:7d} {a['seeds']:5d} " + " ".join(cells), flush=True)


def em_iteration_timing(n_samples: int = 250, seeds=(1, 20, 100), repeats: int = 5) -> list[dict]:
    from opnav.approach import em, scenario as sc
    from opnav.core.config import load_config

    from opnav.approach.setup import Setup

    cfg = Setup.from_config(load_config(REPO / "config" / "config.yaml")["approach"])
    geo = sc.build_geometry(cfg, "roll", n=n_samples)
    Rvar = sc.measurement_variance(geo, cfg, cfg.camera.sigma3_px)
    win = geo.window(Rvar)
    rows = []
    for S in seeds:
        z, _ = sc.simulate(geo, Rvar, sc.rad(cfg.truth_bias_arcsec), sc.seed_streams(1, 1, range(S)))
        theta = np.zeros((S, 3))
        x0 = np.zeros((S, 6))
        em.em_map(theta, z, x0, geo.P0, win, 1e-6)  # warm-up
        t = []
        for _ in range(repeats):
            t0 = time.process_time()
            em.em_map(theta, z, x0, geo.P0, win, 1e-6)
            t.append(time.process_time() - t0)
        best = min(t)
        rows.append({"seeds": S, "samples": n_samples, "em_iteration_s": best,
                     "per_seed_ms": 1e3 * best / S})
    return rows


def workflow_timing(configfile: str | None = None) -> float:
    from opnav.core.snakeio import copy_workflow

    with tempfile.TemporaryDirectory() as d:
        dst = copy_workflow(REPO, Path(d))
        targets = ["results/approach/A-T1_table1.csv", "results/approach/A-X1_crlb.pdf"] + [
            f"results/approach/A-F4_bias_estimate_{v}.pdf" for v in ("literal", "prior", "roll", "reference-start")]
        cmd = [sys.executable, "-m", "snakemake", "--cores", "2", *targets]
        if configfile:
            cmd += ["--configfile", configfile]
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=dst, check=True, capture_output=True)
        return time.perf_counter() - t0


def _export_src(rev: str, dest: Path) -> Path:
    """The package (src/) of git revision ``rev`` under ``dest``."""
    blob = subprocess.run(["git", "-C", str(REPO), "archive", rev, "src"], check=True, capture_output=True).stdout
    with tarfile.open(fileobj=BytesIO(blob)) as tf:
        tf.extractall(dest, filter="data")
    return dest / "src"


def _run_job(src: Path, kind: str, spec: str, quick: bool, out: Path) -> tuple[float, float]:
    """CPU seconds of the job's work and of its whole process (start-up and imports included)."""
    env = dict(os.environ, PYTHONPATH=str(src))
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run([sys.executable, "-c", _JOB, kind, spec, "1" if quick else "0", str(out)],
                       cwd=REPO, env=env, check=True, capture_output=True, text=True)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    whole = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return json.loads(p.stdout.strip().splitlines()[-1])["cpu_s"], whole


def _strip(x):
    """Results without their wall-clock fields (run times differ from run to run)."""
    if isinstance(x, dict):
        return {k: _strip(v) for k, v in x.items() if not (k.startswith("runtime") or k == "em_times")}
    if isinstance(x, (list, tuple)):
        return [_strip(v) for v in x]
    return x


def max_rel_diff(a, b, path: str = "") -> tuple[float, str]:
    """Largest relative difference between two result structures (nested dicts/lists of arrays):
    ``|a - b| / max(|a|, |b|)`` per entry (0 where both are 0); booleans, integers, strings
    and NaN positions must match exactly (else ``inf``)."""
    import dataclasses

    if dataclasses.is_dataclass(a) and not isinstance(a, type):  # a typed record: field by field
        if type(a) is not type(b):
            return float("inf"), f"{path}: types differ"
        return max((max_rel_diff(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
                    for f in dataclasses.fields(a)), default=(0.0, path))
    if a is None or b is None:
        return (0.0, path) if a is b else (float("inf"), f"{path}: None")
    if isinstance(a, dict):
        if set(a) != set(b):
            return float("inf"), f"{path}: keys differ"
        return max((max_rel_diff(a[k], b[k], f"{path}.{k}") for k in a), default=(0.0, path))
    if isinstance(a, (list, tuple)) and not (a and np.isscalar(a[0])):
        if len(a) != len(b):
            return float("inf"), f"{path}: lengths differ"
        return max((max_rel_diff(x, y, f"{path}[{i}]") for i, (x, y) in enumerate(zip(a, b))), default=(0.0, path))
    x, y = np.asarray(a), np.asarray(b)
    if x.shape != y.shape:
        return float("inf"), f"{path}: shapes differ"
    if x.dtype.kind not in "fc":
        return (0.0, path) if np.array_equal(x, y) else (float("inf"), path)
    if not np.array_equal(np.isnan(x), np.isnan(y)):
        return float("inf"), f"{path}: NaN positions differ"
    ok = ~np.isnan(x)
    d = np.abs(x - y)[ok]
    s = np.maximum(np.abs(x), np.abs(y))[ok]
    r = np.where(s > 0, d / np.where(s > 0, s, 1.0), 0.0)
    return (float(r.max()) if r.size else 0.0), path


def schemes_of(quick: bool) -> list[str]:
    from opnav.core.config import load_config

    cfg = load_config(overlays=[REPO / "config" / "quick.yaml"] if quick else [])["approach"]
    return list(cfg["methods"]) + [f"growing-{m}" for m in cfg["growing"]["methods"]]


def mc_specs(quick: bool) -> list[str]:
    """Every Monte-Carlo job of the profile, ``variant:group`` (all EM schemes)."""
    from opnav.approach.pipeline import groups_for
    from opnav.approach.setup import Setup
    from opnav.core.config import load_config

    cfg = load_config(overlays=[REPO / "config" / "quick.yaml"] if quick else [])["approach"]
    setup = Setup.from_config(cfg)
    return [f"{v}:{g}" for v in cfg["variants"] for g in groups_for(setup, v)]


def compare_revisions(rev: str, mc: list[str], x2: list[str], quick: bool, x2_groups_before: list[str],
                      schemes: list[str]) -> None:
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        old_src, new_src = _export_src(rev, d / "before"), REPO / "src"
        print(f"CPU-s per job (process + children), before = {rev}, after = this checkout; "
              f"profile {'quick' if quick else 'full'}")
        print(f"{'job':42s} {'work before':>11s} {'after':>7s} {'ratio':>6s} {'process before':>14s} "
              f"{'after':>7s} {'ratio':>6s} {'max rel diff':>12s}")
        totals = {}
        jobs = [("mc", s, [s] if s.count(":") == 2 else [f"{s}:{m}" for m in schemes], s) for s in mc]
        jobs += [("x2", v, [f"{v}:{g}" for g in x2_groups_before], f"{v}:all") for v in x2]
        for kind, name, before_specs, after_spec in jobs:
            wb = pb = 0.0
            res_b = []
            for i, s in enumerate(before_specs):
                out = d / f"b_{kind}_{i}.pkl"
                w, p = _run_job(old_src, kind, s, quick, out)
                wb, pb = wb + w, pb + p
                with open(out, "rb") as fh:
                    res_b.extend(pickle.load(fh))
            out = d / f"a_{kind}.pkl"
            wa, pa = _run_job(new_src, kind, after_spec, quick, out)
            with open(out, "rb") as fh:
                res_a = pickle.load(fh)
            diff, where = max_rel_diff(_strip(res_b), _strip(res_a))
            t = totals.setdefault(kind, np.zeros(4))
            t += (wb, wa, pb, pa)
            label = f"{kind} {name}" + (f" ({len(before_specs)} jobs before)" if len(before_specs) > 1 else "")
            print(f"{label:42s} {wb:11.2f} {wa:7.2f} {wa / wb:6.3f} {pb:14.2f} {pa:7.2f} {pa / pb:6.3f} "
                  f"{diff:12.3g}" + (f"  at {where}" if diff > 0 else ""), flush=True)
        for kind, (wb, wa, pb, pa) in totals.items():
            print(f"{'total ' + kind:42s} {wb:11.2f} {wa:7.2f} {wa / wb:6.3f} {pb:14.2f} {pa:7.2f} {pa / pb:6.3f}")


def _log_cpu(log: Path) -> float:
    """The CPU seconds a job's log ends with (``job resources: cpu_s=...``: the job's whole process)."""
    last = [ln for ln in log.read_text().splitlines() if "job resources: cpu_s=" in ln][-1]
    return float(last.split("cpu_s=")[1].split()[0])


GROUP_ORDER = ["size", "polarity", "initial", "pixel", "install", "all", "headline"]


def compare_with_run(results: Path, mc: list[str], x2: list[str], quick: bool, schemes: list[str]) -> None:
    """This checkout's jobs against a finished run's work pickles (``results``/approach/work),
    "before" CPU-s from that run's benchmark files (its load may differ from now)."""
    a = results / "approach"
    print(f"CPU-s per job against the run in {results}: before = its jobs' logs (job resources: cpu_s), "
          f"after = this checkout, one process per job (whole process; the load may differ)")
    print(f"{'job':42s} {'before':>8s} {'after':>8s} {'ratio':>6s} {'max rel diff':>12s}")
    totals = {}
    with tempfile.TemporaryDirectory() as d:
        jobs = []
        for s in mc:
            v, g, *m = s.split(":")
            names = [f"{v}__{g}__{x}" for x in (m or schemes)]
            jobs.append(("mc", s, [a / "work" / "mc" / f"{x}.pkl" for x in names],
                         [a / "logs" / f"mc_{x}.log" for x in names]))
        for v in x2:
            pk = sorted((a / "work" / "x2").glob(f"{v}__*.pkl"), key=lambda p: GROUP_ORDER.index(p.stem.split("__")[1]))
            jobs.append(("x2", f"{v}:all", pk, [a / "logs" / f"x2_{p.stem}.log" for p in pk]))
        for kind, spec, pickles, logs in jobs:
            before = []
            for p in pickles:
                with open(p, "rb") as fh:
                    r = pickle.load(fh)
                before.extend(r["results"] if kind == "x2" else r)
            cpu_b = sum(_log_cpu(t) for t in logs)
            out = Path(d) / "a.pkl"
            _, cpu_a = _run_job(REPO / "src", kind, spec, quick, out)
            with open(out, "rb") as fh:
                after = pickle.load(fh)
            diff, where = max_rel_diff(_strip(before), _strip(after))
            t = totals.setdefault(kind, np.zeros(3))
            t += (cpu_b, cpu_a, len(logs))
            print(f"{kind + ' ' + spec + f' ({len(logs)} jobs before)':42s} {cpu_b:8.2f} {cpu_a:8.2f} "
                  f"{cpu_a / cpu_b:6.3f} {diff:12.3g}" + (f"  at {where}" if diff > 0 else ""), flush=True)
    for kind, (tb, ta, n) in totals.items():
        print(f"{'total ' + kind + f' ({int(n)} jobs before)':42s} {tb:8.2f} {ta:8.2f} {ta / tb:6.3f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workflow", action="store_true", help="also time the whole part-A workflow")
    ap.add_argument("--configfile", default=None, help="overlay config for the workflow run (e.g. config/quick.yaml)")
    ap.add_argument("--before", metavar="REV", help="compare jobs against the package of git revision REV")
    ap.add_argument("--against", metavar="RESULTS", type=Path,
                    help="compare jobs with a finished run's results folder (its pickles and benchmark files)")
    ap.add_argument("--quick", action="store_true", help="jobs of the quick profile (config/quick.yaml)")
    ap.add_argument("--mc", nargs="*", default=["roll:size", "prior:headline"],
                    help="Monte-Carlo jobs variant:group (every EM scheme: one job now, one per scheme "
                         "before) or variant:group:scheme, or 'all'")
    ap.add_argument("--x2", nargs="*", default=[], help="A-X2 variants (one job each)")
    ap.add_argument("--kernels", action="store_true",
                    help="time the compiled window passes (filter, smoother, E-step, EM map); with --before "
                         "REV beside REV's numpy versions")
    ap.add_argument("--samples", default="50,250,2000", help="--kernels: window lengths")
    ap.add_argument("--seeds", default="3,20,80", help="--kernels: seed counts")
    args = ap.parse_args()
    if args.kernels:
        compare_kernels(args.before, args.samples, args.seeds)
        return
    if args.against:
        compare_with_run(args.against, mc_specs(args.quick) if args.mc == ["all"] else args.mc, args.x2, args.quick,
                         schemes_of(args.quick))
        return
    if args.before:
        from opnav.approach import cases
        from opnav.approach.setup import Setup
        from opnav.core.config import load_config

        mc = mc_specs(args.quick) if args.mc == ["all"] else args.mc
        cfg = load_config(overlays=[REPO / "config" / "quick.yaml"] if args.quick else [])["approach"]
        groups = list(cases.GROUPS) if Setup.from_config(cfg).scatter == "group" else ["all"]
        compare_revisions(args.before, mc, args.x2, args.quick, groups, schemes_of(args.quick))
        return
    print("one EM iteration (EKF + Bryson-Frazier smoother + E-step + closed-form M-step), 250 samples, CPU:")
    for r in em_iteration_timing():
        print(f"  seeds={r['seeds']:4d}: {r['em_iteration_s'] * 1e3:8.1f} ms  ({r['per_seed_ms']:.2f} ms per seed)")
    if args.workflow:
        w = workflow_timing(args.configfile)
        print(f"part-A workflow, snakemake --cores 2 from empty results/: {w:.1f} s")


if __name__ == "__main__":
    main()
