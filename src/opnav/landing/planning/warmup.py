"""The planning kernels' cache warm-up (``opnav.core.compiled.warm``): every kernel of the
package called once, with the argument types the pipeline passes, through the planning call
of every compiled kind."""
from __future__ import annotations

import numpy as np

from opnav.core.compiled import warms
from opnav.landing.planning.hmetrics import sv_metric
from opnav.landing.planning.layout import (C_BS, C_GRID, C_NOISE, C_RBC, C_SIGMA, KINDS, NC, NOUT, SVD,
                                           estimate_arg, work_size)
from opnav.landing.planning.screens import field_grid, nearest, valid_points
from opnav.landing.planning.search import edge_pick, evaluations, plan_run, score_points


@warms
def _warm() -> None:
    from opnav.landing.landmarks import make_field

    xyz = make_field(500.0, 200, 1).xyz
    grid, cells = field_grid(xyz)
    det = np.arange(0, 200, 2, dtype=np.int64)
    est = estimate_arg(np.array([10.0, 0, 1000.0]), np.array([-5.0, 0, -20.0]), np.zeros(3),
                   np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]]), np.eye(12))
    c = np.zeros(NC)
    c[:5], c[C_RBC:C_RBC + 9:4], c[C_BS + 2], c[C_GRID:C_SIGMA], c[C_SIGMA], c[C_NOISE:NC] = (
        (1.0, 3.0, 1e-3, 0.5, 1e-6), 1.0, -1.0, grid, 1e-3, (5.0, 0.1, 3.0, 1.0, 0.0, 0.0, -3.711))
    work = np.zeros(work_size(3))
    for kind in KINDS.values():
        plan_run(kind, est, c, xyz, det, np.int64(-1), cells, work)
        q = work[:-NOUT]
        score_points(q, xyz, det)
        edge_pick(q, xyz, det, np.int64(-1))
        evaluations(q, np.array([-0.1, 0.1]), xyz, det, 1)
    valid_points(q, xyz)
    sv_metric(SVD, 1.0, 1.0, 1.0, 1.0)
    nearest(0.0, 0.0, xyz, det, np.int64(3), grid, cells)
