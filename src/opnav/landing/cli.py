"""``opnav landing``: fly one Mars powered descent and print a JSON summary.

    opnav landing --method depth --seed 0
    opnav landing --method svd --seed 3 --config config/quick.yaml

``--seed N`` is the Monte-Carlo run index ``N`` (random stream
``SeedSequence([landing.mc.base_seed, N])``), so the command reproduces run N
of the Monte Carlo for that method exactly.
"""

from __future__ import annotations

import json
import math


def _run(args) -> int:
    from opnav.config import load_config
    from opnav.landing.descent import build_scenario, run_descent, summarize_run
    from opnav.landing.planner import available_methods

    cfg = load_config(overlays=[args.config] if args.config else [])["landing"]
    if args.method not in available_methods():
        raise SystemExit(f"opnav landing: unknown --method {args.method!r}; "
                         f"available: {', '.join(available_methods())}")
    if args.seed < 0:
        raise SystemExit("opnav landing: --seed must be >= 0")
    scn = build_scenario(cfg)
    run = run_descent(scn, args.method, args.seed)
    s = summarize_run(run)
    s = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in s.items()}
    s.update(method=args.method, seed=args.seed,
             final_pos_err_m_xyz=[round(float(x), 4) for x in run["err_r"][-1]],
             final_vel_err_mps_xyz=[round(float(x), 5) for x in run["err_v"][-1]],
             final_rpy_err_deg=[round(float(x), 5) for x in run["err_rpy_deg"][-1]])
    print(json.dumps(s, indent=2, sort_keys=True))
    return 0


def register(subparsers) -> None:
    p = subparsers.add_parser("landing", help="fly one Mars powered descent (paper B)",
                              description=__doc__.split("\n\n")[0])
    p.add_argument("--method", default="depth",
                   help="landmark planner: depth, svd, gdop, cond, logdet, mineig (default depth)")
    p.add_argument("--seed", type=int, default=0, help="Monte-Carlo run index (default 0)")
    p.set_defaults(func=_run)
