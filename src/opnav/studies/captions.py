"""A study's caption, made from its spec (report, manuscript, the rule's ``params``)."""

from __future__ import annotations

from collections.abc import Mapping

from opnav.studies.metrics import TIMING_METRICS
from opnav.studies.values import slug

__all__ = ["caption", "slopes_caption"]


def caption(study: Mapping) -> str:
    """The study's caption, from its spec (report and manuscript): at most three sentences of at
    most :data:`opnav.core.wording.MAX_SENTENCE_WORDS` words (what is swept and compared; what
    is plotted, how planning times were measured and what the table adds, while they fit; the
    study's own note, its first sentence) and no config key (the keys are in the study's CSV and
    spec)."""
    from opnav.core import wording

    paper = {"approach": "paper A", "landing": "paper B"}[study["paper"]]
    swept = study.get("title") or ", ".join(k.split(".")[-1] for k in study["keys"])
    vals = ("; " if len(study["keys"]) > 1 else ", ").join(
        ", ".join(slug(v) for v in vs.values()) for vs in study["instances"].values())
    fixed = study.get("fixed") or {}
    fixed_text = (" (" + ", ".join(f"{k.split('.')[-1]} = {slug(v)}" for k, v in fixed.items()) + " at every value)"
                  if fixed else "")
    who = wording.join(study["methods"])
    if study["variants"]:
        who += " under the variants " + wording.join(study["variants"])
        runs = f"{wording.count(study['runs'], 'paired seed')} of the headline case per value"
    else:
        runs = f"{wording.count(study['runs'], 'paired run')} per value and method"
    if study["paper"] == "approach" and study["statistic"] == "sd":
        stat = "the RMS about the truth of the estimate errors and the mean of the other metrics"
    else:
        stat = {"mean": "the mean over runs with its 95 % confidence interval",
                "sd": "the spread (sd over runs)", "rms": "the RMS over runs"}[study["statistic"]]
    limit = wording.MAX_SENTENCE_WORDS
    first = wording.shorten(f"Study '{study['name']}' ({paper}) sweeps {swept} over {vals}{fixed_text}, all else as "
                            f"configured, comparing {who} on {runs}", limit - 1)
    plotted = (f"Plotted, a panel per metric: {stat}"
               + (" beside the 1-sigma Cramer-Rao bound" if study["paper"] == "approach"
                  and study["statistic"] != "mean" else ""))
    for extra in (_timing_text(study), f"the CSV table adds n, sd, RMS, median, the 95 % interval and the paired "
                  f"difference against {study['methods'][0]}"
                  + (", and the log-log slopes" if study.get("slopes") else "")):
        if extra and wording.word_count(f"{plotted}; {extra}") <= limit:
            plotted += f"; {extra}"
    note = wording.sentences(" ".join(str(study.get("note") or "").split()))
    note = wording.shorten(note[0].rstrip("."), limit - 1) + "." if note else ""
    return " ".join(x for x in (first + ".", plotted + ".", note) if x)


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
             f"at most {n} of a job's recorded planning calls (jobs of {per_job} runs), about "
             f"{max(n // per_job, 1)} calls a run")
    return "planning times (the filter's work apart) replay " + which
