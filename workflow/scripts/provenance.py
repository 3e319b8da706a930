"""results/provenance.{csv,md,json} and results/paper/provenance.tex: the
Python, package versions and git commit of this run (opnav.core.provenance)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from datetime import datetime, timezone

import pandas as pd

from opnav.core import provenance
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_json, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("provenance", argv=sys.argv[1:])

with script_context(snakemake) as log:
    info = dict(snakemake.params.info)
    # when this build ran (the job reruns with every new commit): README's findings name the build
    # they quote by commit and date (python -m opnav.report.readme --from ...)
    info["built_utc"] = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    df = pd.DataFrame(provenance.rows(info), columns=["item", "version"])
    write_table(df, [snakemake.output.csv, snakemake.output.md],
                caption="Software environment and commit of this run")
    write_json(snakemake.output.json, info)
    atomic_write_text(snakemake.output.tex, provenance.latex_macros(info))
    log.info("provenance: %s", info)
