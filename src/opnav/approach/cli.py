"""``opnav approach``: one EM-EKF misalignment case from flags, JSON summary on stdout.

Example::

    opnav approach --bias 10 20 10 --pixel-sigma 0.1 --seeds 4 --variant roll --method squarem
"""

from __future__ import annotations

import sys

import numpy as np


def register(sub) -> None:
    from opnav.core.cliargs import finite_float, integer

    from .scenario import VARIANTS

    p = sub.add_parser("approach", help="paper A: run one EM-EKF camera-misalignment case",
                       description="Run one Mars-approach misalignment case (paper A) and print a JSON summary.")
    p.add_argument("--bias", type=finite_float, nargs=3, metavar=("TX", "TY", "TZ"), default=None,
                   help="truth misalignment, arcsec (default: config truth_bias_arcsec)")
    p.add_argument("--init", type=finite_float, nargs=3, metavar=("TX", "TY", "TZ"), default=None,
                   help="EM initial value, arcsec (default: config theta_init_arcsec)")
    p.add_argument("--pixel-sigma", type=finite_float, default=None,
                   help="3-sigma centroid error in pixels (radius: x config ratio); default: config")
    p.add_argument("--seed", type=integer, default=0,
                   help="first Monte-Carlo seed index (>= 0; the last seed index at most that of "
                        "landing.single.run_index's maximum, 1e9)")
    p.add_argument("--seeds", type=integer, default=1,
                   help="number of seeds (batched; limit: the schema's approach.n_seeds)")
    p.add_argument("--variant", default="literal", choices=list(VARIANTS))
    p.add_argument("--method", default=None, choices=["plain", "squarem"], help="EM scheme (default: config)")
    for k in ("N0", "N", "M", "L"):
        p.add_argument(f"--{k}", type=integer, default=None, help=f"segment parameter {k} (default: config)")
    p.add_argument("--mode", default=None, choices=["sliding", "growing"], help="segment mode")
    p.set_defaults(func=run)


#: Config key each flag sets; the flag is held to the key's schema limits and checks.
FLAG_KEYS = {"bias": "approach.truth_bias_arcsec", "init": "approach.theta_init_arcsec",
             "seeds": "approach.n_seeds", "method": "approach.em.method",
             "pixel_sigma": "approach.camera.sigma3_px", "mode": "approach.segments.mode",
             **{k: f"approach.segments.{k}" for k in ("N0", "N", "M", "L")}}


def run(args, rc) -> int:
    """``rc``: the run's config and its checks (:class:`opnav.core.cliargs.RunConfig`)."""
    from opnav.core.checks import schema_node
    from opnav.core.cliargs import print_json
    from opnav.core.config import ConfigError
    from opnav.core.planvalues import accuracy_target_arcsec
    from . import scenario as sc
    from .cases import Case, run_case
    from .pipeline import bound_curve, bound_data, segment_bounds
    from opnav.report.approach.text import bound_cause, reading_text  # the edge words its run (report layer)

    from .labels import row_label
    from .setup import Setup

    config = rc.load(args)  # defaults + --config overlays + --set keys, validated
    # seed indices as paper B's run indices: SeedSequence([base_seed, index]), the same bound
    top = schema_node("landing.single.run_index")["maximum"]
    if args.seed < 0:
        raise ConfigError(f"--seed: must be >= 0, got {args.seed}")
    if args.seed + max(args.seeds, 1) - 1 > top:
        raise ConfigError(f"--seed {args.seed}: the seed indices {args.seed}..{args.seed + args.seeds - 1} exceed "
                          f"{top} (the largest seed index, as landing.single.run_index's)")
    px = None
    if args.pixel_sigma is not None:
        r = config["approach"]["camera"]["radius_to_centroid_ratio"]
        px = [args.pixel_sigma, args.pixel_sigma, r * args.pixel_sigma]
    values = {**vars(args), "pixel_sigma": px,
              "bias": list(args.bias) if args.bias else None,
              "init": list(args.init) if args.init else None}
    flags = {key: ("--" + name.replace("_", "-"), values[name]) for name, key in FLAG_KEYS.items()}
    if px is not None:  # errors state the user's value, not the derived radius 3-sigma
        flags[FLAG_KEYS["pixel_sigma"]] = ("--pixel-sigma", px, args.pixel_sigma)
    checked = rc.with_flags(config, flags)["approach"]
    if args.variant == "stars":          # the arc the flags make must hold a star image
        from opnav.core.checks import stars_arc_problems

        bad = stars_arc_problems(checked, "--variant stars would have no image (lower it or lengthen the arc)")
        if bad:
            raise ConfigError(bad[0])
    setup = Setup.from_config(checked)  # the edge: parsed once
    px = setup.camera.sigma3_px
    truth = setup.truth_bias_arcsec
    init = setup.theta_init_arcsec
    case = Case(0, "cli", "cli", truth, init, px, 0.0)
    method = setup.em.method
    geo = sc.build_geometry(setup, args.variant)
    seeds = range(args.seed, args.seed + args.seeds)
    r = run_case(setup, args.variant, case, seeds, geo=geo, method=method)
    Rvar = geo.measurement_variance(px)
    bound = segment_bounds(setup, geo, Rvar, truth, args.variant)[-1]
    bound0 = segment_bounds(setup, geo, Rvar, truth, args.variant, zero_q=True)[-1]
    curve = bound_curve(setup, geo, Rvar, truth, args.variant)
    curve0 = bound_curve(setup, geo, Rvar, truth, args.variant, zero_q=True)
    s = setup.segments
    used = min(s.data_samples, len(curve) - 1)
    th = r.theta_final_arcsec
    st = r.stalled
    tz = "unobservable" if r.tz_unobservable else None
    label, counts = row_label(r.label)
    target = accuracy_target_arcsec()  # the analysis plan's A-C1 target
    cause = bound_cause(sc.START_OF[args.variant], s.mode, s.N)
    rate = r.contraction_per_map
    rate_med = float(np.nanmedian(rate)) if np.isfinite(rate).any() else float("nan")
    out = {
        "variant": args.variant, "method": method, "seeds": list(seeds), "segments": s.as_dict(),
        "pixel_sigma3_px": list(px),
        "truth_arcsec": list(truth),
        # labels from the data (SPEC A.3c): distance to the ML estimate of the data the run used
        "label": label,
        "reading": reading_text(label, counts, len(st), float(max(bound[:2])), target,
                                float(np.mean(r.dist_to_ml_arcsec)), rate_med, cause),
        "estimate_arcsec": {"mean": th.mean(0),
                            "std": th.std(0, ddof=1) if th.shape[0] > 1 else None,
                            "per_seed": th.round(4)},
        # the bound of the data the estimate used: the last window (sliding) or all data from N0 (growing)
        "crlb_arcsec": {"tx": float(bound[0]), "ty": float(bound[1]), "tz": tz or float(bound[2]),
                        "data": bound_data(setup, args.variant).text},
        # the same with Q = 0: the simulated truth carries no process noise
        "crlb_q0_arcsec": {"tx": float(bound0[0]), "ty": float(bound0[1]), "tz": tz or float(bound0[2])},
        "crlb_all_data_arcsec": {"tx": float(curve[used, 0]), "ty": float(curve[used, 1]), "data_samples": int(used),
                                 "data": (f"samples 1..{s.N0 + used} (all data from t0 with the prior)"
                                          if sc.START_OF[args.variant] == "filter" else
                                          f"samples {s.N0 + 1}..{s.N0 + used} (all data after N0)"),
                                 "tz": tz or float(curve[used, 2])},
        "crlb_all_data_q0_arcsec": {"tx": float(curve0[used, 0]), "ty": float(curve0[used, 1]),
                                    "tz": tz or float(curve0[used, 2])},
        "convergence": {"label": [str(v) for v in r.label],
                  "moved_from_start_arcsec": [float(v) for v in r.moved_arcsec],
                  "contraction_per_map": [float(v) for v in r.contraction_per_map],
                  "ml_estimate_same_data_arcsec": r.theta_ml_arcsec[:, :2].round(4).tolist(),
                  "distance_to_ml_arcsec": [float(v) for v in r.dist_to_ml_arcsec],
                  "distance_to_ml_over_bound": [float(v) for v in r.dist_to_ml_over_bound],
                  "rule": (f"converged if within {setup.em.converge_frac_of_bound:g} x the 1-sigma bound of the "
                           f"data used ({bound_data(setup, args.variant).text}; tx and ty each) of that "
                           f"data's ML estimate; else stalled if the contraction per map toward it is >= "
                           f"{setup.em.stall_rate:g}, not converged otherwise")},
        "iterations": {"em_maps": int(r.theta_iter_arcsec.shape[1]),
                       "per_segment": int(r.maps_per_segment), "segments": s.L},
        "data_to_converge_samples": [None if np.isnan(v) else int(v) for v in r.data_to_converge],
        "nav_err_before_km": float(np.mean(r.nav_err_before_km)),
        "nav_err_after_km": float(np.mean(r.nav_err_after_km)),
    }
    if counts["converged"] < st.size:
        print(f"opnav approach: WARNING: EM did not converge in {st.size - counts['converged']} of {st.size} "
              f"seed(s) ({counts['stalled']} stalled): see 'convergence'", file=sys.stderr)
    print_json(out, indent=2)
    return 0
