"""Paper B's planning time in words and rows: the method sentence of every caption that quotes a
replayed time (:func:`method_text`), a reduction in words (:func:`less_time_text`), the clock in
words (:data:`CLOCK_WORDS`) and the per-variant rows a timing job logs (:func:`summary_frame`),
from a replay (``opnav.landing.timing``) read by ``opnav.landing.timing_summary``.

Units: us in the rows, ns in the replay.
"""

from __future__ import annotations

import math

import numpy as np

from typing import TYPE_CHECKING

from opnav.landing.timing_summary import (CLOCK, cell_times_ns, clock_share, median_evals, n_replays, paper_calls,
                                          replay_calls, replayed_methods, timed)

if TYPE_CHECKING:
    from opnav.landing.records import Replay

__all__ = ["CLOCK_WORDS", "less_time_text", "method_text", "summary_frame", "sources_text"]

#: ``timing_summary.CLOCK`` in words
CLOCK_WORDS = "thread CPU time"


def less_time_text(reduction_pct: float) -> str:
    """A :func:`time_reduction` in words: ``"34.2 % less"``, a negative one ``"137.4 % more"``
    (not "-137.4 % less"); ``"n/a"`` if it is nan."""
    if not math.isfinite(reduction_pct):
        return "n/a"
    return f"{reduction_pct:.1f} % less" if reduction_pct >= 0 else f"{-reduction_pct:.1f} % more"


def sources_text(sources) -> str:
    """The methods whose recorded calls a replay replayed, in words (``"depth, svd"``)."""
    return ", ".join(str(x) for x in sources)


def method_text(tm: "Replay") -> str:
    """One sentence stating how the times were measured (captions, paper)."""
    n, pool = replay_calls(tm), int(tm.n_pool)
    srcs = sources_text(tm.sources)
    subset = (f"all {pool} recorded planning calls" if n == pool else
              f"{n} of the {pool} recorded planning calls (every {pool / n:.1f}th by index, "
              f"landing.timing.max_calls = {int(tm.max_calls)})")
    mis = int(np.sum(tm.mismatch))
    npaper = paper_calls(tm)
    paper = ("" if npaper in (0, n) else
             f" The paper's definition (interpreted, CasADi H) runs on {npaper} of them, evenly spaced "
             f"(landing.timing.max_calls_paper = {int(tm.max_calls_paper) if tm.has('max_calls_paper') else 0}), with its medians "
             "and comparisons on those calls.")
    nr = n_replays(tm)
    reps = ("" if nr < 2 else
            f" The compiled calls of {', '.join(replayed_methods(tm))} were replayed {nr} times, each replay a "
            "separate process run alone on the machine (the between-replay spread is what the timing claims "
            "are judged on). The other variants were replayed once, in a job that runs beside others (calls of "
            "milliseconds).")
    cs = clock_share(tm)
    clock = ("" if cs.share_pct_max is None else
             f" Each call is timed as the mean of back-to-back repetitions (a doubling count, "
             f"{cs.reps_min} to {cs.reps_max}) until the clock's own cost "
             f"({cs.clock_ns:.0f} ns a bracket, measured) is below 5 % of the bracket: "
             f"{cs.share_pct_median:.2f} % median, {cs.share_pct_max:.2f} % at most.")
    load = ""
    n_cpu = int(tm.n_cpu) if tm.has("n_cpu") else 0
    if tm.has("replay_load_avg"):
        la = np.asarray(tm.replay_load_avg, float)
        load = (" The machine's 1-minute load average was " + ", ".join(f"{a:.1f}-{b:.1f}" for a, b in la)
                + f" over the replays ({n_cpu} cores)")
        if tm.has("extra_load_avg"):
            load += " and {:.1f}-{:.1f} over the other variants' job".format(*np.asarray(tm.extra_load_avg, float))
        load += (". Other processes sharing the cores lengthen microsecond calls, mostly their shared part, "
                 "and narrow their differences.")
    elif tm.has("load_avg"):
        load = (" The machine's 1-minute load average was {:.1f} at the start and {:.1f} at the end of the "
                "replay ({} cores): other processes sharing the cores lengthen microsecond calls and "
                "narrow their differences, so timing readings compare between builds at a like load."
                .format(*np.asarray(tm.load_avg, float)[:2], n_cpu))
    # short sentences (issue 55 item 4): what is replayed, how, the paper's path, the clock and the check
    return (f"Planning times by replay: {subset}, replayed one call at a time through every method's planning "
            f"call. The calls come from the Monte Carlo of {srcs}. They are interleaved across methods in one "
            f"process (order rotated per call), with the same states for every method.{paper} Clock: "
            f"{CLOCK_WORDS} (thread_time_ns); replayed picks equal to the recorded ones "
            f"in {int(np.sum(tm.checked)) - mis} of {int(np.sum(tm.checked))} own calls." + reps + clock + load)


def summary_frame(tm: "Replay"):
    """One row per timed variant: method, path, evaluation path, calls timed on
    it (:func:`timed`, every replay's), median and 5-95 % quantiles of the :data:`CLOCK` time
    (us) and median evaluations over those calls; the method's own-call check
    (checked, mismatch) on its main row."""
    import pandas as pd

    methods = [str(m) for m in tm.methods]
    ok = timed(tm)
    rows = []
    for j, (m, p, e) in enumerate(zip(tm.variant_method, tm.variant_path, tm.variant_eval_path)):
        c = np.asarray(cell_times_ns(tm, CLOCK))[ok[:, j], j] / 1e3
        row = {"method": str(m), "path": str(p), "eval_path": str(e), "calls": int(len(c))}
        q = np.quantile(c, [0.05, 0.5, 0.95]) if len(c) else [math.nan] * 3
        row.update({f"{CLOCK}_median_us": float(q[1]), f"{CLOCK}_p05_us": float(q[0]),
                    f"{CLOCK}_p95_us": float(q[2])})
        row["median_evals"] = median_evals(tm, str(m), str(p))
        if str(p) == "main":
            i = methods.index(str(m))
            row["checked"], row["mismatch"] = int(tm.checked[i]), int(tm.mismatch[i])
        rows.append(row)
    return pd.DataFrame(rows)
