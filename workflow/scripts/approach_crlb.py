"""CRLB of (tx, ty, tz) vs data length for every scenario variant (headline case), with Q and Q = 0;
the roll variant's bound against the roll rate (pipeline.roll_rate_study)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path

from opnav.core import published
from opnav.approach import scenario as sc
from opnav.approach import readings
from opnav.approach.cases import headline_case, table1_cases
from opnav.approach.pipeline import bound_curve, mars_attitude_bounds, roll_rate_study
from opnav.approach.setup import Setup
from opnav.core.snakeio import mock_snakemake, save_pickle, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_crlb", argv=sys.argv[1:])

with script_context(snakemake) as log:
    setup = Setup.from_config(snakemake.params.approach)
    case = headline_case(setup)
    curves = {"Q": {}, "Q0": {}}  # with the filter's process noise, and with none (as the truth)
    for v in setup.variants:
        geo = sc.build_geometry(setup, v)
        Rvar = geo.measurement_variance(case.sigma3_px)
        curves["Q"][v] = bound_curve(setup, geo, Rvar, case.truth_arcsec, v)
        curves["Q0"][v] = bound_curve(setup, geo, Rvar, case.truth_arcsec, v, zero_q=True)
        log.info("%s: CRLB at end %s arcsec (Q = 0: %s)", v, curves["Q"][v][-1], curves["Q0"][v][-1])
        # the bound with the Mars images' attitude knowledge of camera.attitude_study_arcsec (issue 54)
        curves.setdefault("mars_attitude", {})[v] = mars_attitude_bounds(
            setup, geo, lambda g: g.measurement_variance(case.sigma3_px), case.truth_arcsec, v)
    if "roll" in setup.variants:  # the roll rows depend on the roll rate: the bound against it
        samples = int(published.paper_a()["headline"]["data_to_converge_samples"])
        target = snakemake.params.target  # A-C1's target (the analysis plan)
        curves["roll_rate"] = roll_rate_study(setup, samples, target)
        log.info("roll rate reaching %g arcsec in %d samples: %s deg/s", target, samples,
                 curves["roll_rate"].rate_to_target_deg_s)
    # two of the paper's statements read against the model (opnav.approach.readings)
    pa = published.paper_a()
    installs = [c.install_deg for c in table1_cases(setup) if c.group == "install"]
    curves["readings"] = {"installation": readings.installation_check(setup, installs, case.truth_arcsec),
                          "sample_time": readings.sample_time_reading(setup, pa["headline"], pa["simulation"])}
    log.info("installation by construction: %s; sample time: %s", curves["readings"]["installation"].by_construction,
             curves["readings"]["sample_time"].bound_after_samples_arcsec)
    Path(snakemake.output[0]).parent.mkdir(parents=True, exist_ok=True)
    save_pickle(snakemake.output[0], curves)
