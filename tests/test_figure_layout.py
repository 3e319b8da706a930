"""Figures fit to print: every figure of the pipeline, drawn on data shaped like a build's,
keeps its legends clear of the plotted data, the tick labels, the axis labels and titles
(opnav.core.figures.legend_collisions on the drawn figure, as it is saved to PNG), and
its labels use symbols, not ASCII spellings (theta, +-, 3-sigma)."""

import re
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from opnav.core import figures

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


# ------------------------------------------------------------------ data shaped like a build's
def _approach_runs(n_seeds=20, n_seg=8, per=5, n_t=200):
    """Headline-case runs of three EM schemes, with the long legend labels of a real build
    (scheme, convergence counts, bound) and NEES curves that fill the axes the way the
    roll variant's do (the theta = 0 filter far above the band, the others inside it)."""
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 2100.0, n_t)
    d = 200.0 + 50.0 * np.arange(1, n_seg + 1)
    runs = {}
    for method, mode in (("plain", "sliding"), ("squarem", "sliding"), ("squarem", "growing")):
        th = np.array([10.0, 20.0, 10.0]) + rng.normal(size=(n_seeds, n_seg * per, 3)) * np.linspace(8, 0.3, n_seg * per)[None, :, None]
        lat = 100.0 * np.exp(-np.arange(n_seg) / 3.0)[None] * (1 + 0.2 * rng.random((n_seeds, n_seg)))
        before = 1e3 * np.exp(-t / 900.0) + 3.0 + 2.0 * rng.random((n_seeds, n_t))
        after = 3.0 + rng.random((n_seeds, n_t)) * np.linspace(8.0, 0.5, n_t)
        nis = 2.4 + 1.2 * rng.random((n_seeds, n_t))
        split = {k: (v + rng.random((n_seeds, n_t)), v / 5 + rng.random((n_seeds, n_t)))
                 for k, v in (("before", 78.0), ("after", 18.0), ("true_theta", 15.0))}
        runs[f"{mode}-{method}"] = SimpleNamespace(
            method=method, mode=mode, t_s=t, case=SimpleNamespace(init_arcsec=(0.0, 0.0, 0.0)),
            truth_arcsec=np.array([10.0, 20.0, 10.0]), theta_iter_arcsec=th, tz_unobservable=True,
            seg_data_used=d, label=np.array(["converged"] * 17 + ["stalled"] * 3),
            bounds=SimpleNamespace(crlb_arcsec=np.array([20.6, 20.6]), crlb_seg_arcsec=np.c_[
                30.0 / np.sqrt(np.arange(1, n_seg + 1)), 25.0 / np.sqrt(np.arange(1, n_seg + 1)), np.full(n_seg, np.inf)]),
            seg_lat_err_km=lat, seg_lat_3sig_km=np.tile(30.0 * np.ones(n_seg), (n_seeds, 1)),
            seg_rng_err_km=lat / 10, seg_rng_3sig_km=np.tile(8.0 * np.ones(n_seg), (n_seeds, 1)),
            err_before_t_km=80.0 + rng.random((n_seeds, n_t)),
            err_after_t_km=20.0 + 60 * np.exp(-t / 500)[None] * rng.random((n_seeds, 1)),
            err_split_t_km=SimpleNamespace(**split),
            sampled=SimpleNamespace(theta_final_arcsec=np.zeros((n_seeds, 3)), consistency_t=SimpleNamespace(
                before=SimpleNamespace(nees_pos=before, nis=nis), after=SimpleNamespace(nees_pos=after, nis=nis),
                consider=SimpleNamespace(nees_pos=after), true_theta=SimpleNamespace(nees_pos=0.8 * after))))
    return runs


PUB_A = {"headline": {"est_x_arcsec": 11.43, "est_y_arcsec": 21.21, "nav_err_before_km": 79.06,
                      "nav_err_after_km": 18.43}}


def _x1():
    curves = {v: np.c_[40.0 / np.sqrt(np.arange(1, 2001) / 50.0), np.ones(2000)] * (0.05 if v == "roll" else 1.0)
              for v in ("literal", "prior", "roll", "reference-start")}
    conv = {v: SimpleNamespace(**{m: SimpleNamespace(dist_arcsec=np.geomspace(10, 1e-3 if m == "squarem" else 1.0,
                                                                             40)[None].repeat(3, 0))
                                  for m in ("plain", "squarem")}) for v in curves}
    x1 = pd.DataFrame([{"variant": v, "total_samples": 2000, "em_plain_rmse_x_arcsec": 20.0 if v != "roll" else 1.0,
                        "mle_samples": 2000, "mle_rmse_x_arcsec": 18.0 if v != "roll" else 0.5} for v in curves])
    from opnav.report.approach import plots
    return plots.fig_crlb(curves, conv, x1, 2.0, 200)


def _approach(name):
    from opnav.report.approach import plots
    runs = _approach_runs()
    return {"A-F4": lambda: plots.fig_bias_estimate(runs, "roll", PUB_A, 50, 5),
            "A-F5": lambda: plots.fig_nav_accuracy(runs, "roll"),
            "A-F6": lambda: plots.fig_compensation(runs, "roll", PUB_A),
            "A-X4": lambda: plots.fig_consistency(runs, "roll")}[name]()


def _b_f4():
    from opnav.report.landing import plots
    t = np.linspace(0, 198, 199)
    s = np.linspace(1, 0, 199)[:, None]
    return plots.fig_true_states(t, np.array([3300, 5870, 6570]) * s, np.array([-56, -66, -90]) * s,
                                 np.c_[-25.7 * s[:, 0], -9.8 * s[:, 0], 0 * s[:, 0]])


def _b_f6():
    from opnav.report.landing import plots
    t = np.linspace(0, 198, 199)
    rng = np.random.default_rng(1)
    from opnav.landing.records import MonteCarlo

    data = {m: MonteCarlo(**{k: rng.normal(size=(6, 199, 3)) * np.geomspace(100, 1, 199)[None, :, None]
                             for k in ("err_r", "err_v", "err_rpy_deg")}) for m in ("depth", "svd", "gdop", "cond")}
    return plots.fig_nav_error_envelopes(t, data)


def _study():
    from opnav.report import study_plots
    spec = {"name": "roll_rate", "id": "A-X3", "title": "roll rate (deg/s)", "paper": "approach",
            "keys": ["approach.roll.rate_deg_s"], "statistic": "sd", "metrics": ["err_x_arcsec", "stalled_pct"],
            "methods": ["em", "augmented"], "variants": ["roll"],
            "instances": {f"r~{x}": {"approach.roll.rate_deg_s": x} for x in (0.025, 0.05, 0.1, 0.2, 0.4)}}
    rows = []
    for i, (inst, x) in enumerate(spec["instances"].items()):
        for m in spec["methods"]:
            for met in spec["metrics"]:
                v = (100.0 if m == "em" else 0.0) if met == "stalled_pct" else 10.0 / (i + 1)
                rows.append({"instance": inst, "variant": "roll", "method": m, "metric": met, "mean": v, "sd": v,
                             "rms": v, "ci95_low": v * 0.9, "ci95_high": v * 1.1})
    return study_plots.fig_study(pd.DataFrame(rows), spec)


FIGURES = {"A-F4": lambda: _approach("A-F4"), "A-F5": lambda: _approach("A-F5"),
           "A-F6": lambda: _approach("A-F6"), "A-X4": lambda: _approach("A-X4"), "A-X1": _x1,
           "B-F4": _b_f4, "B-F6": _b_f6, "study": _study}
#: drawn in the default (fast) set; the others take 3-8 s each on a shared machine
FAST = {"A-X4", "study"}


ASCII = re.compile(r"\+-|(?<!\\)theta|\b[13]-sigma|chi-square|\de[+-]0")


def _labels(fig) -> list[str]:
    out = []
    for ax in fig.axes:
        out += [ax.get_xlabel(), ax.get_ylabel(), ax.get_title()]
        leg = ax.get_legend()
        out += [t.get_text() for t in leg.get_texts()] if leg else []
    for leg in fig.legends:
        out += [t.get_text() for t in leg.get_texts()]
    return out


@pytest.mark.parametrize("name", [n if n in FAST else pytest.param(n, marks=pytest.mark.slow) for n in sorted(FIGURES)])
def test_legends_clear_of_data_ticks_and_labels(name, tmp_path):
    import matplotlib.pyplot as plt

    fig = FIGURES[name]()
    try:
        assert figures.legend_collisions(fig) == [], name
        # ASCII spellings where a symbol belongs
        for lab in _labels(fig):
            assert not ASCII.search(lab), (name, lab)
        if name == "study":  # the stall flag (100 % at every roll rate) is not a panel
            assert [ax.get_ylabel() for ax in fig.axes if ax.get_visible()] == ["RMS of $\\hat t_x - t_x$ (arcsec)"]
        figures.save(fig, tmp_path / f"{name}.png")  # and it saves (the drawn layout is the saved one)
    finally:
        plt.close("all")


def test_the_checker_sees_a_legend_over_data_ticks_and_the_frame():
    """The check itself: a legend over a line, one over the grey band, one spilling over the
    frame (wider than its axes, over the ticks) are each reported; a legend outside is not."""
    import matplotlib.pyplot as plt

    with figures.style():
        fig, ax = plt.subplots(figsize=(3, 2))
        ax.plot([0, 1], [0, 1], label="diagonal")
        ax.legend(loc="center")
        assert "line 'diagonal'" in " ".join(figures.legend_collisions(fig))
        ax.cla()
        ax.plot([0, 1], [1, 1], label="flat")
        ax.axhspan(0.0, 0.2, color="0.8", label="band")
        ax.set_ylim(0, 1.1)
        ax.legend(loc="lower left")
        assert "patch 'band'" in " ".join(figures.legend_collisions(fig))
        ax.legend(["a label far wider than the small axes it belongs to, over the ticks"], loc="upper left")
        assert "frame" in " ".join(figures.legend_collisions(fig))
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))
        assert figures.legend_collisions(fig) == []
        plt.close(fig)


def test_place_legend_finds_the_empty_corner_or_goes_outside():
    import matplotlib.pyplot as plt

    with figures.style():
        fig, ax = plt.subplots(figsize=(3, 2))
        ax.plot(np.linspace(0, 1, 50), np.linspace(0, 1, 50) ** 4, label="rising late")
        leg = figures.place_legend(ax)
        assert leg._loc in (2,)  # upper left: the curve stays low there
        assert figures.legend_collisions(fig) == []
        ax.fill_between([0, 1], 0, 1, color="0.8", label="everywhere")
        leg = figures.place_legend(ax)
        assert leg.get_bbox_to_anchor() is not None and figures.legend_collisions(fig) == []
        plt.close(fig)

