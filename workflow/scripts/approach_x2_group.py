"""A-X2: augmented EKF and batch ML on one Table-1 case group under one variant (one Snakemake job)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach import alternatives as alt
from opnav.approach import scenario as sc
from opnav.approach.pipeline import cases_in
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_x2_group", argv=sys.argv[1:], variant="roll", group="size")

with script_context(snakemake) as log:
    w = snakemake.wildcards
    setup = Setup.from_config(snakemake.params.approach)
    geo = sc.build_geometry(setup, w.variant)
    res = alt.run_group_alternatives(setup, w.variant, w.group, log=log, geo=geo)
    em_times = {}
    headline = [c for c in cases_in(setup, w.group) if c.case_index == 1]
    if headline:  # EM-EKF timed on the same machine and job, headline case, all seeds
        em_times = alt.time_em(setup, w.variant, headline[0], range(setup.n_seeds), geo)
        log.info("EM-EKF run time per seed: %s", em_times)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], {"variant": w.variant, "group": w.group, "results": res, "em_times": em_times})
