"""Gather per-scenario summaries of paper B into one JSON: ``scenarios`` (by
name, with each scenario's camera), ``headline_scenario``, and the headline
scenario's keys also at the top level (the manuscript's default numbers)."""

import json
import sys

from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_json

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_summary_all", argv=sys.argv[1:])

with script_context(snakemake) as log:
    names = list(snakemake.params.scenarios)
    parts = {n: json.loads(open(p).read()) for n, p in zip(names, snakemake.input.parts)}
    head = snakemake.params.headline
    out = dict(parts[head])
    cams = dict(snakemake.params.cameras)
    out["scenarios"] = {n: {**parts[n], "camera": cams.get(n, {})} for n in names}
    out["headline_scenario"] = head
    out["scenario_names_text"] = ", ".join(names)
    write_json(snakemake.output[0], out)
    log.info("%s: scenarios %s, headline %s", snakemake.output[0], names, head)
