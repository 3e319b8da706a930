"""Figure of a parameter study (:mod:`opnav.studies`): each metric against the swept value.

One panel per metric, one line per method (paper A: per scenario variant and
estimator, the variant's colour and the estimator's line style; colours are
:func:`opnav.figures.color`'s, as in every figure). ``statistic: mean`` draws the mean over runs with its 95 %
confidence interval as error bars; ``sd`` / ``rms`` draw the spread or RMS over
runs, and for paper-A errors the 1-sigma CRLB beside it (dashed, black). A
single numeric swept key gives a numeric x axis (log scale when the values span
a decade or more); otherwise the values are categories, in the study's order.
"""

from __future__ import annotations

import math
from typing import Mapping

import numpy as np
import pandas as pd

from opnav import figures
from opnav.studies import METRICS, _slug, shown_statistic


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
    ticks = [", ".join(_slug(vals[i][k]) for k in keys) for i in order]
    return ({labels[i]: float(j) for j, i in enumerate(order)}, ticks,
            ", ".join(k.split(".")[-1] for k in keys))


def fig_study(tidy: pd.DataFrame, study: Mapping):
    import matplotlib.pyplot as plt

    metrics = list(study["metrics"])
    xmap, ticks, xlabel = _x_axis(study)
    ncol = min(3, len(metrics))
    nrow = math.ceil(len(metrics) / ncol)
    units = [(v, m) for v in (study["variants"] or [""]) for m in study["methods"]]
    with figures.style():
        fig, axs = plt.subplots(nrow, ncol, figsize=(figures.PAGE_WIDTH_IN, 2.3 * nrow + 0.6),
                                squeeze=False, constrained_layout=True)
        for ax, metric in zip(axs.ravel(), metrics):
            label, bound = METRICS[study["paper"]][metric]
            stat = shown_statistic(study, metric)
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
                    err = np.vstack([y - lo, hi - y])
                    err = np.where(np.isfinite(err), err, 0.0)
                    ax.errorbar(x, y, yerr=err, fmt="o", ls=ls, color=col, ms=3, capsize=2, label=name)
                else:
                    ax.plot(x, y, "o", ls=ls, color=col, ms=3, label=f"{name} ({stat})")
            if bound and stat != "mean":
                b = tidy[(tidy["metric"] == bound)]
                for j, variant in enumerate(study["variants"] or [""]):
                    bv = b[(b["variant"] == variant)] if variant else b
                    bv = bv[bv["method"] == study["methods"][0]]
                    xb = np.array([xmap[i] for i in bv["instance"]])
                    o = np.argsort(xb, kind="stable")
                    ax.plot(xb[o], bv["mean"].to_numpy(float)[o], "--", color="k" if j == 0 else "0.55",
                            lw=1.2, label=f"{variant}: CRLB" if variant else "CRLB")
            ax.set_ylabel(label if stat == "mean" else f"{stat} of {label}")
            ax.set_xlabel(xlabel)
            if ticks is not None:
                ax.set_xticks(range(len(ticks)), ticks, rotation=30 if len(ticks) > 4 else 0)
            else:
                xs = np.array(sorted(xmap.values()))
                if xs.min() > 0 and xs.max() / xs.min() >= 10:
                    ax.set_xscale("log")
        for ax in axs.ravel()[len(metrics):]:
            ax.set_visible(False)
        handles, labels = axs.ravel()[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=min(4, len(labels)), fontsize=7)
        fig.suptitle(f"{study['id']} {study['name']}: {study['title']}", fontsize=9)
    return fig
