"""The planner's kinds, status codes and the slot layouts of its float vectors.

The compiled planning call (:mod:`opnav.landing.planning.search`) passes three float64
vectors between its kernels: the per-call constants ``q`` (the plane, the objective's
constants, the planned-information tables), the per-field constants ``c`` that
:func:`~opnav.landing.planning.search.plan_run` reads, and its result ``out``. Each slot
has one name here, grouped by the kernel that fills it; a block of ``n`` slots is named
by its first. numba folds these module constants into the compiled code, so a name costs
nothing at run time. ``tests/test_landing_planner.py`` checks that no two blocks of a
layout overlap.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

# ------------------------------------------------------------------ objective kinds
#: objective kinds compiled by the planner (``q[Q_KIND]``); a whitened kind is its H base + 5
KINDS = dict(depth=0, svd=1, gdop=2, cond=3, logdet=4, mineig=5, svd_w=6, gdop_w=7, cond_w=8, logdet_nav=9,
             svd_lapack=10)
DEPTH, SVD, GDOP, COND, LOGDET, MINEIG, SVD_W, GDOP_W, COND_W, LOGDET_NAV, SVD_LAPACK = range(11)
#: structural rank of the paper's 6 x 12 H (two per unit bearing)
H_RANK = 4
#: structural rank of the planned whitened rows A P0^1/2 (m = 4 n_obs - 2 rows): min(m, 11),
#: yaw being unobservable (its singular value is round-off, OC or not)
PLANNED_RANK = 11

# ------------------------------------------------------------------ status codes
#: status of :func:`geometry.plane` / the planning call (0: ok)
OK, ZERO_VELOCITY, NOT_ABOVE, NOT_DESCENDING, ZERO_BASELINE, NO_INTERVAL = range(6)
#: why the plane or the planning call refused a geometry, per status code
REASONS = {ZERO_VELOCITY: "depth error: zero velocity, the velocity line is undefined",
           NOT_ABOVE: "depth error: lander not above the ground",
           NOT_DESCENDING: "depth error: velocity does not descend, it never meets the ground",
           ZERO_BASELINE: "depth error: zero baseline (zero velocity)",
           NO_INTERVAL: "no visible interval"}


class DegenerateGeometry(ValueError):
    """The depth-error model does not apply (zero velocity, a velocity that does not
    descend, a lander not above the ground, a zero baseline): the planner falls back to
    its documented choice (``opnav.landing.planner``)."""


# ------------------------------------------------------------------ q: per-call constants
# the plane holding the velocity (geometry.plane): lander C (3, m), unit velocity v_hat (3),
# in-plane unit w_hat toward the horizon (3), |CD| (m), flight-path angle gamma (rad)
Q_C, Q_VHAT, Q_WHAT, Q_CD, Q_GAMMA = 0, 3, 6, 9, 10
#: the objective kind (:data:`KINDS`)
Q_KIND = 11
# the depth error's baseline b (m, eq. 19) and error radius r_e (m, eq. 21-22)
Q_B, Q_RE = 12, 13
# the H baselines and the validity rule (hmetrics.metric_constants): unit line of sight to the
# known landmark u (3), x = 1/rho_known (1/m), boresight in {L} (3), known landmark usable (1/0),
# min_range (m), boresight check on (1/0)
Q_U, Q_XK, Q_BSL, Q_KNOWN_OK, Q_MINRANGE, Q_BS_ON = 14, 17, 18, 21, 22, 23
# the attitude R_LtoB (9, row-major; the planned-information kinds and svd_lapack), the prior
# P (144, row-major), and the planned-information model (information.nav_constants): velocity
# (3, m/s), acceleration (3, m/s^2), gravity (3, m/s^2), known landmark (3, m; svd_lapack too),
# sigma_f (rad), depth_sigma_frac, n_obs, dt (s), oc (1/0)
Q_R, Q_P = 24, 33
Q_NV, Q_NA, Q_NG, Q_NK, Q_NSF, Q_NDF, Q_NOBS, Q_NDT, Q_NOC = 177, 180, 183, 186, 189, 190, 191, 192, 193
#: slots of q before the per-image tables
NQ = 194
#: per planned image k, from Q_TAB + NT k: Phi_k's navigation block (81, row-major), then the
#: site's whitened rows at the planning instant (2 x 12, row-major)
Q_TAB, NT = NQ, 81 + 24
T_PHI, T_SITE = 0, 81
#: (first slot, length) of every q block, for the layout test
Q_BLOCKS = dict(C=(Q_C, 3), VHAT=(Q_VHAT, 3), WHAT=(Q_WHAT, 3), CD=(Q_CD, 1), GAMMA=(Q_GAMMA, 1),
                KIND=(Q_KIND, 1), B=(Q_B, 1), RE=(Q_RE, 1), U=(Q_U, 3), XK=(Q_XK, 1), BSL=(Q_BSL, 3),
                KNOWN_OK=(Q_KNOWN_OK, 1), MINRANGE=(Q_MINRANGE, 1), BS_ON=(Q_BS_ON, 1), R=(Q_R, 9),
                P=(Q_P, 144), NV=(Q_NV, 3), NA=(Q_NA, 3), NG=(Q_NG, 3), NK=(Q_NK, 3), NSF=(Q_NSF, 1),
                NDF=(Q_NDF, 1), NOBS=(Q_NOBS, 1), NDT=(Q_NDT, 1), NOC=(Q_NOC, 1))

# ------------------------------------------------------------------ c: per-field constants
# plan_run's constants (per field, config and camera): t_s (s), n_sigma_v, tol (rad), tan half-FOV
# less margin, min_range (m), R_BtoC (9, row-major), boresight_B (3), known landmark (3, m), the
# landmark grid (5, :data:`G_X0`...), sigma_b (rad), the filter's model: noise scale,
# depth_sigma_frac, obs_per_landmark, oc (1/0), gravity (3, m/s^2)
C_TS, C_NSIGMA, C_TOL, C_KFOV, C_MINRANGE, C_RBC, C_BS, C_PKNOWN, C_GRID = 0, 1, 2, 3, 4, 5, 14, 17, 20
C_SIGMA, C_NOISE, C_DEPTHFRAC, C_NOBS, C_OC, C_G, NC = 25, 26, 27, 28, 29, 30, 33
C_BLOCKS = dict(TS=(C_TS, 1), NSIGMA=(C_NSIGMA, 1), TOL=(C_TOL, 1), KFOV=(C_KFOV, 1),
                MINRANGE=(C_MINRANGE, 1), RBC=(C_RBC, 9), BS=(C_BS, 3), PKNOWN=(C_PKNOWN, 3),
                GRID=(C_GRID, 5), SIGMA=(C_SIGMA, 1), NOISE=(C_NOISE, 1), DEPTHFRAC=(C_DEPTHFRAC, 1),
                NOBS=(C_NOBS, 1), OC=(C_OC, 1), G=(C_G, 3))

# ------------------------------------------------------------------ the landmark grid
#: screens.field_grid's ``grid``: origin x0, y0 (m), bucket side h (m), buckets nx, ny
G_X0, G_Y0, G_H, G_NX, G_NY, NG = 0, 1, 2, 3, 4, 5

# ------------------------------------------------------------------ out: the call's result
#: the picked landmark, beta* (rad), the objective there, evaluations, edge rule (1/0), the
#: optimum's ground point (3, m), status (:data:`OK`...)
O_PICK, O_BETA, O_F, O_NEVAL, O_EDGE, O_XYZ, O_STATUS, NOUT = 0, 1, 2, 3, 4, 5, 8, 9
O_BLOCKS = dict(PICK=(O_PICK, 1), BETA=(O_BETA, 1), F=(O_F, 1), NEVAL=(O_NEVAL, 1), EDGE=(O_EDGE, 1),
                XYZ=(O_XYZ, 3), STATUS=(O_STATUS, 1))


class Estimate(NamedTuple):
    """The filter's estimate a planning call starts from ({L}, SI): position r (3, m),
    velocity v (3, m/s), acceleration a (3, m/s^2), attitude R_LtoB (3 x 3), covariance P
    (12 x 12) of [r, v, dtheta, p]. The order of the tuple a kernel takes as one argument
    (:func:`estimate_arg`)."""

    r: np.ndarray
    v: np.ndarray
    a: np.ndarray
    R_LtoB: np.ndarray
    P: np.ndarray


def estimate_arg(r, v, a, R_LtoB, P) -> tuple:
    """:class:`Estimate` as the kernels take it (``plan_run``'s ``est``): its fields, in its order,
    as a plain tuple. numba types a named-tuple argument on its slow path, a cost every compiled
    planning call would carry into its timed bracket (the timed call includes numba's argument
    dispatch; docs/performance.md 2026-12-04, the planning call's dispatch)."""
    return tuple(Estimate(r, v, a, R_LtoB, P))


def work_size(n_obs: int) -> int:
    """Length of ``plan_run``'s ``work`` for ``n_obs`` planned observations: q (``Q_TAB +
    NT n_obs``), then out (:data:`NOUT`)."""
    return Q_TAB + NT * int(n_obs) + NOUT
