"""Plain EM vs SQUAREM iterations to the maximum-likelihood estimate (headline case, one window), every variant."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach.cases import convergence_study, headline_case
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_convergence", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    cs = setup.convergence_study
    for variant, out in zip(snakemake.params.variants, snakemake.output):
        res = convergence_study(setup, variant, headline_case(setup), range(cs.n_seeds), cs.data_samples,
                                cs.max_maps, cs.tol_arcsec, init_mode=cs.initial_error_mode)
        log.info("%s: theta* mean %s; maps plain %s squarem %s", variant, res.theta_star_arcsec.mean(0),
                 res.plain.maps_to_converge, res.squarem.maps_to_converge)
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        save_pickle(out, res)
