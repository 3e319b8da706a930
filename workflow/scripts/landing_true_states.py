"""B-F4: the truth trajectory of paper B's descent (camera-independent)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

import numpy as np

from opnav.core import figures
from opnav.report.landing import plots
from opnav.landing.setup import Setup
from opnav.landing.trajectory import euler_rpy_deg, nominal_truth
from opnav.core.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_true_states", argv=sys.argv[1:])

with script_context(snakemake) as log:
    c = Setup.from_config(snakemake.params.landing)    # the edge: paper B's config parsed once
    T = float(c.duration_s)
    t = np.linspace(0.0, T, int(round(T)) * 10 + 1)
    tr = nominal_truth(c, t)
    figures.save(plots.fig_true_states(tr.t, tr.r, tr.v, euler_rpy_deg(tr.R_LtoB)), snakemake.output.f4)
    log.info("B-F4 over %d samples", t.size)
