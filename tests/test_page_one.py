"""Page 1 (issue 45 item 1, 2): the short abstract from the claims table, the verdict figure
(one row per claim) and the table of what we did differently, read from the configuration."""

import copy
import re

import pandas as pd
import pytest
from conftest import REPO

from opnav.core import published
from opnav.core.config import load_config
from opnav.report import claims_prose, differences, manuscript

#: a cause as long as the claims table allows (opnav.report.claims.MAX_CAUSE_WORDS)
LONG_CAUSE = ("the Cramér-Rao bound of the data it used is 20.6 arcsec, the prior's own sigma_r / rho, so a camera "
              "that keeps Mars on its boresight cannot tell the misalignment from a lateral position error of "
              "the same size at this range, far above the claimed accuracy")


def _table(n_a=10, n_b=10, columns=None):
    verdicts = ["reproduced", "not_reproducible", "not_reproducible", "depends_on_choice", "reproduced_with_addition",
                "not_reproduced", "suspect", "unstable", "not_tested", "not_reproducible"]
    rows = []
    for p, n in (("A", n_a), ("B", n_b)):
        for i in range(n):
            rows.append({"paper": p, "claim_id": f"{p}-C{i + 1}", "claim": f"Claim {i} of paper {p} (sec. 3)",
                         "published": "2 arcsec", "ours_as_written": "20.6 arcsec (converged 20/20)",
                         "ours_best": "1.2 arcsec", "best_variant": "roll", "verdict": verdicts[i % len(verdicts)],
                         "cause": LONG_CAUSE, "would_take": "a roll of 0.1 deg/s about the boresight, which the "
                         "pipeline measures, gives 2 arcsec in 250 samples", "flags": "", "sample": "full"})
    df = pd.DataFrame(rows)
    # what a verdict names where the claims table requires it (opnav.report.claims.NEEDS_NAMED)
    named = {"not_reproducible": "the bound 20.6 arcsec of the data as written (T1-01), not at most 2 arcsec",
             "depends_on_choice": "the camera, which the paper does not give",
             "reproduced_with_addition": "a camera that rolls about its boresight (not in the paper)",
             "suspect": "literal is 3.2 times below its own bound", "not_tested": "no evidence for the method",
             "unstable": "main sample reproduced, replication not reproduced"}
    df["named"] = df["verdict"].map(lambda v: named.get(v, ""))
    return df[columns] if columns else df


def _abstract_words(tex: str) -> int:
    return claims_prose.word_count(tex) + claims_prose.ABSTRACT_FRAMING_WORDS


def test_abstract_is_at_most_200_words_with_every_choice_and_cause():
    """Issue 55 item 5: page 1 names the choice of every claim that depends on one and the cause
    of every claim not reproduced, in at most 200 words with main.tex's framing, every sentence at
    most 40 words; the other groups and what they would take only while they fit."""
    from opnav.core import wording
    from opnav.report.claims import MAX_CAUSE_WORDS

    assert len(LONG_CAUSE.split()) >= MAX_CAUSE_WORDS - 3
    main = (REPO / "paper" / "main.tex").read_text()
    framing = main[main.index(r"\begin{abstract}"):main.index(r"\input{\resultsdir/paper/abstract.tex}")]
    printed = re.sub(r"~\\cite\{[^}]*\}", " [1]", framing.replace(r"\begin{abstract}", "").replace(r"\noindent", ""))
    assert claims_prose.word_count(printed.replace("~", " ")) <= claims_prose.ABSTRACT_FRAMING_WORDS
    dense = _table()                  # every verdict in both papers, each cause as long as a cause may be
    roomy = _table(6, 6)              # fewer claims: room for the other groups
    many = _table(10, 10).assign(verdict=["not_reproduced", "depends_on_choice"] * 10,   # 10 causes, 10 choices
                                 named=["", "the camera, which the paper does not give"] * 10)
    for df in (dense, roomy, many):
        for sample in ("", "This build is the quick profile: its samples are too small for verdicts."):
            tex = claims_prose.page_one_abstract_tex(df, sample)
            assert _abstract_words(tex) <= claims_prose.ABSTRACT_MAX_WORDS, (len(df), sample)
            assert not wording.long_sentences(re.sub(r"\\[A-Za-z]+\{?\}?", " ", tex)), tex
            gaps = claims_prose.abstract_gaps(df, tex)
            if df is many:  # more causes than page 1 holds: every choice named, the causes left to Appendix A
                assert "Appendix A gives each cause" in tex and not [g for g in gaps if "choice" in g], gaps
            else:
                assert gaps == [], tex
            assert "((" not in tex and not any(c.count("(") > 1 for c in tex.split(". "))  # no nested parentheses
    tex = claims_prose.page_one_abstract_tex(roomy)
    assert "of its 6 claims" in tex and "A-C2 and A-C3 are not reproducible: the bound 20.6" in tex
    assert "What it would take" in tex
    assert "A-C6 is not reproduced: the Cram" in tex and "A-C4 depends on the camera" in tex
    # a generated number, not fixed text: another table, another abstract
    assert "of its 4 claims" in claims_prose.abstract_findings(_table(n_a=4, n_b=3))


def test_abstract_gaps_finds_what_e19e33d_page_1_left_out():
    """e19e33d's full build: page 1 named neither A-C7's choice nor B-C7's cause."""
    e19 = ("Paper A: of its 10 claims, 2 reproduced, 4 with an addition, 2 not reproduced, 1 not reproducible and 1 "
           "depends on a choice. Paper B: of its 8 claims, 4 reproduced, 2 not reproduced, 1 not tested and 1 unstable. "
           "B-C2 and B-C7 are not reproduced. For B-C2: In no camera does depth reach the threshold sooner than SVD by "
           "one filter step (1 s) or more (interior: depth minus SVD 0.0833 s [-0.0284, 0.195] over 300 runs, below 100 m).")
    df = pd.DataFrame([
        {"paper": "A", "claim_id": "A-C7", "verdict": "depends_on_choice",
         "named": "the arc length and the navigation-error rule, which the paper does not state", "cause": ""},
        {"paper": "B", "claim_id": "B-C2", "verdict": "not_reproduced", "named": "", "cause": "In no camera does depth reach the "
         "threshold sooner than SVD by one filter step (1 s) or more (interior: depth minus SVD 0.0833 s [-0.0284, "
         "0.195] over 300 runs, below 100 m)."},
        {"paper": "B", "claim_id": "B-C7", "verdict": "not_reproduced", "named": "", "cause": "In the interior camera the paired "
         "intervals do not show depth with smaller errors than SVD, GDOP and condition number (depth minus SVD "
         "-0.0085 m [-0.017, -9.5e-05] against SVD 0.376 m)."}])
    gaps = claims_prose.abstract_gaps(df, e19)
    assert [g.split(":")[0] for g in gaps] == ["A-C7", "B-C7"], gaps
    assert claims_prose.abstract_gaps(df, claims_prose.abstract_findings(df)) == []


def test_abstract_of_a_quick_table_says_its_sample_is_too_small():
    df = _table(3, 3).assign(sample="quick")
    tex = claims_prose.page_one_abstract_tex(df, claims_prose.sample_sentence_of(df))
    assert tex.startswith("This build is the quick profile")
    assert claims_prose.sample_sentence_of(_table(3, 3)) == ""
    assert claims_prose.sample_sentence_of(_table(3, 3).drop(columns="sample")) == ""  # an older table


def _figure_texts(fig):
    """Every non-empty text of a drawn figure with its box on the page (display units)."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    return [(t.get_text(), t.get_window_extent(r)) for t in fig.findobj(lambda a: hasattr(a, "get_text")
                                                                          and hasattr(a, "get_window_extent"))
            if getattr(t, "get_text", None) and isinstance(t.get_text(), str) and t.get_text().strip()
            and t.get_visible()]


def _markers(fig, marker):
    return [ln for ln in fig.axes[0].get_lines() if ln.get_marker() == marker]


@pytest.mark.parametrize("n_a, n_b, replication", [(9, 10, True), (10, 8, False), (3, 3, True)])
def test_verdict_figure_is_a_grid_of_claims_by_verdict_without_cut_or_overlapping_text(n_a, n_b, replication):
    """Issue 55 item 3: page 1's figure marks each claim's verdict in its verdict's column (a
    dot for the main sample, a diamond for the replication), every text whole (no ellipsis)
    and clear of every other, inside the figure; no published value or ours (Table 1 has them)."""
    import matplotlib.pyplot as plt

    from opnav.report import verdict_plot

    df = _table(n_a, n_b)
    df["claim"] = df["claim"] + " and a long tail that a narrow column must wrap onto a second line"
    if replication:
        df["verdict_replication"] = ["not_reproduced" if i % 3 else v for i, v in enumerate(df["verdict"])]
    fig = verdict_plot.fig_verdicts(df)
    assert len(_markers(fig, "o")) == len(df) + 1               # the key's dot (drawn first), one per claim
    assert len(_markers(fig, "D")) == (len(df) + 1 if replication else 0)
    verdicts = list(dict.fromkeys([*df["verdict"], *(df["verdict_replication"] if replication else [])]))
    heads = {t for t, _ in _figure_texts(fig)}
    assert all(any(verdict_plot.verdict_word(v).split()[-1] in h for h in heads) for v in verdicts)
    texts = _figure_texts(fig)
    page = fig.bbox
    for text, box in texts:
        assert "…" not in text and "..." not in text, text
        assert box.x0 >= page.x0 - 0.5 and box.x1 <= page.x1 + 0.5 and box.y0 >= page.y0 - 0.5 \
            and box.y1 <= page.y1 + 0.5, (text, box, page)
        assert "20.6 arcsec" not in text and "2 arcsec" != text.strip(), text   # Table 1's values
    for i, (t1, b1) in enumerate(texts):
        for t2, b2 in texts[i + 1:]:
            assert not b1.overlaps(b2), (t1, t2)
    # the dot of each claim lies in its verdict's column, under that column's head
    for ln, v in zip(_markers(fig, "o")[1:], df["verdict"]):   # the first dot is the key's
        x = fig.axes[0].transData.transform((ln.get_xdata()[0], ln.get_ydata()[0]))[0]
        head = [b for t, b in texts if t.replace("\n", " ") == verdict_plot.verdict_word(v)]
        assert head and head[0].x0 - 30 <= x <= head[0].x1 + 30, v
    plt.close(fig)


def test_verdict_figure_tolerates_older_tables():
    import matplotlib.pyplot as plt

    from opnav.report import verdict_plot

    old = _table(3, 3, columns=["paper", "claim_id", "claim", "published", "ours_as_written", "verdict", "cause"])
    fig = verdict_plot.fig_verdicts(old)
    assert len(_markers(fig, "o")) == 7 and not _markers(fig, "D")
    plt.close(fig)


def test_wrap_to_width_never_cuts_a_word():
    from opnav.report import verdict_plot

    lines = verdict_plot.wrap_to_width("a b c extraordinarilylongword d", 0.2, 7.0)
    assert "extraordinarilylongword" in lines and " ".join(lines) == "a b c extraordinarilylongword d"
    assert all(verdict_plot._width_in(ln, 7.0) <= 0.2 for ln in lines if " " in ln)


def test_differences_read_ours_from_the_configuration():
    cfg = load_config()
    pub = published.load()
    rows = differences.rows(cfg, pub)
    by = {r["choice"]: r for r in rows}
    assert by["sample time"]["ours"] == f"{cfg['approach']['dt_s']:g} s"
    assert by["sample time"]["paper_value"] == f"{pub['paper_a']['simulation']['dt_s']:g} s"
    assert by["range noise"]["paper_value"] == differences.NOT_GIVEN
    cfg2 = copy.deepcopy(cfg)
    cfg2["approach"]["segments"]["N"] = 77
    assert "77" in {r["choice"]: r for r in differences.rows(cfg2, pub)}["EM segments (N0, N, M, L)"]["ours"]
    bad = {"paper_a": [{"choice": "x", "keys": ["approach.no_such_key"], "text": "{approach.no_such_key}",
                        "where": "sec:approach"}]}
    with pytest.raises(KeyError, match="approach.no_such_key"):
        differences.rows(cfg, pub, bad)
    assert r"\ref{sec:landing}" in differences.latex(rows)


def test_conclusion_states_each_finding_once():
    """Issue 45 item 5: an addition shared by four claims is named once (it was repeated per
    claim), every claim appears once, and the limitations name the claims that hinge on a choice."""
    df = _table(10, 10)
    df["named"] = ""
    addition = "a camera that rolls about its boresight, growing windows and SQUAREM"
    df.loc[df["verdict"] == "reproduced_with_addition", "named"] = addition
    df.loc[df["claim_id"] == "B-C1", "verdict"] = "reproduced_with_addition"
    df.loc[df["claim_id"] == "B-C1", "named"] = addition
    text = claims_prose.conclusion_text(df)
    assert text.count(addition) == 2  # once per paper, for all the claims that share it
    findings = re.sub(r"What it would take for [^:]*:", "What it would take:", text)  # which claim a take is for
    for cid in df["claim_id"]:
        assert len(re.findall(rf"\b{cid}\b(?!\d)", findings)) == 1, cid
    lim = claims_prose.limitations_text(df)
    hinge = df.loc[df["verdict"].isin(["depends_on_choice", "not_tested", "unstable"]), "claim_id"]
    assert all(c in lim for c in hinge)


def test_plan_and_inputs_appendix_is_latin_script_latex():
    """The analysis plan quotes paper A in Chinese: the appendix prints its English rendering
    (pdflatex without CJK fonts stops on the first Chinese character)."""
    from opnav.report import claims

    plan = claims.load_plan().table()
    tex = manuscript.plan_latex(plan)
    assert not re.search(r"[\u2e80-\u9fff\uff00-\uffef\u3000-\u303f\u2033]", tex)
    assert tex.count(r"\item[") == len(plan)
    assert manuscript.latin_text("估计精度优于2″ (estimation accuracy better than 2 arcsec), headline case") == \
        "estimation accuracy better than 2 arcsec, headline case"
    ins = pd.DataFrame([{"input": "A sample time", "ours": "0.5 s", "published": "0.5 s", "how_derived": "x",
                         "what_would_match": "y"}])
    assert r"\item[A sample time] Ours 0.5 s" in manuscript.inputs_latex(ins)


def test_the_rule_reads_only_the_keys_the_table_shows():
    cfg = load_config()
    pub = published.load()
    sub = differences.subset(cfg)
    assert differences.rows(sub, pub) == differences.rows(cfg, pub)
    assert "accuracy_target_arcsec" not in sub["approach"]  # an edit elsewhere reruns nothing of page 1


def test_build_wall_time_is_the_union_of_its_jobs_from_snakemakes_records(tmp_path):
    """Issue 55 item 7: the PDF states the build's wall time and machine beside the heavy jobs'
    job time. The wall time is the time at least one job ran (side-by-side jobs once, a pause
    between two invocations not at all), read from .snakemake/metadata."""
    import base64
    import json

    meta = tmp_path / "metadata"
    meta.mkdir()

    def record(path, rule, start, end, job_hash, **kw):
        b64 = base64.urlsafe_b64encode(path.encode()).decode()
        parts = [b64[i:i + 60] for i in range(0, len(b64), 60)]  # a long name, cut as Snakemake does
        f = meta.joinpath(*["@" + p for p in parts[:-1]], parts[-1])
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(json.dumps({"rule": rule, "starttime": start, "endtime": end, "job_hash": job_hash,
                                 "incomplete": False, **kw}))

    record("results/quick/a/x.csv", "mc", 100.0, 160.0, 1)
    record("results/quick/a/x.png", "mc", 100.000004, 160.0, 1)           # the same job's other output
    record("results/quick/b/y.csv", "mc", 120.0, 200.0, 2)                  # side by side with it
    record("results/quick/c/" + "long_folder_name/" * 20 + "z.csv", "tables", 1000.0, 1010.0, 3)  # a later run
    record("results/full/a/x.csv", "mc", 0.0, 5000.0, 4)                    # another profile's
    record("results/quick/d/z.csv", "mc", 300.0, 310.0, 5, incomplete=True)
    (meta / "not-base64!").write_text("{}")
    for rel in ("results/quick/a/x.csv", "results/quick/a/x.png", "results/quick/b/y.csv",
                "results/quick/c/" + "long_folder_name/" * 20 + "z.csv", "results/full/a/x.csv", "results/quick/d/z.csv"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("")
    record("results/quick/e/gone.csv", "old", 5000.0, 6000.0, 6)            # no longer made
    jobs = manuscript.snakemake_jobs(meta, "results/quick", workdir=tmp_path)
    assert [(r, a, b) for r, a, b in jobs] == [("mc", 100.0, 160.0), ("mc", 120.0, 200.0), ("tables", 1000.0, 1010.0)]
    assert manuscript.busy_wall_s(jobs) == pytest.approx(110.0)
    bench = [pd.DataFrame({"s": [600.0], "cpu_time": [540.0]}), pd.DataFrame({"s": [60.0], "cpu_time": [30.0]})]
    tex = manuscript.run_info_tex(bench, "AMD EPYC (2 logical cores, 24 GB memory)", jobs)
    assert "AMD EPYC (2 logical cores, 24 GB memory)" in tex and "its 3 jobs" in tex and "1.8 min of wall time" in tex
    assert "The 2 heavy jobs" in tex and "11.0 min of job time" in tex and "9.5 CPU-min" in tex
    assert "docs/run-times.md" in tex
    assert manuscript.snakemake_jobs(tmp_path / "none", "results/quick", workdir=tmp_path) == []
    assert "This build ran on" in manuscript.run_info_tex([], "x", [])
    assert "logical cores" in manuscript.machine_text()


def test_the_html_reports_claims_use_the_pdfs_words():
    """Issue 55 item 11: the report's claims table and landing page say 'ours, as written' and
    'not reproducible', as the PDF does, not ours_as_written and not_reproducible."""
    df = _table(4, 4).assign(verdict_replication=["", "not_reproduced", "unstable", "", "", "reproduced", "", ""])
    out = manuscript.claims_for_readers(df)
    assert "ours, as written" in out.columns and "verdict, replication sample" in out.columns
    assert not [c for c in out.columns if "_" in c]
    words = set(out["verdict"]) | set(out["verdict, replication sample"])
    assert "not reproducible" in words and "depends on a choice" in words and "unstable" in words
    assert not [w for w in words if "_" in w]
    assert out["published"].tolist() == df["published"].tolist()   # cells otherwise unchanged
