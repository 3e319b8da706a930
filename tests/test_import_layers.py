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
a cycle is still a cycle in the design. So does every edge the ``import`` statements do not
show (issue 56 item 3, "hidden edges"): a call of ``importlib.import_module``,
``__import__`` or ``importlib.util.find_spec``, and any string naming a module of the
package (``"opnav.landing.ekf"``, or a pattern ``f"opnav.{part}.cli"``, which names every
module it can match): a module that reaches another by its name depends on it as much as
one that imports it. A dynamic import whose target no string shows fails on its own.
"""

import ast
import functools
import re
from pathlib import Path

from conftest import REPO

SRC = REPO / "src"
PAPERS = ("opnav.approach", "opnav.landing")
EDGE = {"opnav.__main__", "opnav.cli", "opnav.approach.cli", "opnav.landing.cli", "opnav.preflight"}
#: core modules allowed to import upwards: none (issue 41 item 3 removed config and checks)
EDGE_EXCEPTIONS: set[str] = set()
RANK = {"core": 0, "approach": 1, "landing": 1, "report": 2, "edge": 3}
#: Cycles known and left to their owners (each a frozenset of module names). None: the
#: ``opnav`` command's dispatch to ``opnav.{part}.cli`` by name, with the paper CLIs importing
#: ``opnav.cli`` back, was a cycle only the string reader saw (issue 57 removed it); a cycle
#: that comes back fails the test.
KNOWN_CYCLES: set[frozenset[str]] = set()
#: Modules whose dynamic imports load the user's own code, never a module of the package (each
#: with why): the checker cannot name their targets, so they are declared here.
USER_CODE_IMPORTS = {
    "opnav.core.registry": "a user's own method: landing.custom_methods, approach.custom_estimators "
                           "'module:function' or 'file.py:function' paths (issue 58)",
}


def _modules() -> dict[str, Path]:
    out = {}
    for f in SRC.rglob("*.py"):
        parts = f.relative_to(SRC).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = f
    return out


#: calls that import (or locate) a module named by their first argument
DYNAMIC_IMPORTS = {"import_module", "__import__", "find_spec"}
#: one name segment where a pattern has a formatted value (``f"opnav.{part}.cli"``)
_SEGMENT = r"[A-Za-z_][A-Za-z0-9_]*"


def _pattern(node) -> str | None:
    """The regular expression of the strings an expression can be, if it is built from string
    constants (a constant, an f-string, ``+``, ``%`` or ``.format`` of constants); None else.
    Each formatted value stands for one name segment."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return re.escape(node.value)
    if isinstance(node, ast.JoinedStr):
        return "".join(re.escape(v.value) if isinstance(v, ast.Constant) else _SEGMENT for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _pattern(node.left), _pattern(node.right)
        return None if left is None and right is None else (left or _SEGMENT) + (right or _SEGMENT)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod) and isinstance(node.left, ast.Constant) \
            and isinstance(node.left.value, str):
        return "".join(_SEGMENT if i % 2 else re.escape(t) for i, t in enumerate(re.split(r"%[sdr]", node.left.value)))
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "format" \
            and isinstance(node.func.value, ast.Constant) and isinstance(node.func.value.value, str):
        return "".join(_SEGMENT if i % 2 else re.escape(t)
                       for i, t in enumerate(re.split(r"\{[^{}]*\}", node.func.value.value)))
    return None


def _call_name(node: ast.Call) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


def _named(tree, mods) -> tuple[set[str], list[str]]:
    """The modules of ``mods`` that strings in ``tree`` name (constants equal to a module's
    name, or patterns matching it: :func:`_pattern`), and the dynamic imports
    (:data:`DYNAMIC_IMPORTS`) whose argument names no module (line numbers)."""
    found, unresolved, inner = set(), [], set()
    names = [m for m in mods if m.startswith("opnav.")]
    for node in ast.walk(tree):  # outer nodes first: a pattern's parts are not read again
        pat = None
        if id(node) not in inner and (isinstance(node, (ast.JoinedStr, ast.BinOp)) or (
                isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value.startswith("opnav."))):
            pat = _pattern(node)
        if pat is not None:
            inner |= {id(n) for n in ast.walk(node) if n is not node}
            if pat.startswith(re.escape("opnav.")):
                found |= {m for m in names if re.fullmatch(pat, m)}
        if isinstance(node, ast.Call) and _call_name(node) in DYNAMIC_IMPORTS and node.args:
            arg = _pattern(node.args[0])
            if arg is None or not any(re.fullmatch(arg, m) for m in mods):
                unresolved.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found, unresolved


@functools.lru_cache(maxsize=None)
def _scan() -> dict[str, tuple[frozenset, frozenset, tuple]]:
    """Each module of the package: the modules it imports, those it names (:func:`_named`)
    and its unresolved dynamic imports (each file parsed once a session)."""
    mods = _modules()
    out = {}
    for name, f in mods.items():
        pkg = name if f.name == "__init__.py" else name.rpartition(".")[0]
        deps = set()
        tree = ast.parse(f.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                deps |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = pkg.split(".")[: len(pkg.split(".")) - (node.level - 1)]
                    base = ".".join(up + ([node.module] if node.module else []))
                deps |= {f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names}
        named, unresolved = _named(tree, mods)
        out[name] = (frozenset(deps), frozenset(named), tuple(unresolved))
    return out


def _graph(strings: bool = True) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (``import`` statements, lazy ones too) and,
    with ``strings``, those it names (:func:`_named`)."""
    scan = _scan()
    return {name: {d for d in (deps | named if strings else deps) if d in scan and d != name}
            for name, (deps, named, _) in scan.items()}


def hidden_edges() -> list[tuple[str, str]]:
    """Edges only a string shows (module -> module it names but does not import)."""
    full, plain = _graph(), _graph(strings=False)
    return sorted((m, d) for m in full for d in full[m] - plain[m])


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


def test_no_dynamic_import_of_an_unnamed_module():
    """Every ``importlib.import_module`` / ``__import__`` / ``find_spec`` in the package names
    its target in a string the checker reads (a constant or a pattern), so no edge of the
    graph is invisible to the two tests above; the modules that load the user's own code are
    declared (``USER_CODE_IMPORTS``)."""
    scan = _scan()
    bad = [f"{name} {u}" for name, (_, _, unresolved) in sorted(scan.items()) for u in unresolved
           if name not in USER_CODE_IMPORTS]
    assert not bad, "\n".join(bad)
    assert all(scan[m][2] for m in USER_CODE_IMPORTS), "a declared user-code import is gone: drop its entry"


def test_core_names_no_module_above_it():
    """The core reaches no paper, report or edge module, by import or by name (the compiled
    kernels' registry is filled by the paper packages themselves: opnav.core.compiled names
    none of their modules)."""
    up = [(m, d) for m, deps in _graph().items() if _layer(m) == "core" for d in deps if _layer(d) != "core"]
    assert not up, up


def test_the_checker_reads_strings_and_dynamic_imports():
    """Mutations of the checker's input: a module reached through importlib by a constant or
    an f-string, or named in a plain string, is an edge; a dynamic import of a variable is
    reported."""
    mods = {"opnav.cli": None, "opnav.approach.cli": None, "opnav.landing.cli": None,
            "opnav.landing.ekf": None, "opnav.core.compiled": None}
    code = ("import importlib\n"
            "def f(part, name):\n"
            "    importlib.import_module(f'opnav.{part}.cli')\n"
            "    KERNELS = ('opnav.landing.ekf',)\n"
            "    __import__('opnav.' + part + '.cli')\n"
            "    return importlib.import_module(name)\n")
    found, unresolved = _named(ast.parse(code), mods)
    assert found == {"opnav.approach.cli", "opnav.landing.cli", "opnav.landing.ekf"}
    assert len(unresolved) == 1 and "import_module(name)" in unresolved[0]
    doc = '"""See opnav.landing.ekf for the filter."""\nx = "opnav.mplstyle"\n'
    assert _named(ast.parse(doc), mods) == (set(), [])
