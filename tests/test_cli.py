import subprocess
import sys


def test_opnav_help_lists_purpose():
    proc = subprocess.run([sys.executable, "-m", "opnav.cli", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0
    assert "snakemake --cores 2" in proc.stdout


def test_the_paper_commands_never_import_the_top_level_cli():
    """Issue 56 item 3: the paper subcommands take their helpers from opnav.core.cliargs and
    their checks from the RunConfig opnav.cli hands them; opnav.cli imports them by name
    (no importlib, no module-name strings). Mutation: `from opnav.cli import integer` in
    landing/cli.py fails it."""
    import ast

    from conftest import REPO

    src = REPO / "src" / "opnav"
    for part in ("approach", "landing"):
        tree = ast.parse((src / part / "cli.py").read_text())
        names = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        names |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert "opnav.cli" not in names and "opnav" not in names, (part, names)
    top = (src / "cli.py").read_text()
    assert "importlib" not in top and "opnav.{" not in top
