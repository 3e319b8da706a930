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
    prose = block.split("\n\n")[2]
    assert len(re.findall(r"[.!?](?:\s|$)", prose)) <= 6, prose
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
    prose2 = readme.findings_block(two).split("\n\n")[2]
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


def test_from_a_build_stamps_its_commit_and_date_and_the_timing_claims(tmp_path, monkeypatch, capsys):
    """Issue 55 item 9: --from reads the build's provenance beside its results and the block
    names that build (commit, uncommitted edits, date) and says which verdicts time code on the
    build's machine; a table without provenance is refused, naming the file."""
    import json

    ref = readme.read_reference()
    results = tmp_path / "results"
    (results / "paper").mkdir(parents=True)
    ref.to_csv(results / "paper" / "claims.csv", index=False)
    monkeypatch.setattr(readme, "REFERENCE", tmp_path / "docs" / "claims.csv")
    monkeypatch.setattr(readme, "REFERENCE_PROVENANCE", tmp_path / "docs" / "provenance.json")
    (tmp_path / "README.md").write_text(f"# x\n\n{readme.START}\nold\n{readme.END}\n")
    monkeypatch.setattr(readme, "README", tmp_path / "README.md")
    assert readme.main(["--from", str(results / "paper" / "claims.csv")]) == 2   # no provenance: nothing written
    assert not (tmp_path / "docs" / "claims.csv").exists()
    (results / "provenance.json").write_text(json.dumps(
        {"git_commit": "0123456789abcdef0123", "git_dirty": "yes", "built_utc": "2026-12-07 09:15 UTC"}))
    quick = tmp_path / "q" / "paper" / "claims.csv"
    quick.parent.mkdir(parents=True)
    ref.assign(sample="quick").to_csv(quick, index=False)
    (tmp_path / "q" / "provenance.json").write_text("{}")
    assert readme.main(["--from", str(quick)]) == 2                                # a quick build: refused
    assert "full build" in capsys.readouterr().err
    assert readme.main(["--from", str(results / "paper" / "claims.csv")]) == 0
    text = (tmp_path / "README.md").read_text()
    assert "From the full build of commit 0123456789ab with uncommitted edits (built 2026-12-07 09:15 UTC)." in text
    timing = readme.timing_claims(ref)
    assert {"B-C4", "B-C9"} <= set(timing) and "A-C1" not in timing
    assert f"{' and '.join(timing) if len(timing) == 2 else timing[-1]} time planning calls on the build's machine" in text
    # a table without timing claims says nothing about machines
    no_timing = readme.findings_block(ref[~ref["claim_id"].isin(timing)], {"git_commit": "x"})
    assert "machine" not in no_timing


def test_docs_name_no_path_of_the_machine_they_were_written_on():
    """Issue 55 item 10: the user docs and the developers' work log hold no absolute path of a
    machine (a work folder, a scratch folder, a home), which a reader cannot open. Four such
    paths had come back into docs/dev/performance-log.md with a measurement section. Mutation
    tried once: one of them restored fails it."""
    pat = re.compile(r"(?<![\w.])/(?:work|tmp|root|home|scratch)/")
    found = [f"{p.relative_to(REPO)}:{n}" for p in [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md"))]
             for n, line in enumerate(p.read_text().splitlines(), 1) if pat.search(line)]
    assert found == [], found
