"""Every report caption is valid reStructuredText: docutils reports nothing."""

import io
from pathlib import Path

import pytest
from conftest import REPO

docutils_core = pytest.importorskip("docutils.core")

CAPTIONS = sorted((REPO / "workflow" / "report").glob("*.rst"))


def test_there_are_captions():
    assert len(CAPTIONS) >= 10


def _rendered(path: Path, tmp: Path, profile: str = "full", wildcards: dict | None = None) -> str:
    """A caption as Snakemake's report renders it: Jinja with ``snakemake.config`` (the
    profile's), the job's wildcards and the report's files (the landing page reads the claims
    at a glance from the results)."""
    from types import SimpleNamespace

    import jinja2

    from opnav.core.config import load_config

    (tmp / "paper").mkdir(parents=True, exist_ok=True)
    (tmp / "paper" / "claims_glance.csv").write_text(
        "claim_id,claim,published,ours_as_written,verdict\nA-C1,accuracy,2 arcsec,20 arcsec,not_reproducible\n")
    cfg = load_config(overlays=(REPO / "config" / "quick.yaml",) if profile == "quick" else ())
    cfg.update(profile=profile, results_dir=str(tmp))
    wildcards = wildcards or {"bscn": next(iter(cfg["landing"]["scenarios"]))}
    snakemake = SimpleNamespace(config=cfg, params=SimpleNamespace(caption="a caption"),
                                wildcards=SimpleNamespace(**wildcards))
    files = [SimpleNamespace(target="main.pdf")]
    return jinja2.Environment().from_string(path.read_text()).render(snakemake=snakemake, files=files)


@pytest.mark.parametrize("path", CAPTIONS, ids=lambda p: p.name)
def test_caption_renders_without_messages(path: Path, tmp_path):
    warnings = io.StringIO()
    text = _rendered(path, tmp_path)
    if path.name == "workflow.rst":  # the landing page: the claims table and the PDF, Claims first
        assert "A-C1" not in text and "claims_glance.csv" in text and "main.pdf_" in text
        assert "too small for verdicts" in _rendered(path, tmp_path, "quick") and "too small" not in text
        text += "\n\n.. _Claims: #\n.. _main.pdf: #\n"  # the link targets Snakemake appends
    docutils_core.publish_doctree(
        text, source_path=str(path),
        settings_overrides={"report_level": 1, "halt_level": 5, "warning_stream": warnings})
    assert warnings.getvalue() == "", warnings.getvalue()


def test_bx1_caption_states_each_cameras_runs(tmp_path):
    """B-X1 compares every method on the first n runs of each camera (landing.extra.n_runs,
    fewer than the paper's methods fly where set): its caption says how many, per camera."""
    from opnav.core.config import load_config

    path = REPO / "workflow" / "report" / "B-X1.rst"
    cfg = load_config()
    n_mc = cfg["landing"]["mc"]["n_runs"]
    for scn in cfg["landing"]["scenarios"]:
        n = min(n_mc, cfg["landing"]["extra"].get("n_runs", {}).get(scn, n_mc))
        text = " ".join(_rendered(path, tmp_path, wildcards={"bscn": scn}).split())
        assert f"runs 0 to {n - 1} ({n} runs" in text, (scn, text)
        assert (f"of the {n_mc} the paper's methods fly" in text) == (n < n_mc), (scn, text)


# ------------------------------------------------------------ captions fit to print
import re

#: abbreviations a sentence does not end on
_ABBREV = re.compile(r"\b(Fig|Figs|Eq|eq|e\.g|i\.e|vs|cf|Sec|sec|Tab|No)\.$")
#: a dotted config key, e.g. landing.mc.methods or approach.camera.sigma3_px
CONFIG_KEY = re.compile(r"\b(approach|landing|paper|studies)\.[a-z_0-9]+(\.[a-z_0-9]+)*\b")
#: the landing page of the HTML report is not a float caption
NOT_FLOATS = {"workflow.rst"}


def sentences(text: str) -> list[str]:
    """The sentences of a caption: split after . ! ? followed by a capital or an opening
    bracket, not after an abbreviation (Fig., eq., e.g.) or inside a number (1.5)."""
    text = " ".join(text.split())
    out, start = [], 0
    for m in re.finditer(r"[.!?](?=\s+[A-Z(*`:])", text):
        if _ABBREV.search(text[start:m.end()]):
            continue
        out.append(text[start:m.end()].strip())
        start = m.end()
    tail = text[start:].strip()
    return out + ([tail] if tail else [])


@pytest.mark.parametrize("path", [p for p in CAPTIONS if p.name not in NOT_FLOATS], ids=lambda p: p.name)
def test_caption_sentences_are_at_most_40_words(path: Path, tmp_path):
    """Every caption as rendered, each sentence <= 40 words (issue 55 item 4): the build's prose
    test reads only the captions a build prints, and B-F7.overhead.rst's 41-word sentence hid
    behind the wrong caption there. Mutation tried once: that sentence back fails it."""
    from opnav.core import wording

    assert wording.long_sentences(" ".join(_rendered(path, tmp_path).split())) == []


def test_sentence_counter():
    assert len(sentences("One (Fig. 4, eq. 19-26). Two, e.g. this. Three 1.5 s! Four")) == 4
    assert len(sentences("Paper A Fig. 5 re-run: a, b. The C.")) == 2


@pytest.mark.parametrize("path", [p for p in CAPTIONS if p.name not in NOT_FLOATS], ids=lambda p: p.name)
def test_caption_is_three_sentences_without_config_keys(path: Path):
    text = path.read_text()
    assert len(sentences(text)) <= 3, sentences(text)
    assert not CONFIG_KEY.search(text), CONFIG_KEY.search(text).group(0)


def test_study_captions_are_three_sentences_without_config_keys():
    """Every configured study's generated caption (the float under its figure)."""
    from test_studies import _shapes

    from opnav.core.config import SCHEMA_PATH, load_config, validate_config
    from opnav.landing.planner import available_methods
    from opnav.studies import captions, planning

    for overlays in ((), (REPO / "config" / "quick.yaml",)):
        cfg = load_config(overlays=overlays)
        plan = planning.plan(cfg, _shapes(cfg), lambda c: validate_config(c, SCHEMA_PATH), available_methods())
        assert plan
        for name, st in plan.items():
            cap = captions.caption(st.spec())
            assert len(sentences(cap)) <= 3, (name, sentences(cap))
            assert not CONFIG_KEY.search(cap), (name, CONFIG_KEY.search(cap).group(0))
            # it names what the axes show: paper A's spread studies plot RMS errors about the truth
            assert ("RMS about the truth" in cap) == (st.spec()["paper"] == "approach"
                                                      and st.spec()["statistic"] == "sd"), name
