"""Figure of a parameter study (:mod:`opnav.studies`): each metric against the swept value.

One panel per metric, one line per method (paper A: per scenario variant and
estimator, the variant's colour and the estimator's line style; colours are
:func:`opnav.core.figures.color`'s, as in every figure). ``statistic: mean`` draws the mean over runs with its 95 %
confidence interval as error bars (a share's within 0..100 %); ``sd`` / ``rms`` draw the spread or RMS over
runs, paper-A estimate errors always as their RMS about the truth, with the 1-sigma CRLB beside it
(dashed, black). Axis labels are symbols with units; the x label is the study's title. A panel
in which no line moves with the swept value is left to the table. A
single numeric swept key gives a numeric x axis (log scale when the values span
a decade or more); otherwise the values are categories, in the study's order.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from opnav.core import figures
from opnav.studies.metrics import METRICS, shown_statistic
from opnav.studies.values import slug

_LINESTYLES = ("-", "--", "-.", ":")


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _order_key(values: Mapping, keys):
    """Sort key of a value set: its values in key order (numbers and lists of numbers
    compare naturally; anything else by its text)."""
    def one(v):
        if _is_number(v):
            return (0, float(v), "")
        if isinstance(v, (list, tuple)) and all(_is_number(x) for x in v):
            return (1, tuple(float(x) for x in v), "")
        return (2, (), str(v))
    return tuple(one(values[k]) for k in keys)


def _x_axis(study: Mapping):
    """x position of every instance, the tick labels (None: a numeric axis) and the label.
    A numeric first key gives a numeric axis (zipped keys named beside it); otherwise the
    value sets are categories in ascending order of their values."""
    labels = list(study["instances"])
    vals = [study["instances"][lab] for lab in labels]
    keys = list(study["keys"])
    xs = [v[keys[0]] for v in vals]
    if all(_is_number(x) for x in xs) and len(set(xs)) == len(xs):
        others = ", ".join(k.split(".")[-1] for k in keys[1:])
        xlabel = keys[0] + (f" (zipped: {others})" if others else "")
        return {lab: float(x) for lab, x in zip(labels, xs)}, None, xlabel
    order = sorted(range(len(labels)), key=lambda i: _order_key(vals[i], keys))
    ticks = [", ".join(slug(vals[i][k]) for k in keys) for i in order]
    return ({labels[i]: float(j) for j, i in enumerate(order)}, ticks,
            ", ".join(k.split(".")[-1] for k in keys))


#: axis labels with symbols and units (the study tables keep opnav.studies.metrics.METRICS' names)
PLOT_LABELS = {
    "err_x_arcsec": r"$\hat t_x - t_x$ (arcsec)", "err_y_arcsec": r"$\hat t_y - t_y$ (arcsec)",
    "err_z_arcsec": r"$\hat t_z - t_z$ (arcsec)",
    "crlb_x_arcsec": r"CRLB $\sigma_{t_x}$, all data (arcsec)", "crlb_y_arcsec": r"CRLB $\sigma_{t_y}$, all data (arcsec)",
    "crlb_used_x_arcsec": r"CRLB $\sigma_{t_x}$, data used (arcsec)",
    "crlb_used_y_arcsec": r"CRLB $\sigma_{t_y}$, data used (arcsec)",
    "median_plan_time_us": "median planning time (µs)", "median_plan_cpu_us": "median planning CPU time (µs)",
}


#: metrics that cannot be negative (norms, counts, NEES, times): their intervals stop at 0
NONNEGATIVE = {"landing": frozenset(METRICS["landing"]),
               "approach": frozenset(m for m in METRICS["approach"] if not m.startswith("err_"))}


def axis_label(metric: str, paper: str, stat: str) -> str:
    """The y label of a metric's panel: symbol and unit; 'RMS error' for paper-A estimate
    errors (RMS about the truth), the statistic's name otherwise."""
    base = PLOT_LABELS.get(metric, METRICS[paper][metric][0].replace("(us)", "(µs)"))
    if stat == "rms" and metric.startswith("err_"):
        return f"RMS of {base}"
    if stat == "sd":
        return f"sd of {base}"
    return base


def plotted_statistic(study: Mapping, metric: str) -> str:
    """What a panel draws: paper A's estimate errors as their RMS about the truth (a stalled
    estimate that never moved has a tiny spread but a large error) and its other metrics as
    their mean, else :func:`opnav.studies.metrics.shown_statistic`."""
    stat = shown_statistic(study, metric)
    if study["paper"] == "approach" and stat == "sd":
        # errors about the truth as their RMS; any other quantity (a km error norm, data
        # needed) as its mean with interval: the spread of an error norm is not its size
        return "rms" if metric.startswith("err_") else "mean"
    return stat


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) if "$" not in text else text


def _flat(v: np.ndarray) -> bool:
    v = v[np.isfinite(v)]
    return float(np.ptp(v)) <= 1e-12 * max(1.0, float(np.abs(v).max())) if v.size else True


def _constant(tidy: pd.DataFrame, metric: str, stat: str) -> bool:
    """A panel in which no line moves with the swept value (every method's and variant's
    value the same at every instance, e.g. a stall flag at 100 % for one estimator and 0 %
    for another): it shows nothing a sentence cannot, so the figure leaves it to the table."""
    d = tidy[tidy["metric"] == metric]
    if d["instance"].nunique() < 2:
        return False
    by = [c for c in ("variant", "method") if c in d.columns]
    return all(_flat(g[stat].to_numpy(float)) for _, g in (d.groupby(by, sort=False) if by else [(None, d)]))


def fig_study(tidy: pd.DataFrame, study: Mapping):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    metrics = [m for m in study["metrics"] if not _constant(tidy, m, plotted_statistic(study, m))] \
        or list(study["metrics"])
    xmap, ticks, xlabel = _x_axis(study)
    xlabel = _wrap(study.get("title") or xlabel, 28)
    ncol = min(3, len(metrics))
    nrow = math.ceil(len(metrics) / ncol)
    units = [(v, m) for v in (study["variants"] or [""]) for m in study["methods"]]
    with figures.style():
        fig, axs = plt.subplots(nrow, ncol, figsize=(figures.PAGE_WIDTH_IN, 1.8 * nrow + 0.45),
                                squeeze=False, constrained_layout=True)
        for ax, metric in zip(axs.ravel(), metrics):
            bound = METRICS[study["paper"]][metric][1]
            stat = plotted_statistic(study, metric)
            d = tidy[tidy["metric"] == metric]
            for variant, method in units:
                dm = d[d["method"] == method]
                if variant:
                    dm = dm[dm["variant"] == variant]
                x = np.array([xmap[i] for i in dm["instance"]])
                order = np.argsort(x, kind="stable")
                x = x[order]
                y = dm[stat].to_numpy(float)[order]
                # paper A: the variant's colour, the estimator's line style; paper B: the method's colour
                col = figures.color(variant or method)
                ls = _LINESTYLES[list(study["methods"]).index(method) % len(_LINESTYLES)] if variant else "-"
                name = f"{variant}: {method}" if variant else method
                if stat == "mean":
                    lo = dm["ci95_low"].to_numpy(float)[order]
                    hi = dm["ci95_high"].to_numpy(float)[order]
                    if metric.endswith("_pct"):  # a share's interval stays within 0..100 %
                        lo, hi = np.clip(lo, 0.0, 100.0), np.clip(hi, 0.0, 100.0)
                    elif metric in NONNEGATIVE[study["paper"]]:  # an error norm, count or time: >= 0
                        lo = np.clip(lo, 0.0, None)
                    err = np.vstack([y - lo, hi - y])
                    err = np.where(np.isfinite(err), err, 0.0)
                    ax.errorbar(x, y, yerr=err, fmt="o", ls=ls, color=col, ms=3, capsize=2, label=name)
                else:
                    ax.plot(x, y, "o", ls=ls, color=col, ms=3, label=name)
            if bound and stat != "mean":
                b = tidy[(tidy["metric"] == bound)]
                for j, variant in enumerate(study["variants"] or [""]):
                    bv = b[(b["variant"] == variant)] if variant else b
                    bv = bv[bv["method"] == study["methods"][0]]
                    xb = np.array([xmap[i] for i in bv["instance"]])
                    o = np.argsort(xb, kind="stable")
                    ax.plot(xb[o], bv["mean"].to_numpy(float)[o], "--", color="k" if j == 0 else "0.55",
                            lw=1.2, label=f"{variant}: CRLB" if variant else "CRLB")
            ax.set_ylabel(_wrap(axis_label(metric, study["paper"], stat), 30))
            ax.set_xlabel(xlabel)
            if metric.endswith(("_us", "_s")) and np.nanmin(d[stat].to_numpy(float)) > 0:
                ax.set_yscale("log")  # times span decades between methods
                ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: figures.plain_number(v)))
            if ticks is not None:
                ax.set_xticks(range(len(ticks)), ticks, rotation=30 if len(ticks) > 4 else 0)
            else:
                xs = np.array(sorted(xmap.values()))
                if xs.min() > 0 and xs.max() / xs.min() >= 10:
                    ax.set_xscale("log")
                    ax.set_xticks(xs, [figures.plain_number(x) for x in xs])
                    ax.xaxis.set_minor_formatter(NullFormatter())
        for ax in axs.ravel()[len(metrics):]:
            ax.set_visible(False)
        handles, labels = axs.ravel()[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)), fontsize=7)
        fig.suptitle(f"{study['id']}: {study['name']} study", fontsize=9)
    return fig
