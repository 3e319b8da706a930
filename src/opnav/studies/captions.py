"""A study's caption, made from its spec (report, manuscript, the rule's ``params``)."""

from __future__ import annotations

import re
from collections.abc import Mapping

from opnav.studies.metrics import METRICS, TIMING_METRICS
from opnav.studies.values import slug

__all__ = ["caption", "slopes_caption"]


def caption(study: Mapping) -> str:
    """The study's caption, from its spec (report and manuscript): at most three sentences
    (what is swept and compared; what is plotted and what the table adds; the study's own
    note, its first sentence) and no config key (the keys are in the study's CSV and spec)."""
    paper = {"approach": "paper A", "landing": "paper B"}[study["paper"]]
    swept = study.get("title") or ", ".join(k.split(".")[-1] for k in study["keys"])
    vals = ("; " if len(study["keys"]) > 1 else ", ").join(
        ", ".join(slug(v) for v in vs.values()) for vs in study["instances"].values())
    fixed = study.get("fixed") or {}
    fixed_text = (" (" + ", ".join(f"{k.split('.')[-1]} = {slug(v)}" for k, v in fixed.items()) + " at every value)"
                  if fixed else "")
    who = ", ".join(study["methods"])
    if study["variants"]:
        who += " under the scenario variants " + ", ".join(study["variants"])
        runs = f"{study['runs']} paired seeds of the headline case per value"
    else:
        runs = f"{study['runs']} paired runs per value and method"
    if study["paper"] == "approach" and study["statistic"] == "sd":
        stat = "RMS about the truth of the estimate errors and the mean of the other metrics"
    else:
        stat = {"mean": "mean over runs with its 95 % confidence interval",
                "sd": "spread (sd over runs)", "rms": "RMS over runs"}[study["statistic"]]
    mets = ", ".join(METRICS[study["paper"]][m][0] for m in study["metrics"])
    note = re.split(r"(?<=[.!?])\s+(?=[A-Z])", " ".join(str(study.get("note") or "").split()))[0]
    return (f"Study '{study['name']}' ({paper}): {swept} at {vals}{fixed_text}, all else as configured; "
            f"compared: {who}, {runs}. Plotted: the {stat} of {mets}"
            + (" beside the 1-sigma Cramer-Rao bound" if study["paper"] == "approach"
               and study["statistic"] != "mean" else "")
            + f"; the CSV table adds n, sd, RMS, median, the 95 % interval and the paired difference against "
            f"{study['methods'][0]}"
            + (f", and the log-log slopes against {swept}" if study.get("slopes") else "")
            + _timing_text(study) + "."
            + (f" {note}" if note else ""))


def slopes_caption(study: Mapping) -> str:
    """The caption of a study's log-log slopes table."""
    return f"{study['id']} {study['name']}: log-log slopes against {study['keys'][0]}."


def _timing_text(study: Mapping) -> str:
    """How the planning-time metrics were measured (empty if the study shows none)."""
    if not set(study["metrics"]) & set(TIMING_METRICS):
        return ""
    n = study.get("timing_calls")
    per_job = min(int(study.get("runs_per_job") or study["runs"]), int(study["runs"]))
    which = ("every recorded planning call" if not n else
             f"at most {n} of a job's recorded planning calls (jobs of {per_job} runs), evenly spaced, "
             f"so a run's median rests on about {max(n // per_job, 1)} calls")
    return "; planning times by replay, apart from the filter's work, of " + which
