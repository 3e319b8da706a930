"""A repeated --configfile is refused: Snakemake keeps only the last flag's files.

Snakemake's parser takes every file after one ``--configfile`` (argparse ``nargs="+"``)
and a second flag replaces the first list, so ``--configfile config/quick.yaml
--configfile mine.yaml`` would build the full profile: the Snakefile refuses it in one
line (:func:`opnav.core.checks.configfile_flag_problem`)."""

import pytest

from opnav.core.checks import configfile_flag_problem


def test_snakemake_keeps_only_the_last_flag():
    """The premise: Snakemake's own parser drops the first --configfile's files."""
    from snakemake.cli import get_argument_parser

    args = get_argument_parser().parse_args(["--configfile", "a.yaml", "--configfile", "b.yaml"])
    assert [str(p) for p in args.configfile] == ["b.yaml"]
    args = get_argument_parser().parse_args(["--configfile", "a.yaml", "b.yaml"])
    assert [str(p) for p in args.configfile] == ["a.yaml", "b.yaml"]


@pytest.mark.parametrize("argv", [
    ["--cores", "2", "--configfile", "config/quick.yaml", "--configfile", "mine.yaml"],
    ["--configfile=config/quick.yaml", "--configfiles", "mine.yaml", "-n"],
    ["--configfile", "a.yaml", "b.yaml", "--cores", "2", "--configfile", "c.yaml"],
])
def test_repeated_flag_refused_naming_every_file(argv):
    msg = configfile_flag_problem(argv)
    assert msg is not None and "\n" not in msg
    assert "--configfile is given 2 times" in msg
    files = [a.partition("=")[2] or a for a in argv if a.endswith(".yaml")]
    assert msg.endswith("--configfile " + " ".join(files))


@pytest.mark.parametrize("argv", [
    [], ["--cores", "2"], ["--configfile", "config/quick.yaml", "mine.yaml", "--cores", "2"],
    ["--configfile=config/quick.yaml", "-n"],
])
def test_one_flag_accepted(argv):
    assert configfile_flag_problem(argv) is None


@pytest.mark.slow
def test_dry_run_refuses_a_repeated_flag(tmp_path):
    from conftest import copy_workflow, run_snakemake

    wf = copy_workflow(tmp_path)
    (wf / "mine.yaml").write_text("results_dir: results/mine\n")
    p = run_snakemake(wf, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "--configfile", "mine.yaml")
    assert p.returncode != 0
    assert "--configfile is given 2 times" in p.stderr + p.stdout
