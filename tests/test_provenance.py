"""Provenance names the installed stack and the exact commit (or says it cannot)."""

import subprocess
from importlib import metadata

from opnav.core import provenance


def _git(cwd, *args):
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=cwd,
                   check=True, capture_output=True)


def test_versions_are_the_installed_ones(tmp_path):
    info = provenance.collect(tmp_path)
    for name in provenance.PACKAGES:
        assert info[name] == metadata.version(name)
    assert info["git_commit"] == "unknown" and info["git_dirty"] == "unknown"


def test_commit_and_dirty_flag(tmp_path):
    _git(tmp_path, "init", "-q")
    (tmp_path / "f.txt").write_text("a\n")
    _git(tmp_path, "add", "f.txt")
    _git(tmp_path, "commit", "-q", "-m", "x")
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=tmp_path, capture_output=True,
                          text=True, check=True).stdout.strip()
    info = provenance.collect(tmp_path)
    assert info["git_commit"] == head and info["git_dirty"] == "no"
    (tmp_path / "f.txt").write_text("b\n")
    assert provenance.collect(tmp_path)["git_dirty"] == "yes"
    # a folder inside someone else's checkout is not this project's commit
    (tmp_path / "sub").mkdir()
    assert provenance.collect(tmp_path / "sub")["git_commit"] == "unknown"


def test_latex_macros_carry_every_row():
    info = {"python": "3.11.7", "numpy": "2.4.6", "git_commit": "ab" * 20, "git_dirty": "no"}
    tex = provenance.latex_macros(info)
    assert r"\newcommand{\ProvNumpy}{\texttt{2.4.6}}" in tex
    assert r"\newcommand{\ProvGitCommitShort}{\texttt{" + "ab" * 6 + "}}" in tex
    assert r"git\_dirty & \texttt{no}" in tex
