"""The single descent of paper B (headline numbers) and B-F4/B-F5 (truth, depth-error map)."""

import json


from opnav import figures
from opnav.landing import plots
from opnav.landing.descent import build_scenario, depth_map, run_descent, summarize_run
from opnav.landing.trajectory import euler_rpy_deg
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(output={"summary": "results/landing/single/summary.json",
                                       "f4": ["results/landing/B-F4_true_states.pdf",
                                              "results/landing/B-F4_true_states.png"],
                                       "f5": ["results/landing/B-F5_depth_error_map.pdf",
                                              "results/landing/B-F5_depth_error_map.png"]})
    snakemake.params = type("P", (), {"landing": snakemake.config["landing"]})()

with script_context(snakemake) as log:
    cfg = snakemake.params.landing
    scn = build_scenario(cfg)
    tr = scn.truth
    rpy = euler_rpy_deg(tr.R_LtoB)
    figures.save(plots.fig_true_states(tr.t, tr.r, tr.v, rpy), snakemake.output.f4)

    dm = depth_map(scn, float(cfg["figures"]["f5_time_s"]))
    figures.save(plots.fig_depth_error_map(dm["uv_px"], dm["dr_m"], dm["best"], dm["half_px"],
                                           dm["beta_deg"], dm["curve_dr"], dm["interval_deg"],
                                           dm["opt_beta_deg"], dm["opt_uv_px"]),
                 snakemake.output.f5)

    method = cfg["single"]["method"]
    idx = int(cfg["single"]["run_index"])
    run = run_descent(scn, method, idx)
    s = summarize_run(run)
    s.update(method=method, run_index=idx,
             initial_attitude_deg=[float(x) for x in rpy[0]],
             published_initial_attitude_deg=[float(x) for x in cfg["initial_state"]["att_deg"]],
             f5={"time_s": dm["time_s"], "n_visible": dm["n_visible"],
                 "best_landmark_dr_m": float(dm["dr_m"][dm["best"]]),
                 "golden_beta_deg": dm["opt_beta_deg"], "golden_dr_m": float(dm["opt_dr"]),
                 "visible_interval_deg": dm["interval_deg"]},
             final_err_pos_m_xyz=[float(x) for x in run["err_r"][-1]],
             final_err_vel_mps_xyz=[float(x) for x in run["err_v"][-1]],
             final_err_rpy_deg=[float(x) for x in run["err_rpy_deg"][-1]],
             init_error=[float(x) for x in run["init_error"]])
    with open(snakemake.output.summary, "w") as fh:
        json.dump(s, fh, indent=2, sort_keys=True)
    log.info("single descent: %s", json.dumps(s))
