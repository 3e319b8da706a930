"""Pick agreement of the planner with an older commit's, on the same planning inputs (issue 31).

Two steps, one script:

    # 1. record: fly descents with the OLD code (a git worktree of the old commit) and store every
    #    planning call's inputs and pick
    PYTHONPATH=/tmp/old/src python benchmarks/pick_agreement.py record --out calls.npz [--runs 4]
    # 2. compare: replay the stored inputs through THIS tree's planner
    PYTHONPATH=src python benchmarks/pick_agreement.py compare calls.npz

``compare`` prints, per method and scenario, the calls, the calls near a tie and the agreement of
the picks away from ties. A call is near a tie when its deciding scores leave no clear winner: for a
nearest-landmark pick the two detected landmarks nearest to the new optimum's ground point differ
in distance by at most ``--tie`` (relative) plus twice the distance the optimum's ground point
moved between the two codes (the old optimum's ground point from its recorded beta); for an edge
pick the two best scores are within ``--tie`` (relative). Every other call counts.
Last line: ``pick agreement away from ties: X %``.
"""
import argparse
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

METHODS = "depth,svd,gdop,cond,logdet,mineig,svd_w"


def record(a) -> None:
    from opnav.core.config import load_config
    from opnav.landing.montecarlo import run_chunk
    from opnav.landing.setup import Setup

    scns = Setup.from_config(load_config()["landing"]).scenarios_by_name()
    out = {}
    for name, cfg in scns.items():
        for m in a.methods.split(","):
            d = run_chunk(cfg, m, range(a.runs), pick_ratio=False)
            for k, v in d.arrays().items():
                if k.startswith("plan_"):
                    out[f"{name}|{m}|{k}"] = np.asarray(v)
            print(name, m, len(d.plan_index), "calls", flush=True)
    np.savez_compressed(a.out, **out)


def compare(a) -> None:
    from opnav.core.config import load_config
    from opnav.landing.planning import geometry as K
    from opnav.landing import planner as pl
    from opnav.landing.descent import build_scenario
    from opnav.landing.setup import Setup

    z = np.load(a.calls)
    keys = sorted({tuple(k.split("|")[:2]) for k in z.files})
    scns = Setup.from_config(load_config()["landing"]).scenarios_by_name()
    tot_far = tot_agree = tot_all = tot_all_agree = 0
    for name, m in keys:
        scn = build_scenario(scns[name])
        cam, field_, tr = scn.camera, scn.field, scn.truth
        xy = field_.xyz[:, :2]

        def g(k):
            return z[f"{name}|{m}|{k}"]

        n = len(g("plan_index"))
        far = agree = ties = edge_diff = all_agree = 0
        for i in range(n):
            k = int(g("plan_step")[i])
            r_t, R_t = tr.r[k], tr.R_LtoB[k]
            det = np.flatnonzero(cam.in_view((field_.xyz - r_t) @ R_t.T, scn.planner.margin_px))
            ex = int(g("plan_exclude")[i])
            st = pl.PlanState(g("plan_r")[i], g("plan_v")[i], g("plan_a")[i], g("plan_R")[i],
                              g("plan_P")[i])
            res, q = pl.plan_one(m, st, cam, field_, scn.planner, ex, det)
            cand = det[det != ex]
            old = int(g("plan_index")[i])
            edge_diff += bool(g("plan_edge")[i]) != res.edge
            if res.edge:                         # edge rule: the two best scores
                v = np.sort(pl.candidate_scores(m, st, cam, field_, scn.planner, q, cand))
                v = v[np.isfinite(v)]
                tie = v.size > 1 and v[1] - v[0] <= a.tie * abs(v[0])
            elif cand.size > 1 and np.isfinite(res.beta):   # nearest: the two nearest landmarks,
                d = np.sort(np.hypot(*(xy[cand] - res.ground[:2]).T))  # with the optimum's move
                hit, *p_old = K.ground_point(float(g("plan_beta")[i]), q)
                shift = float(np.hypot(*(np.array(p_old[:2]) - res.ground[:2]))) if hit else np.inf
                tie = d[1] - d[0] <= a.tie * d[0] + 2 * shift
            else:
                tie = False
            ties += bool(tie)
            all_agree += res.index == old
            if not tie:
                far += 1
                agree += res.index == old
        tot_far += far
        tot_agree += agree
        tot_all += n
        tot_all_agree += all_agree
        print(f"{name:10s} {m:7s} calls {n:5d}  near a tie {ties:4d}  edge flag differs {edge_diff:3d}  "
              f"agree away from ties {agree}/{far} ({100.0 * agree / max(far, 1):.2f} %)", flush=True)
    print(f"all calls, ties included: {tot_all_agree} of {tot_all} picks agree "
          f"({100.0 * tot_all_agree / max(tot_all, 1):.2f} %)")
    print(f"pick agreement away from ties: {100.0 * tot_agree / max(tot_far, 1):.2f} % "
          f"({tot_agree} of {tot_far} calls)")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("--out", required=True)
    r.add_argument("--runs", type=int, default=4)
    r.add_argument("--methods", default=METHODS)
    c = sub.add_parser("compare")
    c.add_argument("calls")
    c.add_argument("--tie", type=float, default=1e-6)
    a = ap.parse_args()
    record(a) if a.cmd == "record" else compare(a)
