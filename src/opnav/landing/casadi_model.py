"""Two-landmark bearing measurement model of paper B, written once in CasADi.

Description
-----------
Paper B (Li et al., J. Deep Space Explor. 2023, 10(2)) measures unit bearing
vectors to landmarks in the body frame {B} (eq. 11-12),

    b_i = C(q) (r_pi - r) / || C(q) (r_pi - r) ||,

and linearises them about the estimate (eq. 13) with the Jacobian blocks of
eq. 14-18 (H_r = -H_C, H_theta = [b x], H_p = H_C,
H_C = C (|r_i|^2 I - r_i r_i^T) / |r_i|^3, r_i = r_pi - r).  For landmark
selection (sec. 2.2) the paper uses one known landmark at the {L} origin
(n_s = 1) and one unknown landmark in the state (n_p = 1), so the stacked
measurement is a 6-vector and the Jacobian H is 6 x 12 with respect to the
error state [dr (3), dv (3), dtheta (3), dp_cand (3)] (eq. 5).

This module writes the measurement *once* symbolically (CasADi SX), takes H
with ``casadi.jacobian`` at dtheta = 0 and compiles it to ``casadi.Function``
objects:

* :func:`bearing_function` -- z(r, v, dtheta, p_known, p_cand, R_LtoB), 6-vector;
* :func:`jacobian_function` -- H(r, v, p_known, p_cand, R_LtoB), 6 x 12, dtheta = 0;
* :func:`jacobian_map` -- ``Function.map(N)`` of the latter over N candidates.

It is the *cross-check* of the one numpy home of eq. 12-18,
:mod:`opnav.landing.measurement` (``selection_jacobian``), which the tests
prove equal to these Functions (tests/test_landing_metrics.py).

Conventions
-----------
* Frames: {L} landing frame (m), {B} body frame; ``R_LtoB`` maps {L} vectors
  into {B} (paper's C(q)).
* Attitude error (paper eq. 5): dq = q (x) q_hat^-1, dq ~ [dtheta/2, 1]
  (JPL / passive quaternion), so the true rotation is
  ``R_true = C(dq) R_hat`` with ``C(dq) = I - [dtheta x] + O(dtheta^2)``:
  the error is a rotation of the *body* frame, expressed in {B}.  This gives
  paper eq. 16, H_theta = H_C [r_i x] C^T = [b_i x].  For finite dtheta we
  use the Cayley map ``C(dq) = cay(-dtheta/2)``, an exact rotation that agrees
  with exp(-[dtheta x]) to second order and has no branch at dtheta = 0 (only
  the derivative at dtheta = 0 enters H).
* v enters no measurement; it is kept so the columns follow the 12-state layout.
* Units: positions m, H position/landmark columns 1/m, attitude columns 1/rad
  (dimensionless), bearings dimensionless.

The H baselines' reference path (``planning.reference.h_metric_reference``) evaluates
H through :func:`jacobian_casadi_batch` (``Function.map``, serial: the per-candidate call
and the threaded map cost more, ``benchmarks/bench_metrics.py``; docs/performance.md);
the compiled planner uses the closed forms of ``planning.hmetrics``.
"""

from __future__ import annotations

from functools import lru_cache

import casadi as ca
import numpy as np

# the 12-state column layout [r, v, dtheta, p_cand] and the 6 rows: one definition
from opnav.landing.measurement import N_MEAS, N_STATE, SL_P, SL_R, SL_THETA, SL_V  # noqa: E402,F401


def _cayley(a):
    """Rotation matrix of the Cayley map: ((1-|a|^2) I + 2 a a^T + 2 [a x]) / (1 + |a|^2)."""
    n2 = ca.dot(a, a)
    return ((1 - n2) * ca.SX.eye(3) + 2 * (a @ a.T) + 2 * ca.skew(a)) / (1 + n2)


@lru_cache(maxsize=None)
def _symbols():
    r = ca.SX.sym("r_L", 3)
    v = ca.SX.sym("v_L", 3)
    dth = ca.SX.sym("dtheta", 3)
    pk = ca.SX.sym("p_known_L", 3)
    pc = ca.SX.sym("p_cand_L", 3)
    R = ca.SX.sym("R_LtoB", 3, 3)
    R_true = _cayley(-dth / 2) @ R  # C(dq) C(q_hat), C(dq) = I - [dtheta x] + ...

    def unit_bearing(p):
        w = R_true @ (p - r)
        return w / ca.norm_2(w)

    z = ca.vertcat(unit_bearing(pk), unit_bearing(pc))
    x = ca.vertcat(r, v, dth, pc)
    H = ca.jacobian(z, x)
    H0 = ca.substitute(H, dth, ca.SX.zeros(3))
    return r, v, dth, pk, pc, R, z, H0


@lru_cache(maxsize=None)
def bearing_function() -> ca.Function:
    """z = [b_known; b_cand] (6,) in {B} (paper eq. 11-12), inputs
    (r_L, v_L, dtheta, p_known_L, p_cand_L, R_LtoB)."""
    r, v, dth, pk, pc, R, z, _ = _symbols()
    return ca.Function(
        "bearings",
        [r, v, dth, pk, pc, R],
        [z],
        ["r_L", "v_L", "dtheta", "p_known_L", "p_cand_L", "R_LtoB"],
        ["z"],
    )


@lru_cache(maxsize=None)
def jacobian_function() -> ca.Function:
    """H (6 x 12) = dz/d[r, v, dtheta, p_cand] at dtheta = 0 (paper eq. 14-18),
    inputs (r_L, v_L, p_known_L, p_cand_L, R_LtoB)."""
    r, v, _, pk, pc, R, _, H0 = _symbols()
    return ca.Function(
        "H",
        [r, v, pk, pc, R],
        [H0],
        ["r_L", "v_L", "p_known_L", "p_cand_L", "R_LtoB"],
        ["H"],
    )


@lru_cache(maxsize=None)
def jacobian_map(n: int, parallelization: str = "serial") -> ca.Function:
    """``jacobian_function().map(n, parallelization)``: p_cand_L given as 3 x n,
    other inputs broadcast; output 6 x (12 n), horizontally stacked."""
    return jacobian_function().map(n, parallelization)


def jacobian_casadi(r_L, v_L, p_known_L, p_cand_L, R_LtoB) -> np.ndarray:
    """One candidate through the compiled Function: (6, 12) ndarray."""
    return jacobian_function()(r_L, v_L, p_known_L, p_cand_L, R_LtoB).full()


def jacobian_casadi_batch(r_L, v_L, p_known_L, cand_L, R_LtoB, parallelization="serial") -> np.ndarray:
    """n candidates (n, 3) through ``Function.map``: (n, 6, 12) ndarray."""
    cand_L = np.atleast_2d(np.asarray(cand_L, dtype=float))
    n = cand_L.shape[0]
    out = jacobian_map(n, parallelization)(r_L, v_L, p_known_L, cand_L.T, R_LtoB).full()
    return out.reshape(N_MEAS, n, N_STATE).transpose(1, 0, 2)
