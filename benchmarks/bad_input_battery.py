"""Rerun the bad-input battery of tests/test_bad_input.py as a user meets it, and count
the outcomes by category (issue 33's first paragraph; issue 46's classes: NEW_CONFIGS,
YAML_TRAPS, NEW_CLI).

Every bad overlay goes through `snakemake -n --configfile config/quick.yaml FILE` (the
pipeline's own path: Snakefile, rule files, DAG), every bad config file through both
`opnav landing --config FILE` and `snakemake -n --configfile FILE`, every bad CLI call
through `python -m opnav ...`, each in a fresh process, timed. Categories:

  clean       refused (non-zero exit) in one line per problem naming the key/flag/file
  frames      refused naming it, but inside Snakemake stack frames
  no-file     a file's problem refused without naming the file
  unnamed     refused without naming the key (neither of the above)
  traceback   a Python traceback
  accepted    exit 0 (garbage accepted)
  slow        took more than 10 s (counted besides its category)

    PYTHONPATH=src python benchmarks/bad_input_battery.py [--only configs|files|cli] [-k TEXT]
"""

from __future__ import annotations

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))


def _run(cmd, cwd, timeout=120):
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    t = time.perf_counter()
    try:
        p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout,
                           errors="replace")
        rc, out = p.returncode, p.stdout + p.stderr
    except subprocess.TimeoutExpired:
        rc, out = -1, "timeout"
    return rc, out, time.perf_counter() - t


_FRAME = re.compile(r'File "[^"]+", line \d+|\.smk", line \d+')


def classify(rc: int, out: str, named: str, file_name: str | None = None) -> str:
    if rc == 0:
        return "accepted"
    if "Traceback (most recent call last)" in out:
        return "traceback"
    if file_name is not None and file_name not in out:
        return "no-file"
    if named not in out:
        return "unnamed"
    if _FRAME.search(out):
        return "frames"
    return "clean"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=["configs", "files", "cli"], default=None)
    ap.add_argument("-k", default="", help="only cases whose text contains this")
    args = ap.parse_args(argv)
    import test_bad_input as t

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        smk = [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "--configfile", "config/quick.yaml"]
        if args.only in (None, "configs"):
            for i, (overlay, key) in enumerate([*t.BAD_CONFIGS, *((o, k) for _, o, k in t.NEW_CONFIGS)]):
                if args.k not in overlay:
                    continue
                f = tmp / f"bad{i}.yaml"
                f.write_text(overlay + "\n")
                rc, out, dt = _run([*smk, str(f)], REPO)
                rows.append(("config", overlay[:70], classify(rc, out, key), dt, out))
        if args.only in (None, "files"):
            for i, (content, expected) in enumerate([*t.BAD_FILES, *t.YAML_TRAPS]):
                if args.k not in str(content):
                    continue
                f = tmp / f"file{i}.yaml"
                if isinstance(content, bytes):
                    f.write_bytes(content)
                elif content is not None:
                    f.write_text(content)
                rc, out, dt = _run([sys.executable, "-m", "opnav", "landing", "--config", str(f)], tmp)
                rows.append(("file/cli", str(content)[:70], classify(rc, out, expected.format(f=f), str(f)), dt, out))
                rc, out, dt = _run([*smk, str(f)], REPO)
                rows.append(("file/smk", str(content)[:70], classify(rc, out, str(f), str(f)), dt, out))
        if args.only in (None, "cli"):
            for name, text in (("broken.yaml", "approach: {dt_s: [1, 2\n"), ("nan.yaml", "approach: {dt_s: .nan}\n"),
                               ("tilt.yaml", "landing: {camera: {tilt_deg: 0}}\n"),
                               ("dup.yaml", "landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n"),
                               ("study.yaml", "studies: {s: {paper: landing, vary: "
                                              "{landing.camera.fov_deg: [45, 45.0]}}}\n"),
                               ("trap.yaml", "landing: {mc: {base_seed: 010}}\n"), ("yte.yaml", "__use_yte__: true\n")):
                (tmp / name).write_text(text)
            for argv_, named in [*t.BAD_CLI, *t.NEW_CLI]:
                if args.k not in " ".join(argv_):
                    continue
                argv_ = [a.replace("{tmp}", str(tmp)) for a in argv_]
                rc, out, dt = _run([sys.executable, "-m", "opnav", *argv_], REPO)
                cat = classify(rc, out, named)
                if cat == "clean" and rc != 2:
                    cat = f"exit {rc}"
                rows.append(("cli", " ".join(argv_)[:70], cat, dt, out))
    counts = collections.Counter(r[2] for r in rows)
    slow = [r for r in rows if r[3] > 10]
    for kind, case, cat, dt, out in rows:
        if cat != "clean" or dt > 10:
            print(f"{cat:10s} {dt:5.1f}s {kind:9s} {case}\n    " + "\n    ".join(out.strip().splitlines()[-4:]))
    print(f"\n{len(rows)} cases: " + ", ".join(f"{k} {v}" for k, v in counts.most_common())
          + f"; over 10 s: {len(slow)}; slowest {max(r[3] for r in rows):.1f} s")
    by_kind = collections.defaultdict(collections.Counter)
    for kind, _, cat, _, _ in rows:
        by_kind[kind][cat] += 1
    for kind, c in by_kind.items():
        print(f"  {kind:9s} " + ", ".join(f"{k} {v}" for k, v in c.most_common()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
