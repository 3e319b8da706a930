"""One palette (opnav.core.figures.PALETTE): every method and scenario variant of both papers
has one colour, and every figure that draws it uses that colour (A-X1 and the A-X3
ablation figure used to colour the roll variant differently)."""

import numpy as np
import pandas as pd
from matplotlib.colors import to_rgba

from opnav.core import figures
from opnav.report import study_plots
from opnav.report.approach import plots as aplots
from opnav.report.approach.text import METHOD_LABELS
from opnav.core.config import load_config
from opnav.report.landing import plots as lplots
from opnav.landing.planner import available_methods
from opnav.studies.metrics import APPROACH_METHODS

VARIANTS = ["literal", "prior", "roll", "reference-start"]
A_ESTIMATORS = ["plain", "squarem", "growing-plain", "growing-squarem", *METHOD_LABELS, *APPROACH_METHODS]


def test_every_label_has_its_own_palette_entry():
    cfg = load_config()
    b_methods = set(available_methods()) | set(cfg["landing"]["mc"]["methods"]) | set(cfg["landing"]["extra"]["methods"])
    for label in [*VARIANTS, *A_ESTIMATORS, *METHOD_LABELS.values(), *b_methods]:
        assert figures.ALIASES.get(label, label) in figures.PALETTE, label
    # distinct within what one paper's figures draw side by side
    for group in (VARIANTS, sorted({figures.ALIASES.get(m, m) for m in A_ESTIMATORS}), sorted(b_methods)):
        cols = [figures.color(x) for x in group]
        assert len(set(cols)) == len(cols), dict(zip(group, cols))
    # aliases are the same method: the same colour
    assert figures.color("EM-EKF (SQUAREM)") == figures.color("em_squarem") == figures.color("squarem")
    # a label outside the palette still gets one colour, from its name alone
    assert figures.color("new_method") == figures.color("new_method")


def _drawn(fig) -> dict[str, set]:
    """legend label -> set of RGBA colours it is drawn with, over every axis of ``fig``."""
    out: dict[str, set] = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            lab = line.get_label()
            if not lab.startswith("_"):
                out.setdefault(lab, set()).add(to_rgba(line.get_color()))
        for cont in ax.containers:
            lab = cont.get_label()
            if lab and not lab.startswith("_"):
                patches = getattr(cont, "patches", None)
                if patches:  # bars
                    out.setdefault(lab, set()).update(to_rgba(p.get_facecolor()) for p in patches)
                elif getattr(cont, "lines", None) and cont.lines[0] is not None:  # error bars: the data line
                    out.setdefault(lab, set()).add(to_rgba(cont.lines[0].get_color()))
    return out


def _study_tidy(paper, variants, methods, metrics):
    rows = []
    for inst, x in (("k~1", 1.0), ("k~2", 2.0)):
        for v in variants or [""]:
            for m in methods:
                for met in metrics:
                    row = {"instance": inst, "method": m, "metric": met, "mean": x, "sd": x, "rms": x,
                           "ci95_low": x - 0.1, "ci95_high": x + 0.1}
                    if v:
                        row["variant"] = v
                    rows.append(row)
    return pd.DataFrame(rows)


def _study(paper, variants, methods, metrics):
    return {"name": "t", "id": "A-S", "title": "t", "paper": paper, "keys": [f"{paper}.k"],
            "statistic": "mean", "metrics": metrics, "methods": methods, "variants": variants,
            "instances": {"k~1": {f"{paper}.k": 1.0}, "k~2": {f"{paper}.k": 2.0}}}


def _figures():
    a = _study("approach", ["literal", "roll"], ["em", "augmented"], ["err_x_arcsec"])
    yield "A study", study_plots.fig_study(_study_tidy("approach", a["variants"], a["methods"], a["metrics"]), a), \
        lambda lab: lab.split(":")[0]
    b = _study("landing", [], ["depth", "svd", "gdop"], ["final_pos_err_m"])
    yield "B study", study_plots.fig_study(_study_tidy("landing", [], b["methods"], b["metrics"]), b), lambda lab: lab
    t = np.linspace(0, 1, 5)
    rng = np.random.default_rng(0)
    from opnav.landing.records import MonteCarlo

    data = {m: MonteCarlo(**{k: rng.normal(size=(3, 5, 3)) for k in ("err_r", "err_v", "err_rpy_deg")})
            for m in ("depth", "svd", "cond")}
    names = {lplots._label(m): m for m in data}
    yield "B-F6", lplots.fig_nav_error_envelopes(t, data), names.get
    long = pd.DataFrame([{"variant": v, "method": m, "case_id": "T1-01", "err_x_mean_arcsec": 1.0,
                          "err_y_mean_arcsec": 1.0, "err_x_std_arcsec": 1.0, "err_y_std_arcsec": 1.0,
                          "crlb_x_arcsec": 0.5, "crlb_y_arcsec": 0.5, "nav_err_after_km": 1.0,
                          "nav_err_before_km": 2.0, "data_to_converge_samples": 100.0,
                          "runtime_s_per_seed": 1.0} for v in ("literal", "roll") for m in METHOD_LABELS])
    inv = {lab: m for m, lab in METHOD_LABELS.items()}
    yield "A-X2", aplots.fig_alternatives(long, METHOD_LABELS), inv.get


def test_every_figure_draws_a_label_in_its_palette_colour():
    import matplotlib.pyplot as plt

    seen: dict[str, set] = {}
    for name, fig, key_of in _figures():
        for lab, cols in _drawn(fig).items():
            key = key_of(lab)
            if key in (None, "") or "CRLB" in lab:
                continue
            seen.setdefault(key, set()).update(cols)
            assert cols == {to_rgba(figures.color(key))}, (name, lab, cols)
        plt.close(fig)
    assert {"roll", "literal", "depth", "svd", "augmented"} <= set(seen)
    assert all(len(c) == 1 for c in seen.values()), seen


def test_saved_png_is_200_dpi_and_tight_even_outside_the_style(tmp_path):
    """save() applies the style's savefig settings itself: a figure drawn in the style and
    saved after the context closed is still >= 200 dpi with a tight bounding box."""
    import matplotlib.pyplot as plt
    from PIL import Image

    from opnav.core import figures

    with figures.style():
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("x (km)")
    w_in, h_in = fig.get_size_inches()
    figures.save(fig, tmp_path / "f.png")
    im = Image.open(tmp_path / "f.png")
    assert im.info["dpi"][0] >= 199.5
    # tight: the white margins of the default layout are cut (smaller than the full canvas)
    assert im.size[0] < w_in * 200 and im.size[1] <= h_in * 200 + 1
    assert im.size[0] > 0.6 * w_in * 200  # and it is the 200-dpi canvas, not a 100-dpi one


def test_paper_a_study_plots_rms_error_with_symbols_and_drops_constant_panels():
    """A stalled estimate has a tiny spread and a large error: paper-A error panels draw the
    RMS about the truth even when the study's statistic is sd; labels are symbols with
    units, never config keys; a panel with one value everywhere is left to the table."""
    import matplotlib.pyplot as plt

    a = _study("approach", ["literal"], ["em"], ["err_x_arcsec", "stalled_pct"])
    a["statistic"] = "sd"
    a["title"] = "centroid pixel error, 3-sigma (px)"
    tidy = _study_tidy("approach", a["variants"], a["methods"], a["metrics"])
    tidy.loc[tidy["metric"] == "err_x_arcsec", "sd"] = 0.01      # spread tiny ...
    tidy.loc[tidy["metric"] == "err_x_arcsec", "rms"] = [9.0, 10.0]  # ... error large
    tidy.loc[tidy["metric"] == "stalled_pct", "mean"] = 100.0       # constant panel
    fig = study_plots.fig_study(tidy, a)
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == 1
    ax = axes[0]
    assert "RMS" in ax.get_ylabel() and "t_x" in ax.get_ylabel()
    assert ax.get_xlabel().replace("\n", " ") == "centroid pixel error, 3-sigma (px)"
    ys = [y for line in ax.get_lines() if line.get_label().startswith("literal: em") for y in line.get_ydata()]
    assert sorted(ys) == [9.0, 10.0]
    for lab in (ax.get_xlabel(), ax.get_ylabel()):
        assert "approach." not in lab and "_" not in lab.replace("t_x", "")
    plt.close(fig)
