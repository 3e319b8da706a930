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
from opnav.studies import METRICS, _slug


_LINESTYLES = ("-", "--", "-.", ":")


def _x_axis(study: Mapping):
    labels = list(study["instances"])
    vals = [study["instances"][lab] for lab in labels]
    if len(study["keys"]) == 1:
        xs = [v[study["keys"][0]] for v in vals]
        if all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in xs):
            return {lab: float(x) for lab, x in zip(labels, xs)}, None, study["keys"][0]
    ticks = [", ".join(_slug(v[k]) for k in study["keys"]) for v in vals]
    return {lab: float(i) for i, lab in enumerate(labels)}, ticks, ", ".join(k.split(".")[-1] for k in study["keys"])


def fig_study(tidy: pd.DataFrame, study: Mapping):
    import matplotlib.pyplot as plt

    stat = study["statistic"]
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
