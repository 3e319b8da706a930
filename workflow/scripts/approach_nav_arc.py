"""The navigation error after compensation against arc length (A-C7's would_take) and with the
tz bias on and off (opnav.approach.navfloor): tz's effect under the paper as written (the
``literal`` variant: paper A's claim, A-C12), the arc lengths under the configured nav-floor
variant."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.approach import navfloor
from opnav.approach.setup import Setup
from opnav.approach.summaries import AS_WRITTEN
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_nav_arc", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    nf = setup.nav_floor
    out = {"nav_floor_by_arc": navfloor.nav_floor_by_arc(setup, nf.variant, nf.scheme, nf.arcs_s, log=log),
           "tz_nav_effect": navfloor.tz_nav_effect(setup, AS_WRITTEN)}
    for r in out["nav_floor_by_arc"].rows:
        log.info("arc %g s: after %.3g km (last %.3g), true theta %.3g km (last %.3g)", r.arc_s, r.nav_err_km_rule,
                 r.nav_err_km_last, r.true_theta_km_rule, r.true_theta_km_last)
    log.info("tz on %.5g km, off %.5g km", out["tz_nav_effect"].nav_err_km_tz_on, out["tz_nav_effect"].nav_err_km_tz_off)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], out)
