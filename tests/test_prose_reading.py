"""Prose a reader can follow (issue 55 item 4): numbers, counts and changes said through one
helper (opnav.report.wording), and no generated sentence longer than 40 words; the checks
find what e19e33d's outputs held (the ~313-word navigation sentence of pp. 4-5, '1 maps',
'1 stars per image', '-0 % lower', a velocity 3-sigma ratio of 0.9999 printed as 1)."""

import pytest

from opnav.report import print_size, wording

#: e19e33d's quick build, results/paper/macros.tex: the navigation sentence (one macro, one
#: sentence of 322 words here, repeated per variant) and the convergence sentence's slip
E19_NAV = (r"\newcommand{\ATextNav}{Navigation error (RMS over the last part of the arc) after compensation, split "
           r"across and along the line of sight, beside the filter given the true $\theta$ (a diagnostic floor): "
           + "; ".join(rf"{v}: after compensation 118 km (lateral 108, range 41.8: the lateral channel sets it); with "
                       rf"the true $\theta$ 41.8 km (lateral 0.21, range 41.8); position NEES (initial error drawn from the "
                       rf"prior, 3 expected): 5.2$\times10^{{5}}$ compensated with $\theta$\_hat as exact, 2.66 with the "
                       rf"Schmidt filter carrying the bound of $\theta$\_hat's data, 2.52 with the true $\theta$"
                       for v in ("literal", "prior", "roll", "reference-start", "stars")) + ".}")
E19_CONV = (r"\newcommand{\ATextConvergence}{On one window of the convergence study, the EM maps needed to come "
            r"within the tolerance of the maximum-likelihood estimate are: literal: plain EM needs 1 maps, SQUAREM 1.}")
E19_STARS = (r"\newcommand{\ATextStars}{From 1 to 1 stars per image the bound goes from 2.73 to 2.73 arcsec "
             r"(-0\,\% lower) at the configured attitude knowledge (5 arcsec).}")


def test_numbers_counts_and_changes_read_right():
    assert wording.num(0.9999) == "0.9999" and wording.num(1.0) == "1" and wording.num(-0.0001, 1) == "-0.0001"
    assert wording.num(19.96) == "20" and wording.num(-0.0) == "0" and wording.num(None) == "n/a"
    assert wording.num(12345.6) == "12346" and wording.num(float("inf")) == "n/a"
    assert wording.count(1, "map") == "1 map" and wording.count(3, "map") == "3 maps"
    assert wording.count(1, "star") == "1 star" and wording.count(0, "run", zero="no run") == "no run"
    assert wording.count(2, "axis") == "2 axes" and wording.count(2, "study") == "2 studies"
    assert wording.change(-0.3) == "unchanged" and wording.change(0.4) == "unchanged"
    assert wording.change(12.4) == "12 % lower" and wording.change(-3.6) == "4 % higher"
    assert wording.key_value("target_arcsec", "20.6") == "a target of 20.6 arcsec"
    assert wording.key_value("margin_rel", "1.38") == "a relative margin of 1.38"
    assert wording.key_words("roll_rate_deg_s") == ("roll rate", "deg/s")


def test_sentences_are_cut_where_a_reader_stops():
    text = ("Fig. 6 shows e.g. the error vs. time (paper B, sec. 3). It is 1.5 m. Then J. X. Li wrote it.\n\n"
            "A new paragraph")
    assert wording.sentences(text) == ["Fig. 6 shows e.g. the error vs. time (paper B, sec. 3).", "It is 1.5 m.",
                                       "Then J. X. Li wrote it.", "A new paragraph"]
    assert wording.word_count("depth minus SVD -0.027 m [-0.0732, +0.0193]") == 7
    long = "a " * 30 + "(with a parenthesis of words) and, finally, a last clause that runs on and on"
    short = wording.shorten(long, 32)
    assert wording.word_count(short) <= 32 and "parenthesis" not in short


def test_long_sentences_and_slips_are_found_in_e19e33d_fragments(tmp_path):
    paper = tmp_path / "paper"
    paper.mkdir()
    (paper / "macros.tex").write_text("\n".join([E19_NAV, E19_CONV, E19_STARS,
                                                 r"\newcommand{\AUnused}{" + "word " * 60 + ".}"]) + "\n")
    (paper / "floats.tex").write_text(
        "\\begin{table}\\caption{Short caption.}\\begin{tabular}{ll}" + " & ".join(["cell"] * 80)
        + "\\\\\\end{tabular}\\end{table}\n")
    used = {"ATextNav", "ATextConvergence", "ATextStars"}
    found = print_size.long_sentence_findings(tmp_path, used)
    assert len(found) == 1 and "ATextNav" in found[0], found       # the table's cells and the unused macro are not read
    assert int(found[0].split("(")[1].split()[0]) > 300
    slips = print_size.slip_findings(tmp_path, used)
    assert any("1 maps" in s for s in slips) and any("1 stars" in s for s in slips)
    assert any("signed zero" in s for s in slips), slips
    # said through the helpers, the same facts are clean
    (paper / "macros.tex").write_text(
        r"\newcommand{\ATextConvergence}{Plain EM needs " + wording.count(1, "map") + ".}\n"
        r"\newcommand{\ATextStars}{From " + wording.count(1, "star") + " per image the bound is "
        + wording.change(-0.2) + ".}\n")
    assert print_size.slip_findings(tmp_path, used) == [] and print_size.long_sentence_findings(tmp_path, used) == []
