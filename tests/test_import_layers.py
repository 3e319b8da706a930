"""The import picture of the package (issue 41 item 3): four layers and no cycles.

* core (``opnav.core.*``: errors, rotations, compiled kernels' loader, snakeio, published
  values, provenance, the table/figure writers and the number-verdict rule): imports only
  the core;
* the papers (``opnav.approach.*``, ``opnav.landing.*``, their ``cli`` modules aside):
  import the core and their own paper only, never the other paper;
* the report (``opnav.report.*``: claims, scorecard, manuscript, study plots, each
  paper's claims) and the study package (``opnav.studies.*``): import anything below them;
* the edge (the CLIs, ``__main__``, ``opnav.preflight``: the config checks that need the
  papers' physics and the study planner, which the Snakefile and the CLIs call): may
  import anything.

A module imports only its own layer or a lower one, with no exception: config loading
(``opnav.core.config``, ``opnav.core.checks``) imports nothing above the core, and
importing it loads no numba, scipy or pandas (a test runs ``python -X importtime``).

Every ``import`` counts, function-level (lazy) ones included: a lazy import that closes
a cycle is still a cycle in the design.
"""

import ast
from pathlib import Path

from conftest import REPO

SRC = REPO / "src"
PAPERS = ("opnav.approach", "opnav.landing")
EDGE = {"opnav.__main__", "opnav.cli", "opnav.approach.cli", "opnav.landing.cli", "opnav.preflight"}
#: core modules allowed to import upwards: none (issue 41 item 3 removed config and checks)
EDGE_EXCEPTIONS: set[str] = set()
RANK = {"core": 0, "approach": 1, "landing": 1, "report": 2, "edge": 3}
#: Cycles known and left to their owners (each a frozenset of module names). None
#: now: the landing Monte Carlo / ranking / replay / descent component was broken
#: up (B-T3's summary_table moved to landing.report, the planning-call records to
#: landing.records); a cycle that comes back fails the test.
KNOWN_CYCLES: set[frozenset[str]] = set()


def _modules() -> dict[str, Path]:
    out = {}
    for f in SRC.rglob("*.py"):
        parts = f.relative_to(SRC).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = f
    return out


def _graph() -> dict[str, set[str]]:
    mods = _modules()
    graph = {}
    for name, f in mods.items():
        pkg = name if f.name == "__init__.py" else name.rpartition(".")[0]
        deps = set()
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Import):
                deps |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                    base = ".".join(up + ([node.module] if node.module else []))
                deps |= {f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names}
        graph[name] = {d for d in deps if d in mods and d != name}
    return graph


def _layer(name: str) -> str:
    if name in EDGE:
        return "edge"
    if name.startswith(PAPERS):
        return name.split(".")[1]
    if name.startswith(("opnav.report", "opnav.studies")):
        return "report"
    return "core"


def test_no_module_imports_a_higher_layer_or_the_other_paper():
    bad = []
    for mod, deps in _graph().items():
        layer = _layer(mod)
        if mod in EDGE_EXCEPTIONS:
            continue
        for d in deps:
            dl = _layer(d)
            if dl == layer or RANK[dl] < RANK[layer]:
                continue
            bad.append(f"{mod} ({layer}) imports {d} ({dl})")
    assert not bad, "\n".join(sorted(bad))


def _cycles(graph):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(frozenset(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return set(out)


def test_no_import_cycles():
    cycles = _cycles(_graph())
    assert cycles == KNOWN_CYCLES, sorted(map(sorted, cycles ^ KNOWN_CYCLES))


def test_the_checker_sees_a_cycle_and_an_upward_import():
    g = {"opnav.a": {"opnav.b"}, "opnav.b": {"opnav.a"}, "opnav.c": set()}
    assert _cycles(g) == {frozenset({"opnav.a", "opnav.b"})}
    assert _layer("opnav.landing.descent") == "landing" and _layer("opnav.report.manuscript") == "report"
    assert _layer("opnav.core.tables") == "core" and _layer("opnav.approach.cli") == "edge"
    assert RANK[_layer("opnav.core.tables")] < RANK[_layer("opnav.approach.em")] < RANK[_layer("opnav.report.claims")]


def test_loading_a_config_imports_no_heavy_package():
    """`python -X importtime` of loading the checkout's config (core.config): no numba,
    scipy, pandas or paper package among the imports (issue 41 item 3). Mutation: a
    top-level `import numpy` or a physics check called from core.config fails it."""
    import os
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-X", "importtime", "-c",
                           "from opnav.core.config import load_config; load_config()"],
                          capture_output=True, text=True, cwd=REPO,
                          env={**os.environ, "PYTHONPATH": str(SRC)}, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
    names = {line.rsplit("|", 1)[-1].strip() for line in proc.stderr.splitlines() if line.startswith("import time")}
    heavy = sorted(n for n in names if n.split(".")[0] in ("numba", "scipy", "pandas", "numpy", "matplotlib")
                   or n.startswith(("opnav.approach", "opnav.landing", "opnav.report", "opnav.studies")))
    assert not heavy, heavy
