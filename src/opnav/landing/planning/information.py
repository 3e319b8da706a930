"""B-X1's information baselines, compiled: what a candidate landmark would give the filter
(logdet, mineig, svd_w, gdop_w, cond_w, logdet_nav; beyond paper B).

The specification (the candidate's own initialisation, the filter's noise model, the planned
observations mapped to the planning instant, the yaw projection of the OC update) and the
numpy definition it is tested equal to: ``reference.planned_rows`` / ``reference.planned_metric``.
Here, per call, :func:`nav_constants` fills q's planned-information slots and the per-image
tables once; per candidate, :func:`planned_rows` builds P0 and the whitened rows A, and
:func:`planned` reads the metric off them through one Cholesky factor of S = I + A P0 A^T.
"""
from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel
from opnav.landing import ekf
from opnav.landing import measurement as me
from opnav.landing.linalg import cholesky_shifted, logdet_spd
from opnav.landing.planning.layout import (C_DEPTHFRAC, C_G, C_NOBS, C_NOISE, C_OC, C_PKNOWN, C_SIGMA, C_TS,
                                           COND_W, LOGDET, LOGDET_NAV, NT, PLANNED_RANK, Q_C, Q_NA, Q_NDF,
                                           Q_NDT, Q_NG, Q_NK, Q_NOBS, Q_NOC, Q_NSF, Q_NV, Q_P, Q_R, Q_TAB,
                                           SVD_W, T_PHI, T_SITE)


@kernel
def nav_constants(est, c, q) -> None:
    """Fill the planned-information slots of q (after ``hmetrics.metric_constants``) once per call:
    the planning state (``layout.Estimate`` ``est``: position r m, velocity v m/s, acceleration a
    m/s^2, attitude R_LtoB, prior P 12 x 12), the filter's model from ``search.plan_run``'s ``c``
    (``layout.C_SIGMA`` ...: sigma_f = noise scale x sigma_b
    rad, the new landmark's depth 1-sigma / depth, n_obs observations dt = t_s s apart, oc,
    gravity m/s^2), and the candidate-independent part of every planned image k (``Q_TAB``): the
    transition Phi_k to the predicted pose r + v t + a t^2 / 2 (``ekf._transition``, eq. 6-10,
    attitude held; its landmark block is the identity, so its 9 x 9 navigation block is kept) and
    the site's rows whitened by 1/sigma_f (``measurement.tangent_rows``, landmark columns zero)
    times Phi_k. q must hold ``Q_TAB + NT n_obs`` slots (``layout.work_size``)."""
    r, v, a, R_LtoB, P = est
    for i in range(9):
        q[Q_R + i] = R_LtoB[i // 3, i % 3]
    for i in range(12):
        for j in range(12):
            q[Q_P + 12 * i + j] = P[i, j]
    for i in range(3):
        q[Q_NV + i], q[Q_NA + i], q[Q_NG + i], q[Q_NK + i] = v[i], a[i], c[C_G + i], c[C_PKNOWN + i]
    q[Q_NSF], q[Q_NDF], q[Q_NOBS] = c[C_NOISE] * c[C_SIGMA], c[C_DEPTHFRAC], c[C_NOBS]
    q[Q_NDT], q[Q_NOC] = c[C_TS], c[C_OC]
    Phi, G = np.empty((12, 12)), np.empty((2, 12))
    rk, vk, dk, g = np.empty(3), np.empty(3), np.empty(3), q[Q_NG:Q_NG + 3]
    for k in range(int(q[Q_NOBS])):
        t = k * q[Q_NDT]
        for i in range(3):
            rk[i] = r[i] + v[i] * t + 0.5 * a[i] * t * t
            vk[i] = v[i] + a[i] * t
            dk[i] = q[Q_NK + i] - rk[i]
        ekf._transition(r, v, R_LtoB, rk, vk, R_LtoB, t, g, Phi)
        base = Q_TAB + NT * k
        for i in range(9):
            for j in range(9):
                q[base + T_PHI + 9 * i + j] = Phi[i, j]
        me.tangent_rows(R_LtoB, dk, 1.0 / q[Q_NSF], G)
        for b in range(2):
            for j in range(12):
                x = 0.0
                if j < 9:
                    for i in range(9):
                        x += G[b, i] * Phi[i, j]
                q[base + T_SITE + 12 * b + j] = x


@kernel
def planned_rows(d0, d1, d2, rho, q, p0, P0, A) -> int:
    """The candidate at offset d = p - r (m), |d| = rho, as ``reference.planned_rows`` specifies
    it: P0 (12 x 12) its initialisation from its noise-free bearing (``ekf._init``, p0 its ground
    point), A (m x 12, m = 4 n_obs - 2) the whitened tangent-plane rows of the n_obs planned images
    at the planning instant: the site's from the call's table (:func:`nav_constants`), the
    candidate's (``measurement.tangent_rows`` at the predicted pose, times Phi_k), projected off the
    unit yaw direction (``ekf._nullspace``) if oc. Returns m, or -1 where the candidate cannot be
    initialised (its line of sight misses the ground)."""
    R, P, r = q[Q_R:Q_R + 9].reshape((3, 3)), q[Q_P:Q_P + 144].reshape((12, 12)), q[Q_C:Q_C + 3]
    b = np.empty(3)
    for i in range(3):
        b[i] = (R[i, 0] * d0 + R[i, 1] * d1 + R[i, 2] * d2) / rho
    J, JP = np.empty((3, 9)), np.empty((3, 9))
    if not ekf._init(r, R, P, b, q[Q_NDF], q[Q_NSF], p0, P0, J, JP):
        return -1
    n_obs = int(q[Q_NOBS])
    m = 4 * n_obs - 2
    G, dk = np.empty((2, 12)), np.empty(3)
    row = 0
    for k in range(n_obs):
        t = k * q[Q_NDT]
        base = Q_TAB + NT * k
        for a in range(2):                            # the site (its landmark columns zero)
            for c in range(12):
                A[row + a, c] = q[base + T_SITE + 12 * a + c]
        row += 2
        if k == 0:                                    # the first image initialises the candidate
            continue
        for i in range(3):
            dk[i] = p0[i] - (r[i] + q[Q_NV + i] * t + 0.5 * q[Q_NA + i] * t * t)
        me.tangent_rows(R, dk, 1.0 / q[Q_NSF], G)
        for a in range(2):                            # G Phi_k: Phi_k's landmark block is I
            for c in range(9):
                x = 0.0
                for j in range(9):
                    x += G[a, j] * q[base + T_PHI + 9 * j + c]
                A[row + a, c] = x
            for c in range(9, 12):
                A[row + a, c] = G[a, c]
        row += 2
    if q[Q_NOC] != 0.0:                               # A (I - N N^T), N the unit yaw direction
        N = np.empty(12)
        ekf._nullspace(r, q[Q_NV:Q_NV + 3], R, p0, N)
        N /= math.sqrt(np.sum(N * N))
        for a in range(m):
            x = 0.0
            for c in range(12):
                x += A[a, c] * N[c]
            for c in range(12):
                A[a, c] -= x * N[c]
    return m


@kernel
def planned(kind, d0, d1, d2, rho, q) -> float:
    """The planned-information objective (minimised: minus the metric) of kind ``kind`` for the
    candidate at offset d (m), |d| = rho, from :func:`planned_rows` (P0, A), as
    ``reference.planned_metric`` defines each: with S = I + A P0 A^T = L L^T and X = L^-1 A P0,
    the posterior Sigma = P0 - X^T X (Woodbury) and the information Lambda = P0^-1 + A^T A:
    logdet_nav = -log det Sigma[:9, :9] (nats), logdet = log det Lambda = log det S - log det P0,
    mineig = lambda_min(Lambda) = 1 / lambda_max(Sigma) (LAPACK eigvalsh of Sigma), and svd_w,
    gdop_w, cond_w (``hmetrics.sv_metric``'s rules) of the PLANNED_RANK-or-fewer structural singular
    values of the whitened rows A P0^1/2 (LAPACK SVD of A chol(P0): their Gram A P0 A^T squares
    a condition number ~1e4, its eigenvalues agreed with the SVD to only 2e-5). +inf where the
    candidate cannot be initialised."""
    p0, P0 = np.empty(3), np.empty((12, 12))
    n_obs = int(q[Q_NOBS])
    A = np.empty((4 * n_obs - 2, 12))
    m = planned_rows(d0, d1, d2, rho, q, p0, P0, A)
    if m < 0:
        return math.inf
    if kind >= SVD_W and kind <= COND_W:             # singular values of A P0^1/2 (LAPACK SVD)
        sv = np.linalg.svd(A @ np.linalg.cholesky(P0))[1]
        rk = min(m, PLANNED_RANK)
        s1, sr = sv[0], sv[rk - 1]
        if not sr > 0.0:
            return 0.0
        if kind == SVD_W:
            return -sr
        if kind == COND_W:
            return -sr / s1
        x = 0.0
        for i in range(rk):
            x += 1.0 / (sv[i] * sv[i])
        return -1.0 / x
    X, S = np.empty((m, 12)), np.empty((m, m))
    for a in range(m):                                # X <- A P0
        for c in range(12):
            x = 0.0
            for j in range(12):
                x += A[a, j] * P0[j, c]
            X[a, c] = x
    for a in range(m):                                # S = I + A P0 A^T (lower triangle)
        for b_ in range(a + 1):
            x = 1.0 if a == b_ else 0.0
            for j in range(12):
                x += X[a, j] * A[b_, j]
            S[a, b_] = x
    L = np.empty((m, m))
    if not cholesky_shifted(S, m, 0.0, L):
        return math.inf
    if kind == LOGDET:
        ld = 0.0
        for a in range(m):
            ld += 2.0 * math.log(L[a, a])
        return -(ld - logdet_spd(P0, 12, np.empty((12, 12))))
    nc = 9 if kind == LOGDET_NAV else 12
    for c in range(nc):                               # X <- L^-1 A P0
        for a in range(m):
            x = X[a, c]
            for j in range(a):
                x -= L[a, j] * X[j, c]
            X[a, c] = x / L[a, a]
    Sig = np.empty((nc, nc))
    for i in range(nc):
        for j in range(nc):
            x = P0[i, j]
            for a in range(m):
                x -= X[a, i] * X[a, j]
            Sig[i, j] = x
    if kind == LOGDET_NAV:
        return logdet_spd(Sig, 9, np.empty((9, 9)))
    for i in range(12):                               # symmetric to round-off: its lower triangle
        for j in range(i):
            Sig[j, i] = Sig[i, j]
    lmax = np.linalg.eigvalsh(Sig)[11]
    return -1.0 / lmax if lmax > 0.0 else math.inf
