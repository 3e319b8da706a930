"""``opnav check CONFIG...`` (issue 57 item 3): config files read as the workflow will read
them, one line per problem naming the file and the key, exit 2; never a hang."""

import json
import os
import time

import pytest

from conftest import REPO
from opnav.cli import EXIT_USER, main


def _check(capsys, *argv):
    rc = main(["check", *map(str, argv)])
    cap = capsys.readouterr()
    return rc, cap.out, [ln for ln in cap.err.splitlines() if ln.strip()]


def test_good_files_pass_with_a_summary(capsys):
    rc, out, err = _check(capsys, REPO / "config" / "quick.yaml")
    assert rc == 0 and not err, err
    summary = json.loads(out)
    assert summary["ok"] and summary["files"] == [str(REPO / "config" / "quick.yaml")]


@pytest.mark.parametrize("kind", ["fifo", "device", "utf16", "latin1", "deep", "huge", "yte", "empty", "list",
                                  "multi", "nul", "tab"])
def test_what_snakemakes_reader_would_hang_or_trace_on_is_one_line(kind, tmp_path, capsys):
    """Each case Snakemake's own reader meets first (a hang, memory, a traceback or a message
    without the file's name): one line naming the file, exit 2, within seconds."""
    f = tmp_path / f"{kind}.yaml"
    contents = {"utf16": "landing: {mc: {n_runs: 8}}\n".encode("utf-16"),
                "latin1": "landing: {site: {name: 'J\u00e9zero'}}\n".encode("latin-1"),
                "deep": b"a: " + b"[" * 5000 + b"]" * 5000 + b"\n", "huge": b"- x\n" * 3_000_000,
                "yte": b"__use_yte__: true\nx:\n  ?for i in range(10**12):\n    ?i: 1\n", "empty": b"",
                "list": b"- a\n", "multi": b"a: 1\n---\nb: 2\n", "nul": b"a: 1\x00\n", "tab": b"a:\n\tb: 1\n"}
    if kind == "fifo":
        os.mkfifo(f)
    elif kind == "device":
        f = "/dev/zero"
    else:
        f.write_bytes(contents[kind])
    t0 = time.monotonic()
    rc, out, err = _check(capsys, f)
    assert time.monotonic() - t0 < 20
    assert rc == EXIT_USER and len(err) == 1 and f"config file {f}" in err[0] and out == "", err


def test_a_problem_names_the_file_that_sets_the_key(tmp_path, capsys):
    """Several files merge in order (as --configfile merges them): a line names the last file
    setting the key (or a parent of it); a cross-key problem no file sets names them all."""
    a = tmp_path / "a.yaml"
    b = tmp_path / "b.yaml"
    a.write_text("landing: {mc: {n_runs: 3.0}}\nresults_dir: 'my out'\n")
    b.write_text("approach: {dt_s: .nan}\n")
    rc, out, err = _check(capsys, REPO / "config" / "quick.yaml", a, b)
    assert rc == EXIT_USER, err
    by_key = {ln.split("config key '")[1].split("'")[0]: ln for ln in err}
    assert f"config file {a}: invalid config key 'landing.mc.n_runs'" in by_key["landing.mc.n_runs"]
    assert f"config file {a}: invalid config key 'results_dir'" in by_key["results_dir"]
    assert f"config file {b}: invalid config key 'approach.dt_s'" in by_key["approach.dt_s"]
    c = tmp_path / "c.yaml"
    c.write_text("landing: {filter: {min_update_altitude_m: 100000}}\n")
    rc, out, err = _check(capsys, c)
    assert rc == EXIT_USER and len(err) == 1, err
    assert f"config files {c} (merged on config/config.yaml): invalid config key 'landing.filter.update_altitude_margin_m'" in err[0]


def test_a_check_that_takes_too_long_is_stopped(monkeypatch, tmp_path, capsys):
    """The hard limits: a check that never ends is stopped at --timeout, one that grows past
    the memory limit is stopped; each one line. Mutation: running check_files unforked
    hangs the first."""
    import opnav.cli as cli
    import opnav.preflight as preflight

    f = tmp_path / "ok.yaml"
    f.write_text("landing: {mc: {n_runs: 8}}\n")
    monkeypatch.setattr(preflight, "check_files", lambda files: time.sleep(60))
    t0 = time.monotonic()
    rc, out, err = _check(capsys, f, "--timeout", "1")
    assert time.monotonic() - t0 < 10
    assert rc == EXIT_USER and len(err) == 1 and "did not finish in 1 s" in err[0], err

    def grow(files):
        block = []
        while True:
            block.append(bytearray(16 << 20))

    monkeypatch.setattr(preflight, "check_files", grow)
    monkeypatch.setattr(cli, "CHECK_MEMORY_MB", 128)         # the same limit, reached sooner
    rc, out, err = _check(capsys, f)
    assert rc == EXIT_USER and len(err) == 1 and "ran out of memory" in err[0], err


def test_one_flag_setting_a_list_is_one_line(capsys):
    """--pixel-sigma 0 sets three 3-sigma values: one line, not one per item."""
    rc = main(["approach", "--pixel-sigma", "0"])
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert rc == EXIT_USER and len(err) == 1 and err[0].startswith("opnav: error: --pixel-sigma 0"), err
