"""The bad-input battery, in process, counted by class (issue 57 item 6).

Every case is tried as a new user would meet it, but in this one process (no Snakemake
start-up per case): config overlays through the workflow's own pre-flight
(:func:`opnav.preflight.problems` on config/config.yaml + config/quick.yaml + the overlay,
what the Snakefile runs before it builds the DAG); config files through ``opnav check FILE``
(:func:`opnav.cli.main`: the reader the Snakefile also uses, under its time and memory
limit) and ``opnav landing --config FILE``; command lines through ``opnav ...``
(:func:`opnav.cli.main`, any simulation replaced by a trap so an accepted bad case shows
as accepted, not as minutes of work). The cases are tests/test_bad_input.py's lists (every
round's) and this issue's Snakemake-reader cases (FIFO, /dev/zero, huge and deep files,
encodings, YTE).

Classes:

  clean                refused in one line per problem naming the key, flag or file
  noisy                refused naming it, but one problem said on several lines (a key twice, a
                       study blamed for a key outside the studies, more than 5 lines)
  framed               refused without naming it, or with a traceback / an exception not the user's
  hang                 did not end in HANG_S seconds
  garbage accepted     a bad input accepted
  accepted-unchecked   accepted, and docs/usage.md says why (ACCEPTED_ON_PURPOSE)
  legitimate           a good input near the traps, accepted with the right value

The script ends by listing the cases only Snakemake's own reader sees (a ``--configfile``
it reads before any project code runs) with what the user sees there, measured on
Snakemake 9.27 (SNAKEMAKE_READER).

    PYTHONPATH=src python benchmarks/bad_input_battery.py [-v] [-k TEXT]
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

#: Seconds a case may take before it counts as a hang.
HANG_S = 20.0

#: Accepted on purpose, each with its reason in docs/usage.md: (overlay, reason)
ACCEPTED_ON_PURPOSE = [
    ("profile: quick\napproach: {n_seeds: 20}\nlanding: {mc: {n_runs: 300}}",
     "quick label on full-size samples: it only under-claims"),
    ("studies: {a: {paper: approach, id: A-X9, vary: {approach.camera.ifov_arcsec: [10.0]}}, "
     "b: {paper: approach, id: A-X9, vary: {approach.camera.ifov_arcsec: [20.0]}}}",
     "two studies of one paper sharing an id: an id names an experiment (pixel and segment are both A-X3)"),
    ("studies: {solo_outputs: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "a name ending in _outputs where no study makes that rule"),
    ("results_dir: results/quick", "a profile's own folder inside another's (the project's layout)"),
]

#: What Snakemake's own reader does with a --configfile, before any project code (measured
#: on Snakemake 9.27 in issue 57's battery); `opnav check` refuses each in one line.
SNAKEMAKE_READER = [
    ("a FIFO", "hangs (Snakemake opens and reads it, waiting for a writer)"),
    ("/dev/zero", "grows until memory runs out"),
    ("a 10 MB YAML list", "hangs for minutes"),
    ("10 MB of comments", "refused only after ~36 s"),
    ("a YTE template with a huge loop", "hangs (Snakemake evaluates it)"),
    ("UTF-16 or latin-1 text", "a Python traceback (UnicodeDecodeError)"),
    ("5,000-deep nesting", "a Python traceback (RecursionError)"),
    ("an empty, list, scalar, multi-document, NUL or tab file",
     "\"Config file is not valid JSON or YAML\" without the file's name"),
]


def _cases(tmp: Path):
    """(section, kind, label, run, expect) for every case: ``run()`` returns (accepted,
    output text); ``expect`` is the text a clean refusal names, or ("ok", value check)."""
    import test_bad_input as t

    from opnav.preflight import problems

    def config_case(overlay):
        def run():
            cfg = t._overlaid(overlay)
            lines = problems(cfg, root=REPO, workdir=REPO, workflow=True)
            return not lines, "\n".join(lines)
        return run

    def section(overlay):
        head = overlay.lstrip("{ ").split(":")[0].strip()
        return head if head else "top"

    for overlay, key in t.BAD_CONFIGS:
        yield section(overlay), "config", overlay, config_case(overlay), key
    for cls, overlay, key in t.NEW_CONFIGS + t.ROUND_FOUR_CONFIGS:
        yield section(overlay), "config", overlay, config_case(overlay), key
    for overlay, key in t.ONCE:
        yield section(overlay), "config", overlay, config_case(overlay), key
    for overlay, why in ACCEPTED_ON_PURPOSE:
        yield section(overlay), "config", overlay, config_case(overlay), ("unchecked", why)
    yield "top", "config", "{} (the quick profile)", config_case("{}"), ("ok", None)

    # config files: opnav check and opnav landing --config, in process
    files = [*t.BAD_FILES, *t.YAML_TRAPS, *_reader_cases(tmp)]
    for i, (content, expected) in enumerate(files):
        f = _write(tmp / f"file{i}.yaml", content)
        label = (str(content)[:60] if not isinstance(content, Path) else str(content))
        shown = str(f if not isinstance(content, Path) else content)
        expected = expected.format(f=shown)
        yield "file", "check", label, _cli(["check", shown]), expected
        if not isinstance(content, Path):
            yield "file", "--config", label, _cli(["landing", "--config", shown]), expected
    for i, (content, key, value) in enumerate(t.ACCEPTED_FILES):     # the reader: right value
        f = _write(tmp / f"ok{i}.yaml", content)
        yield "file", "reader", str(content)[:60], _reads(f, key, value), ("ok", None)

    # command lines
    for name, text in (("broken.yaml", "approach: {dt_s: [1, 2\n"), ("nan.yaml", "approach: {dt_s: .nan}\n"),
                       ("tilt.yaml", "landing: {camera: {tilt_deg: 0}}\n"),
                       ("dup.yaml", "landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n"),
                       ("study.yaml", "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n"),
                       ("trap.yaml", "landing: {mc: {base_seed: 010}}\n"), ("yte.yaml", "__use_yte__: true\n")):
        (tmp / name).write_text(text)
    for argv, named in [*t.BAD_CLI, *t.NEW_CLI, *t.ROUND_FOUR_CLI]:
        argv = [a.replace("{tmp}", str(tmp)) for a in argv]
        yield "cli", argv[0] if not argv[0].startswith("-") else argv[2], " ".join(argv)[:70], _cli(argv), named


def _reader_cases(tmp: Path):
    """Issue 57's files that only Snakemake's reader met before: (content or Path, expected)."""
    fifo = tmp / "fifo.yaml"
    os.mkfifo(fifo)
    out = [(fifo, "{f}: a FIFO (named pipe), not a regular file"),
           (Path("/dev/zero"), "{f}: a device, not a regular file"),
           ("- " + "x\n- " * 2_000_000, "bytes, over the 1000000"),
           ("#" * 100 + "\n" * 10 + "# c\n" * 2_600_000, "bytes, over the 1000000"),
           ("__use_yte__: true\nx:\n  ?for i in range(10**12):\n    ?i: 1\n", "key '__use_yte__': YTE templates"),
           ("landing: {mc: {n_runs: 8}}\n".encode("utf-16"), "UTF-16 text (byte-order mark)"),
           ("landing: {site: {name: 'Jezero-\u00e9'}}\n".encode("latin-1"), "not UTF-8 text"),
           ("a: " + "[" * 5000 + "]" * 5000 + "\n", "nested more than 32 levels deep"),
           ("a:\n" + "".join(" " * (2 * i) + f"k{i}:\n" for i in range(1, 200)), "nested more than 32"),
           ("", "{f}: empty"), ("- a\n- b\n", "the top level must be a mapping"), ("3\n", "must be a mapping"),
           ("a: 1\n---\nb: 2\n", "more than one YAML document"), (b"a: 1\x00\n", "a NUL byte"),
           ("a:\n\tb: 1\n", "not valid YAML"), ("'just a string'\n", "must be a mapping"),
           ("null\n", "{f}: empty"), ("---\n...\n", "{f}: empty"),
           ("{\"a\": 1, \"a\": 2}", "given twice"), ("[1, 2]", "must be a mapping")]
    return out


def _write(f: Path, content) -> Path:
    if isinstance(content, Path):
        return content
    if content is None:
        return f
    if isinstance(content, bytes):
        f.write_bytes(content)
    else:
        f.write_text(content)
    return f


def _reads(f: Path, key: str, value):
    def run():
        from opnav.core.yamlfile import read_config_file

        node = read_config_file(f)
        for part in key.split("."):
            node = node[part]
        ok = node == value and type(node) is type(value)
        return ok, "" if ok else f"read {node!r}, expected {value!r}"
    return run


def _cli(argv):
    def run():
        from opnav.cli import main

        err, out = io.StringIO(), io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            try:
                rc = main(list(argv))
            except SystemExit as exc:
                rc = exc.code if isinstance(exc.code, int) else 2
        text = err.getvalue()
        if rc == 0 and "WORK STARTED" in text:
            return True, text
        return rc == 0, text + out.getvalue() + (f"\n(exit {rc})" if rc not in (0, 2) else "")
    return run


@contextlib.contextmanager
def _no_work():
    """Any simulation a case starts raises: an accepted bad command line shows as accepted."""
    import opnav.approach.cases as cases
    import opnav.approach.scenario as scenario
    import opnav.landing.descent as descent

    class Work(Exception):
        pass

    def forbidden(*a, **k):
        print("WORK STARTED", file=sys.stderr)
        raise SystemExit(0)

    saved = [(m, n, getattr(m, n)) for m, n in ((cases, "run_case"), (scenario, "build_geometry"),
                                                (descent, "build_scenario"), (descent, "run_descent"))]
    for m, n, _ in saved:
        setattr(m, n, forbidden)
    try:
        yield
    finally:
        for m, n, f in saved:
            setattr(m, n, f)


def classify(accepted: bool, text: str, expect, seconds: float, label: str = "") -> str:
    if seconds > HANG_S:
        return "hang"
    if isinstance(expect, tuple):
        kind = expect[0]
        if not accepted:
            return "framed"                       # a good input refused
        return "legitimate" if kind == "ok" else "accepted-unchecked"
    if accepted:
        return "garbage accepted"
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    if "Traceback" in text or "(exit 3)" in text or "check failed" in text or expect not in text:
        return "framed"
    keys = [ln.split("config key '")[1].split("'")[0] for ln in lines if "config key '" in ln]
    blamed = any(k.startswith("studies") for k in keys) and "stud" not in label
    if len(lines) > 5 or len(keys) != len(set(keys)) or blamed:
        return "noisy"
    return "clean"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-k", default="", help="only cases whose text contains this")
    ap.add_argument("-v", action="store_true", help="print every case that is not clean")
    args = ap.parse_args(argv)
    os.chdir(REPO)
    rows = []
    t_all = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, _no_work():
        for sec, kind, label, run, expect in _cases(Path(tmp)):
            if args.k not in label:
                continue
            t0 = time.perf_counter()
            try:
                accepted, text = run()
            except Exception as exc:              # noqa: BLE001 - a traceback a user would see
                accepted, text = False, f"Traceback (most recent call last): {type(exc).__name__}: {exc}"
            dt = time.perf_counter() - t0
            rows.append((sec, kind, label, classify(accepted, text, expect, dt, label), dt, text, expect))
    slow = sorted(rows, key=lambda r: -r[4])[:3]
    print("slowest: " + "; ".join(f"{r[2][:40]!r} {r[4]:.1f} s" for r in slow))
    order = ["clean", "noisy", "framed", "hang", "garbage accepted", "accepted-unchecked", "legitimate"]
    counts = collections.Counter(r[3] for r in rows)
    for sec, kind, label, cls, dt, text, expect in rows:
        if cls not in ("clean", "legitimate") and (args.v or cls not in ("accepted-unchecked",)):
            print(f"{cls:18s} {dt:5.1f}s {kind:8s} {label!r}\n    expected: {expect}\n    "
                  + "\n    ".join(text.strip().splitlines()[:4]))
    print(f"\n{len(rows)} cases in {time.perf_counter() - t_all:.0f} s: "
          + ", ".join(f"{k} {counts.get(k, 0)}" for k in order))
    by_sec = collections.defaultdict(collections.Counter)
    for sec, kind, *_ in rows:
        by_sec[f"{sec} ({kind})"][_[1]] += 1
    for name, c in sorted(by_sec.items()):
        print(f"  {name:32s} " + ", ".join(f"{k} {c[k]}" for k in order if c[k]))
    print("\nOnly Snakemake's own reader sees a --configfile before the project's code; what a user sees "
          "there (Snakemake 9.27), each refused in one line by `opnav check FILE` first:")
    for what, seen in SNAKEMAKE_READER:
        print(f"  {what:55s} {seen}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
