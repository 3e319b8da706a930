"""``opnav landing``: fly one Mars powered descent and print a JSON summary.

    opnav landing --method depth --seed 0
    opnav landing --method svd --seed 3 --config config/quick.yaml
    opnav landing --scenario site-tilt --method closest

``--scenario NAME`` is a camera scenario of ``landing.scenarios`` (default: the
headline scenario, ``landing.headline_scenario``), flown as its Monte Carlo is.

``--seed N`` is the Monte-Carlo run index ``N`` (random stream
``SeedSequence([landing.mc.base_seed, N])``), so the command reproduces run N
of the Monte Carlo for that method exactly.
"""

from __future__ import annotations


def _run(args, rc) -> int:
    """``rc``: the run's config and its checks (:class:`opnav.core.cliargs.RunConfig`)."""
    from opnav.core.cliargs import print_json
    from opnav.landing.descent import build_scenario, run_descent
    from opnav.landing.montecarlo import summarize_run

    config = rc.load(args)  # defaults + --config overlays + --set keys, validated
    # the planner's registry and the seed's limits are checked as the config's
    # landing.single.method / run_index (opnav.core.checks), naming the flag
    from opnav.core.config import ConfigError
    from opnav.landing.setup import Setup

    checked = rc.with_flags(config, {"landing.single.method": ("--method", args.method),
                                     "landing.single.run_index": ("--seed", args.seed)})
    setup = Setup.from_config(checked["landing"])    # the edge: paper B's config parsed once
    scenarios = setup.scenarios_by_name()
    name = setup.headline() if args.scenario is None else args.scenario
    if name not in scenarios:
        raise ConfigError(f"--scenario {name!r}: not a camera scenario of landing.scenarios "
                          f"({', '.join(scenarios)})")
    scn = build_scenario(scenarios[name])
    run = run_descent(scn, args.method, args.seed)
    from opnav.core.tables import json_ready
    from opnav.landing.timing import replay_own
    from opnav.landing.timing_summary import median_us

    tm = replay_own(scn, run, args.method)       # planning time by replay of the run's calls
    # the edge: the run's summary as JSON keys, with its planning time and what was flown
    s = {**json_ready(summarize_run(run), nan_as_none=False), "median_plan_time_us": median_us(tm, args.method),
         "method": args.method, "seed": args.seed, "scenario": name,
         "final_pos_err_m_xyz": [round(float(x), 4) for x in run.err_r[-1]],
         "final_vel_err_mps_xyz": [round(float(x), 5) for x in run.err_v[-1]],
         "final_rpy_err_deg": [round(float(x), 5) for x in run.err_rpy_deg[-1]]}
    print_json(s, indent=2, sort_keys=True)
    return 0


def register(subparsers) -> None:
    from opnav.core.cliargs import integer

    p = subparsers.add_parser("landing", help="fly one Mars powered descent (paper B)",
                              description=__doc__.split("\n\n")[0])
    p.add_argument("--method", default="depth",
                   help="landmark planner, a name of opnav.landing.planner.available_methods() "
                        "(depth, svd, gdop, cond, ...; default depth)")
    p.add_argument("--seed", type=integer, default=0, help="Monte-Carlo run index (>= 0, default 0)")
    p.add_argument("--scenario", default=None,
                   help="camera scenario (a key of landing.scenarios; default: landing.headline_scenario)")
    p.set_defaults(func=_run)
