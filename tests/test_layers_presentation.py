"""Presentation lives in the report layer (issue 56 item 2): a paper package holds models,
estimators and experiments and imports nothing of ``opnav.report``; paper A's package draws
nothing (no matplotlib) and words nothing of its own (no module of text or plots).

Read from the sources with ``ast`` (0.1 CPU-s): every ``import`` and ``from ... import``,
function-level ones included, and relative imports resolved against the module's package.
(:mod:`tests.test_import_layers` ranks the layers; this test names the presentation rule.)
"""

import ast
from pathlib import Path

from conftest import REPO

SRC = REPO / "src"
#: the paper packages
PAPERS = ("approach", "landing", "studies")
#: paper packages that draw nothing (issue 56 item 2): no matplotlib, no plots or text modules
#: (paper A's figures and words are in opnav.report.approach, paper B's figures in
#: opnav.report.landing)
NO_PRESENTATION = ("approach", "landing")
#: the edge inside a paper package (as tests/test_import_layers.py's EDGE): a paper's CLI prints
#: its run in words and may import the report layer
EDGE = {"opnav/approach/cli.py", "opnav/landing/cli.py"}


def _imports(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import of a module."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append((node.lineno, mod))
            out += [(node.lineno, f"{mod}.{a.name}") for a in node.names]
    return out


def _modules(paper: str):
    root = SRC / "opnav" / paper
    for f in sorted(root.rglob("*.py")):
        rel = f.relative_to(SRC).with_suffix("")
        package = ".".join(rel.parts[:-1])
        yield f, package


def test_no_paper_package_imports_the_report_layer():
    """Mutation: ``from opnav.report import approach_text`` in approach/summaries.py, or a
    relative ``from ..report.approach import plots``, fails it."""
    bad = [f"{f.relative_to(SRC)}:{line} imports {mod}" for paper in PAPERS for f, pkg in _modules(paper)
           if str(f.relative_to(SRC)) not in EDGE
           for line, mod in _imports(f, pkg) if mod == "opnav.report" or mod.startswith("opnav.report.")]
    assert not bad, "\n".join(bad)


def test_the_papers_draw_and_word_nothing():
    """Neither paper's package imports matplotlib or holds a plots or text module: their figures
    and words are in opnav.report.approach and opnav.report.landing (mutation: moving
    approach/plots.py or landing/plots.py back fails it)."""
    bad = []
    for paper in NO_PRESENTATION:
        for f, pkg in _modules(paper):
            if f.stem.endswith(("plots", "_text")) or f.stem in ("text", "labels_text", "prose", "report"):
                bad.append(f"{f.relative_to(SRC)}: a presentation module")
            bad += [f"{f.relative_to(SRC)}:{line} imports {mod}" for line, mod in _imports(f, pkg)
                    if mod.split(".")[0] == "matplotlib"]
    assert not bad, "\n".join(bad)


def test_the_checker_sees_a_relative_import_of_the_report():
    """The reader resolves relative imports (a control: the rule could not fail otherwise)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "m.py"
        p.write_text("from ..report.approach import plots\n")
        assert (1, "opnav.report.approach.plots") in _imports(p, "opnav.approach")
