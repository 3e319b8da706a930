"""What we did differently: every choice the papers leave open or that we changed, with
our value (from the run's configuration), the paper's (from ``published.yaml``, or "not
given") and the section that shows its effect.

The list of choices is data (``src/opnav/data/differences.yaml``); no value is written
there or here, so the table follows the configuration a build ran with.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

DIFFERENCES = Path(__file__).resolve().parents[1] / "data" / "differences.yaml"
NOT_GIVEN = "not given"
PAPERS = {"paper_a": "A", "paper_b": "B"}


def lookup(tree: Mapping[str, Any], dotted: str) -> Any:
    """The value at a dotted path of a nested mapping (``KeyError`` naming the path)."""
    node: Any = tree
    for part in dotted.split("."):
        if not isinstance(node, Mapping) or part not in node:
            raise KeyError(f"differences.yaml: no key {dotted!r}")
        node = node[part]
    return node


def value_text(v: Any) -> str:
    """A configuration value as table text: lists comma-joined, mappings by their keys,
    floats without trailing zeros (1e6 as 1,000,000)."""
    if isinstance(v, Mapping):
        return ", ".join(str(k) for k in v)
    if isinstance(v, (list, tuple)):
        return ", ".join(value_text(x) for x in v)
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:,.0f}" if abs(v) >= 1e4 and v == int(v) else f"{v:g}"
    if isinstance(v, int):
        return f"{v:,}" if abs(v) >= 1e4 else str(v)
    return str(v)


def subset(config: Mapping[str, Any], spec: Mapping | None = None) -> dict:
    """The part of ``config`` the table reads (its ``keys``, nested as in the config): the
    rule's params, so editing any other key reruns nothing of page 1."""
    spec = yaml.safe_load(DIFFERENCES.read_text()) if spec is None else spec
    out: dict = {}
    for items in spec.values():
        for it in items:
            for k in it["keys"]:
                parts = k.split(".")
                node = out
                for part in parts[:-1]:
                    node = node.setdefault(part, {})
                node[parts[-1]] = lookup(config, k)
    return out


def rows(config: Mapping[str, Any], published: Mapping[str, Any], spec: Mapping | None = None) -> list[dict]:
    """One row per choice: paper, choice, ours, paper's value, where its effect is shown."""
    spec = yaml.safe_load(DIFFERENCES.read_text()) if spec is None else spec
    out = []
    for paper_key, items in spec.items():
        for it in items:
            for k in it["keys"]:
                lookup(config, k)  # every key exists: a renamed key fails here, by name
            ours = re.sub(r"\{([A-Za-z0-9_.-]+)\}", lambda m: value_text(lookup(config, m.group(1))), it["text"])
            if it.get("published"):
                pub = value_text(lookup(published, it["published"]))
                pub += f" {it['published_unit']}" if it.get("published_unit") else ""
            else:
                pub = NOT_GIVEN
            out.append({"paper": PAPERS[paper_key], "choice": it["choice"], "ours": ours, "paper_value": pub,
                        "where": it["where"]})
    return out


def latex(table: list[dict]) -> str:
    """The choices as a LaTeX tabular (wrapping text columns; ``where`` as a reference)."""
    from opnav.report.manuscript import prose_tex

    lines = [(r"\begin{tabular}{@{}l>{\raggedright\arraybackslash}p{0.22\linewidth}"
             r">{\raggedright\arraybackslash}p{0.4\linewidth}>{\raggedright\arraybackslash}p{0.17\linewidth}l@{}}"),
             r"\toprule", r"paper & choice & ours & paper & shown in \\", r"\midrule"]
    for i, r in enumerate(table):
        if i and r["paper"] != table[i - 1]["paper"]:
            lines.append(r"\midrule")
        lines.append(" & ".join([r["paper"], prose_tex(r["choice"]), prose_tex(r["ours"]),
                                 prose_tex(r["paper_value"]), rf"\ref{{{r['where']}}}"]) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}"]
    return "\n".join(lines) + "\n"
