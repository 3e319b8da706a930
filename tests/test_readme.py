"""README as a front door (issue 45 item 6): its findings block is the one generated from the
committed reference claims table of the last full build, so the two cannot differ."""

import re

import pytest
from conftest import REPO

from opnav.report import readme


def test_readme_findings_block_matches_the_reference_claims_table():
    ref = readme.read_reference()
    assert len(ref) >= 10 and set(ref["paper"]) == {"A", "B"}
    text = (REPO / "README.md").read_text()
    assert readme.current_block(text) == readme.findings_block(ref), \
        "README.md's findings differ from docs/reference/claims.csv: run python -m opnav.report.readme"


def test_findings_are_a_few_sentences_and_a_table_of_every_claim():
    ref = readme.read_reference()
    block = readme.findings_block(ref)
    prose = block.split("\n\n")[1]
    assert len(re.findall(r"[.!?](?:\s|$)", prose)) <= 5, prose
    for cid in ref["claim_id"]:
        assert f"| {cid} |" in block
    assert "What it would take" not in prose
    # a group whose claims name different things it would take: none of them (the first
    # group as page 1 words it, without what it would take; the reference table has them)
    two = ref.copy()
    b = two["paper"] == two["paper"].iloc[-1]
    idx = two.index[b][:2]
    two.loc[idx, "verdict"] = "unstable"
    two.loc[idx, "would_take"] = ["a bigger sample", "a quieter machine"]
    prose2 = readme.findings_block(two).split("\n\n")[1]
    assert "What it would take" not in prose2, prose2
    mutated = ref.copy()
    mutated.loc[0, "verdict"] = "suspect" if mutated.loc[0, "verdict"] != "suspect" else "reproduced"
    assert readme.findings_block(mutated) != block  # the block follows the table


def test_a_quick_table_is_refused_as_the_reference():
    ref = readme.read_reference().assign(sample="quick")
    with pytest.raises(ValueError, match="full build"):
        readme.findings_block(ref)


def test_readme_gives_the_two_commands_and_the_quick_report():
    text = (REPO / "README.md").read_text()
    assert 'pip install -r requirements.lock -e ".[test,peers]" && snakemake --cores 2' in text
    assert 'pip install -r requirements.lock -e ".[test,peers]" && pytest' in text
    assert "pytest -m slow" in text
    assert "--configfile config/quick.yaml --report results/quick/report.html" in text
    assert "not findings" in text
