"""House counts of issue 56 (reproducible with ``ast``): dict-returning functions, constant-string
subscripts, ``.get("k")`` calls and lines of presentation in the paper packages.

    python benchmarks/house_counts.py [SRC] [--by-file] [--list]

SRC is the package folder (default ``src/opnav``). What is counted, per module:

* **dict-returning function** (column ``dict_functions``, issue 56's target): a function (or
  method) one of whose own ``return`` statements (not a nested function's) returns a dict display
  (``{...}``), a dict comprehension or a ``dict(...)`` call, or whose return annotation is
  ``dict`` / ``dict[...]`` / ``Dict[...]`` / ``Mapping`` (with or without ``| None``), unless it
  is a keyed map (below). A function returning ``list[dict]`` counts too (its annotation names
  ``dict`` inside ``list[...]``/``tuple[...]``);
* **keyed map** (column ``keyed_maps``, not in ``dict_functions``): a function annotated as
  returning ``dict[K, V]`` / ``Mapping[K, V]`` whose values ``V`` are typed (a record class, a
  number, ``str``, an array: not ``Any``, ``object``, a bare or nested dict) and none of whose
  returns is a dict display with a constant string key or a ``dict(k=...)`` call: a map keyed by
  data (method name -> record, run -> median, label -> reading). Such a function is counted here
  whatever its key: the ``.npz`` edges (``MonteCarlo.arrays``, ``Replay.arrays``,
  ``records.load``: array name -> array) are keyed maps by this rule too, as are config helpers
  annotated with typed values. ``all_dicts`` is both columns together (the count before this rule
  existed);
* **record-as-dict function** (column ``record_dicts``, a subset): one that hands a *record* over
  as a dict: it returns a dict display with a constant string key or a ``dict(k=...)`` call, or
  its annotation is an untyped dict (``dict``, ``Mapping``, ``dict[str, Any]``, a dict of dicts,
  ``list[dict]``). A mapping keyed by data whose values are typed (``dict[str, NeesRow]``,
  ``dict[str, float]``: variant or method name to a record or a number) is not a record;
* **constant-string subscript**: ``x["k"]`` (any ``Subscript`` whose index is a str constant,
  as a load, store or delete; pandas column lookups included);
* **``.get("k")``**: a call ``x.get("k", ...)`` whose first argument is a str constant;
* **presentation lines** in a paper package (``approach/``, ``landing/``, ``studies/``): the
  lines of its modules that import matplotlib (plots), plus, in every other module of the
  package, the lines of functions returning ``str`` (annotation ``-> str``) or whose name says
  text (``*_text``, ``*_note``, ``*_label``, ``*_prose``, ``*caption*``): prose and labels.

The totals are printed per part (approach, landing, core, studies, report, other) and for the
whole tree; ``--by-file`` adds every module's counts, ``--list`` every dict-returning function.
"""

from __future__ import annotations

import argparse
import ast
from collections import Counter, defaultdict
from pathlib import Path

PAPERS = ("approach", "landing", "studies")
TEXT_NAMES = ("_text", "_note", "_label", "_prose", "caption", "_words", "_sentence")


def _mentions_dict(ann: ast.AST | None) -> bool:
    """Whether a return annotation is (or holds) a dict type."""
    if ann is None:
        return False
    if isinstance(ann, ast.Constant) and isinstance(ann.value, str):  # a string annotation
        try:
            ann = ast.parse(ann.value, mode="eval").body
        except SyntaxError:
            return False
    for node in ast.walk(ann):
        if isinstance(node, ast.Name) and node.id in ("dict", "Dict", "Mapping", "MutableMapping"):
            return True
        if isinstance(node, ast.Attribute) and node.attr in ("Dict", "Mapping", "MutableMapping"):
            return True
    return False


def _own_returns(fn: ast.AST):
    """The return statements of ``fn`` itself (not of functions or classes nested in it)."""
    stack = list(fn.body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(node, ast.Return):
            yield node
        stack.extend(ast.iter_child_nodes(node))


def _is_dict_value(v: ast.AST | None) -> bool:
    if isinstance(v, (ast.Dict, ast.DictComp)):
        return True
    return isinstance(v, ast.Call) and isinstance(v.func, ast.Name) and v.func.id == "dict"


def returns_dict(fn) -> bool:
    if _mentions_dict(fn.returns):
        return True
    return any(_is_dict_value(r.value) for r in _own_returns(fn))


_TYPED_VALUES = ("float", "int", "str", "bool", "np.ndarray", "ndarray")


def _untyped_dict_annotation(ann: ast.AST | None) -> bool:
    """A dict annotation whose values are untyped: bare dict/Mapping, ``Any``/``object`` values,
    dict values, or a list/tuple of dicts."""
    if ann is None:
        return False
    if isinstance(ann, ast.Constant) and isinstance(ann.value, str):
        try:
            ann = ast.parse(ann.value, mode="eval").body
        except SyntaxError:
            return False
    if isinstance(ann, ast.BinOp):  # X | None
        return _untyped_dict_annotation(ann.left) or _untyped_dict_annotation(ann.right)
    name = lambda n: n.id if isinstance(n, ast.Name) else (n.attr if isinstance(n, ast.Attribute) else "")  # noqa: E731
    if name(ann) in ("dict", "Dict", "Mapping", "MutableMapping"):
        return True
    if isinstance(ann, ast.Subscript):
        outer = name(ann.value)
        args = ann.slice.elts if isinstance(ann.slice, ast.Tuple) else [ann.slice]
        if outer in ("dict", "Dict", "Mapping", "MutableMapping"):
            value = args[-1]
            v = ast.unparse(value)
            return v in ("Any", "object") or _mentions_dict(value)
        if outer in ("list", "tuple", "Sequence", "Iterator", "Iterable"):
            return any(_untyped_dict_annotation(a) for a in args)
    return False


def keyed_map(fn) -> bool:
    """A function returning a map keyed by data with typed values (module docstring)."""
    ann = fn.returns
    if ann is None:
        return False
    if isinstance(ann, ast.Constant) and isinstance(ann.value, str):
        try:
            ann = ast.parse(ann.value, mode="eval").body
        except SyntaxError:
            return False
    if isinstance(ann, ast.BinOp):      # X | None
        sides = [x for x in (ann.left, ann.right) if not (isinstance(x, ast.Constant) and x.value is None)]
        if len(sides) != 1:
            return False
        ann = sides[0]
    if not isinstance(ann, ast.Subscript):
        return False
    outer = ann.value.id if isinstance(ann.value, ast.Name) else (
        ann.value.attr if isinstance(ann.value, ast.Attribute) else "")
    if outer not in ("dict", "Dict", "Mapping"):
        return False
    args = ann.slice.elts if isinstance(ann.slice, ast.Tuple) else [ann.slice]
    if len(args) != 2:
        return False
    value = args[1]
    if ast.unparse(value) in ("Any", "object") or _mentions_dict(value):
        return False
    for r in _own_returns(fn):
        v = r.value
        if isinstance(v, ast.Dict) and any(isinstance(k, ast.Constant) and isinstance(k.value, str) for k in v.keys):
            return False
        if isinstance(v, ast.Call) and isinstance(v.func, ast.Name) and v.func.id == "dict" and v.keywords:
            return False
    return True


def returns_record_dict(fn) -> bool:
    if _untyped_dict_annotation(fn.returns):
        return True
    for r in _own_returns(fn):
        v = r.value
        if isinstance(v, ast.Dict) and any(isinstance(k, ast.Constant) and isinstance(k.value, str) for k in v.keys):
            return True
        if isinstance(v, ast.Call) and isinstance(v.func, ast.Name) and v.func.id == "dict" and v.keywords:
            return True
        if isinstance(v, ast.DictComp) and fn.returns is None:
            return True
    return False


def _is_text_function(fn) -> bool:
    ann = fn.returns
    if isinstance(ann, ast.Name) and ann.id == "str":
        return True
    if isinstance(ann, ast.Constant) and ann.value == "str":
        return True
    return any(t in fn.name for t in TEXT_NAMES)


def _imports_matplotlib(tree: ast.AST) -> bool:
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] == "matplotlib" for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "matplotlib":
            return True
    return False


def count_module(path: Path) -> dict:
    src = path.read_text()
    tree = ast.parse(src)
    c = Counter()
    dict_fns = []
    text_lines = 0
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if returns_dict(node):
                c["all_dicts"] += 1
                if keyed_map(node):
                    c["keyed_maps"] += 1
                    dict_fns.append(f"{node.name}:{node.lineno} (keyed map)")
                else:
                    rec = returns_record_dict(node)
                    c["record_dicts"] += rec
                    c["dict_functions"] += 1
                    dict_fns.append(f"{node.name}:{node.lineno}{' (record)' if rec else ''}")
            if _is_text_function(node):
                text_lines += node.end_lineno - node.lineno + 1
        elif isinstance(node, ast.Subscript):
            s = node.slice
            if isinstance(s, ast.Constant) and isinstance(s.value, str):
                c["str_subscripts"] += 1
        elif isinstance(node, ast.Call):
            f = node.func
            if (isinstance(f, ast.Attribute) and f.attr == "get" and node.args
                    and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
                c["get_calls"] += 1
    c["lines"] = len(src.splitlines())
    c["plot_lines"] = c["lines"] if _imports_matplotlib(tree) else 0
    c["text_lines"] = 0 if c["plot_lines"] else text_lines
    return {"counts": c, "dict_fns": dict_fns}


def part_of(rel: Path) -> str:
    top = rel.parts[0] if len(rel.parts) > 1 else "other"
    return top if top in ("approach", "landing", "core", "studies", "report") else "other"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("src", nargs="?", default=str(Path(__file__).resolve().parents[1] / "src" / "opnav"))
    ap.add_argument("--by-file", action="store_true")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args(argv)
    root = Path(a.src)
    parts: dict[str, Counter] = defaultdict(Counter)
    files = {}
    for p in sorted(root.rglob("*.py")):
        rel = p.relative_to(root)
        r = count_module(p)
        files[rel] = r
        parts[part_of(rel)].update(r["counts"])
    keys = ("dict_functions", "record_dicts", "keyed_maps", "all_dicts", "str_subscripts", "get_calls", "plot_lines",
            "text_lines", "lines")
    print(f"{'part':<10}" + "".join(f"{k:>15}" for k in keys))
    total = Counter()
    for name in ("approach", "landing", "studies", "core", "report", "other"):
        total.update(parts[name])
        print(f"{name:<10}" + "".join(f"{parts[name][k]:>15}" for k in keys))
    print(f"{'total':<10}" + "".join(f"{total[k]:>15}" for k in keys))
    pres = sum(parts[n]["plot_lines"] + parts[n]["text_lines"] for n in PAPERS)
    print(f"presentation lines in paper packages ({', '.join(PAPERS)}): {pres}")
    if a.by_file:
        print()
        for rel, r in files.items():
            c = r["counts"]
            if any(c[k] for k in keys[:8]):
                print(f"{str(rel):<44}" + "".join(f"{c[k]:>8}" for k in keys[:8]))
    if a.list:
        print()
        for rel, r in files.items():
            for f in r["dict_fns"]:
                print(f"{rel}:{f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
