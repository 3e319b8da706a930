"""The single descent of one camera scenario of paper B (headline numbers) and
B-F5 (depth-error maps: detected landmarks, whole field, in-plane curve)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import json
import sys

from opnav.core import figures
from opnav.report.landing import plots
from opnav.landing.depth_map import depth_map
from opnav.landing.descent import build_scenario, run_descent
from opnav.landing.montecarlo import summarize_run
from opnav.landing.setup import Setup
from opnav.core.snakeio import mock_snakemake, script_context
from opnav.core.tables import json_ready

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("landing_single", argv=sys.argv[1:], bscn="site-tilt")

with script_context(snakemake) as log:
    cfg = Setup.from_config(snakemake.params.landing)    # the edge: paper B's config parsed once
    scn = build_scenario(cfg)
    dm = depth_map(scn, float(cfg.figures.f5_time_s))
    figures.save(plots.fig_depth_error_map(dm), snakemake.output.f5)

    method = cfg.single.method
    idx = int(cfg.single.run_index)
    run = run_descent(scn, method, idx)
    # the file edge: the run's summary and B-F5's numbers as the summary's keys
    s = {**json_ready(summarize_run(run), nan_as_none=False), "method": method, "run_index": idx,
         "f5": {"time_s": dm.time_s, "n_visible": dm.n_visible,
                "best_landmark_dr_m": float(dm.dr_m[dm.best]),
                "golden_beta_deg": dm.opt_beta_deg, "golden_dr_m": float(dm.opt_dr),
                "unconstrained_beta_deg": dm.unconstrained_beta_deg,
                "unconstrained_dr_m": dm.unconstrained_dr,
                "field_best_dr_m": dm.field_best_dr,
                "optimum_inside_image": dm.optimum_inside_image,
                "visible_interval_deg": dm.interval_deg},
         "final_err_pos_m_xyz": [float(x) for x in run.err_r[-1]],
         "final_err_vel_mps_xyz": [float(x) for x in run.err_v[-1]],
         "final_err_rpy_deg": [float(x) for x in run.err_rpy_deg[-1]],
         "init_error": [float(x) for x in run.init_error]}
    with open(snakemake.output.summary, "w") as fh:
        json.dump(s, fh, indent=2, sort_keys=True)
    log.info("single descent: %s", json.dumps(s))
