"""Paper B's planner, compiled: each equation once, as plain loops under ``@kernel``.

Description
-----------
One planning call (SPEC B.3, paper B sec. 2.2), each step a kernel
(``opnav.core.compiled.kernel``: numba, on-disk cache, no fastmath), each equation
once: the plane holding the velocity (:func:`plane`), eq. 19 (:func:`baseline`),
eq. 21-22 (:func:`error_radius`), eq. 23-25 (:func:`depth_error`), eq. 26
(:func:`plane_depth`, :func:`ground_point`), the closed form of the paper's H
baselines (:func:`h_metric`), the candidate validity rule (:func:`candidate_ok`),
the visible interval (:func:`visible_interval`), the golden-section search
(:func:`golden_section`), the nearest detected landmark (:func:`nearest`), the
tie rule (:func:`best_index`) and the call itself (:func:`plan_core`, compiled by :func:`plan_run` for every
:data:`KINDS`; run by the interpreter with a Python objective through
:func:`interpreted` for the paper's definitions, ``opnav.landing.planner``;
B-X1's information baselines logdet, mineig, svd_w, gdop_w, cond_w and logdet_nav: one
family, :func:`planned` of the candidate's planned rows, :func:`planned_rows`).

Per-run constants ``q`` (float64 (NQ,)): 0-2 C (m), 3-5 v_hat, 6-8 w_hat, 9 |CD|
(m), 10 gamma (rad), 11 objective kind (:data:`KINDS`), 12 b (m), 13 r_e (m),
14-16 unit line of sight to the known landmark u, 17 x = 1/rho_known (1/m),
18-20 boresight in {L}, 21 known landmark usable (1/0), 22 min_range (m),
23 boresight check on (1/0); the planned-information kinds' slots from :data:`Q_R` on.

Objectives are minimised: the depth error (m), or minus a metric (larger is
better for every metric). ``+inf`` where the line of sight misses the ground,
at beta = 0 (no parallax) and for invalid candidates; never NaN.
"""
from __future__ import annotations

import math
import types

import numpy as np

from opnav.core.compiled import kernel, warms
from opnav.landing import ekf
from opnav.landing import measurement as me

#: objective kinds compiled here (``q[11]``); the whitened ones are their H base + 5
KINDS = dict(depth=0, svd=1, gdop=2, cond=3, logdet=4, mineig=5, svd_w=6, gdop_w=7, cond_w=8, logdet_nav=9,
             svd_lapack=10)
DEPTH, SVD, GDOP, COND, LOGDET, MINEIG, SVD_W, GDOP_W, COND_W, LOGDET_NAV, SVD_LAPACK = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10
#: structural rank of the paper's 6 x 12 H (two per unit bearing)
H_RANK = 4
#: q slots of the planned-information kinds (:func:`nav_constants`): R_LtoB (3 x 3, row-major),
#: the prior P (12 x 12), velocity (m/s), acceleration (m/s^2), gravity (m/s^2), known landmark
#: (m), sigma_f (rad), depth_sigma_frac, n_obs, dt (s), oc; from Q_TAB on, per planned image k
#: (NT slots each): Phi_k's navigation block (9 x 9) and the site's whitened rows mapped to the
#: planning instant (2 x 12), candidate-independent, filled once per call
Q_R, Q_SIG = 24, 33
Q_NV, Q_NA, Q_NG, Q_NK, Q_NSF, Q_NDF, Q_NOBS, Q_NDT, Q_NOC, NQ = 177, 180, 183, 186, 189, 190, 191, 192, 193, 194
Q_TAB, NT = NQ, 81 + 24
#: structural rank of the planned whitened rows A P0^1/2 (m = 4 n_obs - 2 rows): min(m, 11),
#: yaw being unobservable (the 12th singular value measured ~3e-17 of the first, OC or not)
PLANNED_RANK = 11
#: the tie rule's relative tolerance: candidates whose score lies within
#: TIE_RTOL * |best| of the best score are tied, and the lowest landmark index
#: wins. Paths agree to round-off (~1e-12 relative: closed form vs LAPACK's
#: smallest structural singular value), far inside it; mineig's plateau
#: (spread ~2e-15, ``opnav.landing.metrics``) is one tie
TIE_RTOL = 1e-9
#: status codes of :func:`plane` / :func:`plan_core` (``depth_error.REASONS`` says them)
OK, ZERO_VELOCITY, NOT_ABOVE, NOT_DESCENDING, ZERO_BASELINE, NO_INTERVAL = 0, 1, 2, 3, 4, 5
INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


@kernel
def plane(r, v, q) -> int:
    """Fill q[0:11] with the plane of (r, v) (m, m/s); returns a status (0: ok). A
    vertical velocity takes the plane through {L} +x."""
    sp = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if not (sp >= 1e-9) or not math.isfinite(sp):
        return ZERO_VELOCITY
    if not (r[2] > 0):
        return NOT_ABOVE
    a0, a1, a2 = v[0] / sp, v[1] / sp, v[2] / sp
    if a2 >= 0:
        return NOT_DESCENDING
    nh = math.hypot(a0, a1)
    h0, h1 = (1.0, 0.0) if nh < 1e-9 else (a0 / nh, a1 / nh)
    hv = h0 * a0 + h1 * a1
    w0, w1, w2 = h0 - hv * a0, h1 - hv * a1, -hv * a2
    nw = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    for i in range(3):
        q[i] = r[i]
    q[3], q[4], q[5] = a0, a1, a2
    q[6], q[7], q[8] = w0 / nw, w1 / nw, w2 / nw
    q[9] = r[2] / -a2
    q[10] = math.asin(min(1.0, -a2))
    return OK


@kernel
def max_eig_sym3(A) -> float:
    """Largest eigenvalue of the symmetric part of a 3 x 3 matrix (trigonometric closed form)."""
    a00, a11, a22 = A[0, 0], A[1, 1], A[2, 2]
    a01, a02, a12 = 0.5 * (A[0, 1] + A[1, 0]), 0.5 * (A[0, 2] + A[2, 0]), 0.5 * (A[1, 2] + A[2, 1])
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    m = (a00 + a11 + a22) / 3.0
    if p1 <= 1e-30 * max(1.0, m * m):
        return max(a00, a11, a22)
    d0, d1, d2 = a00 - m, a11 - m, a22 - m
    p = math.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1) / 6.0)
    b00, b11, b22, b01, b02, b12 = d0 / p, d1 / p, d2 / p, a01 / p, a02 / p, a12 / p
    det = (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02)
           + b02 * (b01 * b12 - b11 * b02))
    return m + 2.0 * p * math.cos(math.acos(max(-1.0, min(1.0, det / 2.0))) / 3.0)


@kernel
def baseline(v, a, t_s) -> float:
    """Eq. 19: estimated baseline |v t_s + a t_s^2 / 2| (m) from velocity v (m/s),
    acceleration a (m/s^2) over t_s (s)."""
    h = 0.5 * t_s * t_s
    b2 = 0.0
    for i in range(3):
        x = v[i] * t_s + a[i] * h
        b2 += x * x
    return math.sqrt(b2)


@kernel
def error_radius(P_vv, t_s, n_sigma) -> float:
    """Eq. 21-22: error-ball radius r_e = eps_v t_s (m), eps_v = n_sigma sqrt(max eig
    P_vv) (m/s) of the (symmetrised) velocity covariance P_vv (3 x 3, m^2/s^2)."""
    return n_sigma * math.sqrt(max(max_eig_sym3(P_vv), 0.0)) * t_s


@kernel
def plane_depth(beta, q) -> float:
    """Range (m) to the ground along the line of sight at signed beta (rad) in the
    plane q, law of sines ``|CD| sin(alpha) / sin(alpha + |beta|)``; +inf where it
    misses the ground or beta = 0."""
    g = q[10]
    alpha = math.pi - g if beta > 0 else g
    s = math.sin(alpha + abs(beta))
    if beta == 0.0 or alpha + abs(beta) >= math.pi or s <= 0.0:
        return math.inf
    return q[9] * math.sin(alpha) / s


@kernel
def ground_point(beta, q):
    """Eq. 26: (hit, x, y, z) (m) of the line of sight at signed beta (rad) in the plane q."""
    d = plane_depth(beta, q)
    if d == math.inf:
        return False, 0.0, 0.0, 0.0
    cb, sb = math.cos(beta), math.sin(beta)
    return (True, q[0] + d * (cb * q[3] + sb * q[6]), q[1] + d * (cb * q[4] + sb * q[7]),
            q[2] + d * (cb * q[5] + sb * q[8]))


@kernel
def depth_error(d, cb, sb, b, r_e) -> float:
    """Eq. 23-25: depth estimation error (m) of a landmark at range d (m) seen at
    beta from the velocity (cos, sin), baseline b (m) > 0, error radius r_e (m);
    +inf without parallax (sin beta <= 0 or |r^(k+s)| = 0)."""
    rks = math.sqrt(max(b * b + d * d - 2.0 * b * d * cb, 0.0))   # eq. 25
    if sb <= 0.0 or rks <= 0.0:
        return math.inf
    return (2.0 * r_e / b) * rks / sb                              # eq. 23-24


@kernel
def h_metric(kind, x, y, c, s2) -> float:
    """The paper's H baselines in closed form (larger is better, :func:`sv_metric`
    of the four structural singular values of H), from
    x = 1/rho_known, y = 1/rho_cand (1/m), c = u . w, s2 = |u x w|^2 (squared
    singular values m +- sqrt(e^2 + k_j^2) and D_j / (m + ...), written without
    cancellation; ``opnav.landing.metrics`` derives them)."""
    a = 1.0 + x * x
    dd = 1.0 + 2.0 * y * y
    m = 0.5 * (a + dd)
    e2 = (0.5 * (a - dd)) ** 2
    xy = x * y
    k1, k2 = c + xy, 1.0 + c * xy
    base = (x - c * y) ** 2 + (2.0 - c * c) * y * y
    D1 = s2 + base + xy * xy
    D2 = base + (1.0 + s2) * xy * xy
    lp1 = m + math.sqrt(e2 + k1 * k1)
    lp2 = m + math.sqrt(e2 + k2 * k2)
    return sv_metric(kind, max(lp1, lp2), min(lp1, lp2), max(D1 / lp1, D2 / lp2), min(D1 / lp1, D2 / lp2))


@kernel
def h_lapack(r, R_LtoB, p_known, d0, d1, d2) -> float:
    """svd (larger is better) of the candidate at offset d = p - r (m) by a real SVD: the 6 x 12
    H of eq. 14-18 built in place (``measurement.line_of_sight``, ``measurement.blocks``: rows of
    the known landmark [-H_C, 0, [b x], 0], of the candidate [-H_C, 0, [b x], H_C]) and numba's
    LAPACK SVD of it, its fourth (smallest structural) singular value. The same metric as
    :func:`h_metric`'s closed form to round-off; timed beside it (B-F7: which "SVD" is timed)."""
    H = np.zeros((6, 12))
    u, b, HC, p = np.empty(3), np.empty(3), np.empty((3, 3)), np.empty(3)
    p[0], p[1], p[2] = r[0] + d0, r[1] + d1, r[2] + d2
    for s in range(2):
        inv = me.line_of_sight(r, p_known if s == 0 else p, u)
        me.blocks(R_LtoB, u, inv, b, HC)
        o = 3 * s
        for i in range(3):
            for j in range(3):
                H[o + i, j] = -HC[i, j]
                if s == 1:
                    H[o + i, 9 + j] = HC[i, j]
        H[o + 0, 7], H[o + 0, 8] = -b[2], b[1]              # [b x]
        H[o + 1, 6], H[o + 1, 8] = b[2], -b[0]
        H[o + 2, 6], H[o + 2, 7] = -b[1], b[0]
    sv = np.linalg.svd(H)[1]
    return sv[H_RANK - 1]


@kernel
def sv_metric(base, l1, l2, l3, l4) -> float:
    """svd = s4, cond = s4 / s1, gdop = 1 / sum s_i^-2 (``base`` SVD, COND, GDOP) from the
    squares l_i = s_i^2 of the four structural singular values (l1 the largest, l4
    the smallest); 0 if l4 <= 0."""
    if not l4 > 0.0:
        return 0.0
    return (math.sqrt(l4) if base == SVD else math.sqrt(l4 / l1) if base == COND
            else 1.0 / (1.0 / l1 + 1.0 / l2 + 1.0 / l3 + 1.0 / l4))


@kernel
def nav_constants(r, v, a, R_LtoB, P, c, q) -> None:
    """Fill the planned-information slots of q (after :func:`metric_constants`) once per call: the
    planning state (position r m, velocity v m/s, acceleration a m/s^2, attitude R_LtoB, prior P
    12 x 12), the filter's model from :func:`plan_run`'s ``c`` (sigma_f = noise scale x sigma_b
    rad, the new landmark's depth 1-sigma / depth, n_obs observations dt = t_s s apart, oc,
    gravity m/s^2), and the candidate-independent part of every planned image k (``Q_TAB``): the
    transition Phi_k to the predicted pose r + v t + a t^2 / 2 (``ekf._transition``, eq. 6-10,
    attitude held; its landmark block is the identity, so its 9 x 9 navigation block is kept) and
    the site's rows whitened by 1/sigma_f (``measurement.tangent_rows``, landmark columns zero)
    times Phi_k. q must hold ``Q_TAB + NT n_obs`` slots (:func:`work_size`)."""
    for i in range(9):
        q[Q_R + i] = R_LtoB[i // 3, i % 3]
    for i in range(12):
        for j in range(12):
            q[Q_SIG + 12 * i + j] = P[i, j]
    for i in range(3):
        q[Q_NV + i], q[Q_NA + i], q[Q_NG + i], q[Q_NK + i] = v[i], a[i], c[C_NAV + 4 + i], c[C_PKNOWN + i]
    q[Q_NSF], q[Q_NDF], q[Q_NOBS] = c[C_NAV] * c[C_SIGMA], c[C_NAV + 1], c[C_NAV + 2]
    q[Q_NDT], q[Q_NOC] = c[C_TS], c[C_NAV + 3]
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
                q[base + 9 * i + j] = Phi[i, j]
        me.tangent_rows(R_LtoB, dk, 1.0 / q[Q_NSF], G)
        for b in range(2):
            for j in range(12):
                x = 0.0
                if j < 9:
                    for i in range(9):
                        x += G[b, i] * Phi[i, j]
                q[base + 81 + 12 * b + j] = x


def work_size(n_obs: int) -> int:
    """Length of :func:`plan_run`'s ``work`` for ``n_obs`` planned observations: q (``Q_TAB +
    NT n_obs``), then out (9)."""
    return Q_TAB + NT * int(n_obs) + 9


@kernel
def cholesky_shifted(Q, n, mu, C) -> bool:
    """C[:n, :n] <- the lower Cholesky factor of Q[:n, :n] - mu I (lower triangle of Q read); False
    if that is not positive definite (exact arithmetic: lambda_min <= mu; in floating point within a
    backward error of ~n eps max Q_ii)."""
    for j in range(n):
        p = Q[j, j] - mu
        for k in range(j):
            p -= C[j, k] * C[j, k]
        if not p > 0.0:
            return False
        C[j, j] = math.sqrt(p)
        for i in range(j + 1, n):
            v = Q[i, j]
            for k in range(j):
                v -= C[i, k] * C[j, k]
            C[i, j] = v / C[j, j]
    return True


@kernel
def logdet_spd(A, n, C) -> float:
    """log det A[:n, :n] (symmetric) as ``metrics.chol_logdet`` defines it: 2 sum log diag of the
    Cholesky factor of the Jacobi-equilibrated D^-1/2 A D^-1/2 + j I, plus sum log D; j from n eps,
    x 1e3 while the Cholesky fails, up to 1e-8; -inf if it still fails or a diagonal entry is not
    positive (C: (n, n) scratch, receives the factor)."""
    ld = 0.0
    for i in range(n):
        for j in range(n):
            if not math.isfinite(A[i, j]):
                return -math.inf
        if not A[i, i] > 0.0:
            return -math.inf
        ld += math.log(A[i, i])
    S = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            S[i, j] = A[i, j] / math.sqrt(A[i, i] * A[j, j])
    jit = n * 2.0 ** -52
    while jit <= 1e-8:
        if cholesky_shifted(S, n, -jit, C):
            for i in range(n):
                ld += 2.0 * math.log(C[i, i])
            return ld
        jit *= 1e3
    return -math.inf


@kernel
def planned_rows(d0, d1, d2, rho, q, p0, P0, A) -> int:
    """The candidate at offset d = p - r (m), |d| = rho, as ``planned_info.planned_rows`` specifies
    it: P0 (12 x 12) its initialisation from its noise-free bearing (``ekf._init``, p0 its ground
    point), A (m x 12, m = 4 n_obs - 2) the whitened tangent-plane rows of the n_obs planned images
    at the planning instant: the site's from the call's table (:func:`nav_constants`), the
    candidate's (``measurement.tangent_rows`` at the predicted pose, times Phi_k), projected off the
    unit yaw direction (``ekf._nullspace``) if oc. Returns m, or -1 where the candidate cannot be
    initialised (its line of sight misses the ground)."""
    R, P, r = q[Q_R:Q_R + 9].reshape((3, 3)), q[Q_SIG:Q_SIG + 144].reshape((12, 12)), q[0:3]
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
                A[row + a, c] = q[base + 81 + 12 * a + c]
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
                    x += G[a, j] * q[base + 9 * j + c]
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
    ``planned_info.planned_metric`` defines each: with S = I + A P0 A^T = L L^T and X = L^-1 A P0,
    the posterior Sigma = P0 - X^T X (Woodbury) and the information Lambda = P0^-1 + A^T A:
    logdet_nav = -log det Sigma[:9, :9] (nats), logdet = log det Lambda = log det S - log det P0,
    mineig = lambda_min(Lambda) = 1 / lambda_max(Sigma) (LAPACK eigvalsh of Sigma), and svd_w,
    gdop_w, cond_w (:func:`sv_metric`'s rules) of the PLANNED_RANK-or-fewer structural singular
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


@kernel
def in_view(d0, d1, d2, rho, q) -> bool:
    """A landmark at offset d = p - C (m), |d| = rho, beyond min_range and in front
    of the camera (d . boresight > 0, when the check is on)."""
    if not rho > q[22]:
        return False
    return q[23] == 0.0 or d0 * q[18] + d1 * q[19] + d2 * q[20] > 0.0


@kernel
def candidate_ok(d0, d1, d2, rho, q) -> bool:
    """The candidate validity rule: the candidate in view and the known landmark usable."""
    return q[21] != 0.0 and in_view(d0, d1, d2, rho, q)


@kernel
def metric_constants(r, R_LtoB, bs_B, has_bs, p_known, min_range, q) -> None:
    """Fill q[14:24] (the H baselines' and validity rule's constants) for lander r,
    attitude R_LtoB, boresight bs_B in {B} (unit; ``has_bs`` 0 disables the check),
    known landmark p_known (m)."""
    for i in range(3):
        q[i] = r[i]
        q[18 + i] = R_LtoB[0, i] * bs_B[0] + R_LtoB[1, i] * bs_B[1] + R_LtoB[2, i] * bs_B[2]
    q[22], q[23] = min_range, has_bs
    d0, d1, d2 = p_known[0] - r[0], p_known[1] - r[1], p_known[2] - r[2]
    rho = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    q[21] = 1.0 if in_view(d0, d1, d2, rho, q) else 0.0
    inv = 1.0 / rho if rho > 0 else math.nan
    q[14], q[15], q[16], q[17] = d0 * inv, d1 * inv, d2 * inv, 1.0 / rho if rho > 0 else math.inf


@kernel
def valid_points(q, pts):
    """:func:`candidate_ok` of each row of ``pts`` (n, 3) (m)."""
    ok = np.empty(pts.shape[0], np.bool_)
    for j in range(pts.shape[0]):
        d0, d1, d2 = pts[j, 0] - q[0], pts[j, 1] - q[1], pts[j, 2] - q[2]
        ok[j] = candidate_ok(d0, d1, d2, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2), q)
    return ok


@kernel
def score_point(p0, p1, p2, q) -> float:
    """The objective (minimised) of kind q[11] at the ground point p (m): the depth
    error (eq. 23-25 at the landmark's range) or minus an H baseline or B-X1
    metric (+inf where the candidate is invalid)."""
    d0, d1, d2 = p0 - q[0], p1 - q[1], p2 - q[2]
    rho = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    kind = int(q[11])
    if kind == DEPTH:
        if not (p2 < q[2]) or rho <= 0.0:
            return math.inf
        c0, c1, c2 = d1 * q[5] - d2 * q[4], d2 * q[3] - d0 * q[5], d0 * q[4] - d1 * q[3]  # d x v_hat
        return depth_error(rho, (d0 * q[3] + d1 * q[4] + d2 * q[5]) / rho,
                           math.sqrt(c0 * c0 + c1 * c1 + c2 * c2) / rho, q[12], q[13])
    if LOGDET <= kind <= LOGDET_NAV:
        return planned(kind, d0, d1, d2, rho, q) if in_view(d0, d1, d2, rho, q) else math.inf
    if not candidate_ok(d0, d1, d2, rho, q):
        return math.inf
    if kind == SVD_LAPACK:
        return -h_lapack(q[0:3], q[Q_R:Q_R + 9].reshape((3, 3)), q[Q_NK:Q_NK + 3], d0, d1, d2)
    y = 1.0 / rho
    w0, w1, w2 = d0 * y, d1 * y, d2 * y
    u0, u1, u2 = q[14], q[15], q[16]
    c0, c1, c2 = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
    return -h_metric(kind, q[17], y, u0 * w0 + u1 * w1 + u2 * w2, c0 * c0 + c1 * c1 + c2 * c2)


@kernel
def objective(beta, q) -> float:
    """The objective at signed beta: the depth error (eq. 23-25 at the law-of-sines
    range), or :func:`score_point` at the ground point (eq. 26)."""
    if int(q[11]) == DEPTH:
        d = plane_depth(beta, q)
        return depth_error(d, math.cos(beta), abs(math.sin(beta)), q[12], q[13]) if d < math.inf else d
    hit, x, y, z = ground_point(beta, q)
    return score_point(x, y, z, q) if hit else math.inf


@kernel
def score_points(q, xyz, cand):
    """:func:`score_point` of landmarks ``xyz[cand]`` (minimised)."""
    out = np.empty(cand.size)
    for j in range(cand.size):
        i = cand[j]
        out[j] = score_point(xyz[i, 0], xyz[i, 1], xyz[i, 2], q)
    return out


@kernel
def evaluations(q, betas, xyz, cand, reps) -> float:
    """The objective at ``betas`` and :func:`score_points` of ``cand``, ``reps``
    times (the evaluations of a planning call, timed alone by ``timing.call_overhead``)."""
    s = 0.0
    for _ in range(reps):
        for b in betas:
            s += objective(b, q)
        if cand.size:
            s += score_points(q, xyz, cand).sum()
    return s


@kernel
def visible_interval(q, M, k):
    """(n, lo0, hi0, lo1, hi1): the n <= 2 sub-intervals of signed beta (rad) whose
    lines of sight u = cos(beta) v_hat + sin(beta) w_hat meet the ground inside the
    field of view, negative side first. M = R_BtoC R_LtoB; k = (half width -
    margin) / focal (tangent of the half field of view). Each side plane of the
    square field of view (k z -+ x > 0, k z -+ y > 0 in camera axes) and the ground
    (u_z < 0) is an open half circle of directions centred at phi_i; they meet
    unless the centres do not fit in an arc shorter than pi, in
    (max phi_i - pi/2, min phi_i + pi/2)."""
    if k <= 0:
        return 0, 0.0, 0.0, 0.0, 0.0
    A = np.empty(3)
    C = np.empty(3)
    for i in range(3):
        A[i] = M[i, 0] * q[3] + M[i, 1] * q[4] + M[i, 2] * q[5]
        C[i] = M[i, 0] * q[6] + M[i, 1] * q[7] + M[i, 2] * q[8]
    pi = math.pi
    phis = np.sort(np.array([math.atan2(k * C[2] - C[0], k * A[2] - A[0]),
                             math.atan2(k * C[2] + C[0], k * A[2] + A[0]),
                             math.atan2(k * C[2] - C[1], k * A[2] - A[1]),
                             math.atan2(k * C[2] + C[1], k * A[2] + A[1]), q[10] - pi / 2]))
    j, gap = 4, phis[0] + 2 * pi - phis[4]          # the widest gap, first on ties
    for i in (3, 2, 1, 0):
        if phis[i + 1] - phis[i] >= gap:
            j, gap = i, phis[i + 1] - phis[i]
    if gap <= pi:
        return 0, 0.0, 0.0, 0.0, 0.0
    b0 = (phis[j] + 2 * pi if j < 4 else phis[4]) - pi / 2
    b1 = phis[(j + 1) % 5] + pi / 2
    shift = 2 * pi * round((q[10] - pi / 2 - 0.5 * (b0 + b1)) / (2 * pi))  # into (-(pi - g), g)
    b0, b1 = b0 + shift + 1e-12, b1 + shift - 1e-12
    n, lo0, hi0, lo1, hi1 = 0, 0.0, 0.0, 0.0, 0.0
    eps = 1e-9                                       # split at beta = 0 (no parallax)
    if b0 < 0 and min(b1, -eps) > b0:
        n, lo0, hi0 = 1, b0, min(b1, -eps)
    if b1 > 0 and b1 > max(b0, eps):
        if n == 0:
            lo0, hi0 = max(b0, eps), b1
        else:
            lo1, hi1 = max(b0, eps), b1
        n += 1
    return n, lo0, hi0, lo1, hi1


@kernel
def golden_section(q, a, b, tol):
    """Minimise ``objective(x, q)`` on [a, b] by golden-section search: the bracket shrinks
    by 1/phi per evaluation until shorter than ``tol``; returns (x, f(x), n_evals),
    x the best evaluated point (+inf values allowed)."""
    c = b - INVPHI * (b - a)
    d = a + INVPHI * (b - a)
    fc, fd = objective(c, q), objective(d, q)
    n = 2
    while (b - a) > tol:
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - INVPHI * (b - a)
            fc = objective(c, q)
        else:
            a, c, fc = c, d, fd
            d = a + INVPHI * (b - a)
            fd = objective(d, q)
        n += 1
    return (c, fc, n) if fc <= fd else (d, fd, n)


@kernel
def best_index(scores) -> int:
    """The tie rule: the first position whose score (minimised) lies within
    :data:`TIE_RTOL` relative of the smallest finite score; -1 if none is finite."""
    best = math.inf
    for s in scores:
        if s < best:
            best = s
    if not math.isfinite(best):
        return -1
    lim = _tie_limit(best)
    for j in range(scores.size):
        if scores[j] <= lim:
            return j
    return -1


@kernel
def _tie_limit(best) -> float:
    """The tie rule's bound: scores <= best + TIE_RTOL |best| are tied with ``best``."""
    return best + TIE_RTOL * abs(best) if math.isfinite(best) else best


@kernel
def _nearest_of(x, y, xyz, det, exclude) -> int:
    best, bd = -1, math.inf
    for i in det:
        if i == exclude:
            continue
        dx, dy = xyz[i, 0] - x, xyz[i, 1] - y
        d2 = dx * dx + dy * dy
        if d2 < bd or (d2 == bd and i < best):
            best, bd = i, d2
    return best


@kernel
def nearest(x, y, xyz, det, exclude, grid, cells) -> int:
    """The landmark of ``det`` (sorted field indices) nearest to (x, y) (m) by
    dx^2 + dy^2, less ``exclude``, exact ties to the smaller index; -1 if none.
    Rings of grid buckets (:func:`field_grid`) outward until no unsearched bucket
    can hold a nearer one (the bound shrunk by 1e-9 buckets); a query whose
    rings hold more than 64 undetected landmarks scores ``det`` directly."""
    if det.size <= 32:
        return _nearest_of(x, y, xyz, det, exclude)
    x0, y0, h = grid[0], grid[1], grid[2]
    nx, ny = int(grid[3]), int(grid[4])
    cx = min(max(int((x - x0) // h), 0), nx - 1)
    cy = min(max(int((y - y0) // h), 0), ny - 1)
    nc = nx * ny
    best, bd, rejected, r = -1, math.inf, 0, 0
    while True:
        for xx in range(max(cx - r, 0), min(cx + r, nx - 1) + 1):
            for yy in range(max(cy - r, 0), min(cy + r, ny - 1) + 1):
                if max(abs(xx - cx), abs(yy - cy)) != r:
                    continue
                c = xx * ny + yy
                for t in range(cells[c], cells[c + 1]):
                    i = cells[nc + 1 + t]
                    dx, dy = xyz[i, 0] - x, xyz[i, 1] - y
                    d2 = dx * dx + dy * dy
                    if d2 < bd or (d2 == bd and i < best):
                        k = np.searchsorted(det, i)              # detected?
                        if i != exclude and k < det.size and det[k] == i:
                            best, bd = i, d2
                        else:
                            rejected += 1
        lb = math.inf                                  # distance to the unsearched buckets
        if cx + r < nx - 1:
            lb = x0 + (cx + r + 1) * h - x
        if cx - r > 0:
            lb = min(lb, x - (x0 + (cx - r) * h))
        if cy + r < ny - 1:
            lb = min(lb, y0 + (cy + r + 1) * h - y)
        if cy - r > 0:
            lb = min(lb, y - (y0 + (cy - r) * h))
        if lb == math.inf:
            return best
        lb -= 1e-9 * h
        if best >= 0 and lb > 0 and bd < lb * lb:
            return best
        if rejected > 64:
            return _nearest_of(x, y, xyz, det, exclude)
        r += 1


def interpreted(fn, **names):
    """The kernel ``fn``'s Python source run by the interpreter, with the module
    names ``names`` (kernels it calls) replaced: the same steps with a Python
    objective (the planner's paper path: the paper's definitions, ``planned_info``)."""
    py = fn.py_func
    return types.FunctionType(py.__code__, {**py.__globals__, **names}, py.__name__, py.__defaults__,
                              py.__closure__)


def field_grid(xyz: np.ndarray, per_cell: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The bucket grid of :func:`nearest` over the (x, y) of ``xyz`` (n, 3), m:
    ``grid`` = [x0, y0, h, nx, ny] and ``cells`` = [start (nx ny + 1), items]
    (int64, the field indices of bucket c at items[start[c]:start[c+1]], increasing)."""
    xy = np.asarray(xyz, float)[:, :2]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float(max(hi - lo))
    m = max(1, int(math.ceil(math.sqrt(len(xy) / per_cell))))
    h = span / m if span > 0 else 1.0
    nx, ny = int((hi[0] - lo[0]) // h) + 1, int((hi[1] - lo[1]) // h) + 1
    c = (np.minimum(((xy[:, 0] - lo[0]) // h).astype(np.int64), nx - 1) * ny
         + np.minimum(((xy[:, 1] - lo[1]) // h).astype(np.int64), ny - 1))
    order = np.argsort(c, kind="stable")
    start = np.searchsorted(c[order], np.arange(nx * ny + 1))
    return (np.array([lo[0], lo[1], h, nx, ny], float),
            np.concatenate([start, order]).astype(np.int64))


@kernel
def edge_pick(q, xyz, det, exclude):
    """The edge rule: (pick, landmarks scored): every detected landmark less
    ``exclude`` scored (:func:`score_points`), the tie rule picks (-1: none finite)."""
    cand = det[det != exclude]
    j = best_index(score_points(q, xyz, cand))
    return (cand[j] if j >= 0 else -1), cand.size


@kernel
def plan_core(q, M, kfov, tol, xyz, det, exclude, grid, cells, out) -> None:
    """One planning call in the plane ``q`` (status q-independent: the caller
    checked the plane): visible sub-intervals, a golden-section ``search`` of ``f``
    on each (the first wins exact ties), the optimum's ground point (eq. 26);
    edge rule: an optimum within ``tol`` of an end of its sub-interval lies
    outside the image, so every detected landmark is scored (``scores_of(q, xyz,
    cand)``) and the tie rule (:func:`best_index`) picks; else, or if none scores
    finite, the detected landmark nearest to the ground point (:func:`nearest`).
    ``out`` = [pick, beta, f, n_evals, edge, x, y, z, status]; no interval: status
    NO_INTERVAL, the rest left to the caller's fallback."""
    n, lo0, hi0, lo1, hi1 = visible_interval(q, M, kfov)
    out[8] = OK if n else NO_INTERVAL
    if n == 0:
        out[3] = 0
        return
    bx, bf, ba, bb, ne = math.nan, math.inf, 0.0, 0.0, 0
    for s in range(n):
        a, b = (lo0, hi0) if s == 0 else (lo1, hi1)
        x, fx, k = golden_section(q, a, b, tol)
        ne += k
        if fx < bf or math.isnan(bx):
            bx, bf, ba, bb = x, fx, a, b
    hit, gx, gy, gz = ground_point(bx, q)
    edge = min(bx - ba, bb - bx) <= tol
    pick, m = edge_pick(q, xyz, det, exclude) if edge else (-1, 0)
    ne += m
    if pick < 0:
        pick = nearest(gx, gy, xyz, det, exclude, grid, cells)
    out[0], out[1], out[2], out[3], out[4] = pick, bx, bf, ne, 1.0 if edge else 0.0
    out[5], out[6], out[7] = gx, gy, gz


#: layout of :func:`plan_run`'s constant vector ``c`` (per field, config and camera)
C_TS, C_NSIGMA, C_TOL, C_KFOV, C_MINRANGE, C_RBC, C_BS, C_PKNOWN, C_GRID = 0, 1, 2, 3, 4, 5, 14, 17, 20
C_SIGMA, C_NAV, NC = 25, 26, 33


@kernel
def plan_run(kind, r, v, a, R_LtoB, P, c, xyz, det, exclude, cells, work) -> None:
    """:func:`plan_core` of a compiled objective ``kind`` (:data:`KINDS`) for one
    run: ``c`` (:data:`NC`) = [t_s (s), n_sigma_v, tol (rad), tan half-FOV less
    margin, min_range (m), R_BtoC (9, row-major), boresight_B (3), known landmark
    (3, m), grid (5, :func:`field_grid`), sigma_b (rad: the B-X1 kinds' bearing
    noise sigma_b: the filter's is its noise scale times it), the planned-information kinds'
    filter model (:func:`nav_constants`: noise scale, depth_sigma_frac, obs_per_landmark, oc
    (1/0), gravity (3, m/s^2))]; ``P`` the prior (12 x 12); ``work`` (:func:`work_size` of
    obs_per_landmark) receives q and out (its last 9 slots; status last, 0 ok)."""
    q, out = work[:work.size - 9], work[work.size - 9:]
    st = plane(r, v, q)
    q[11] = kind
    if st == OK and kind == DEPTH:
        q[12], q[13] = baseline(v, a, c[C_TS]), error_radius(P[3:6, 3:6], c[C_TS], c[C_NSIGMA])
        if not q[12] > 0:
            st = ZERO_BASELINE
    elif st == OK:
        metric_constants(r, R_LtoB, c[C_BS:C_BS + 3], 1.0, c[C_PKNOWN:C_PKNOWN + 3], c[C_MINRANGE], q)
        if LOGDET <= kind <= LOGDET_NAV:
            nav_constants(r, v, a, R_LtoB, P, c, q)
        elif kind == SVD_LAPACK:                      # the attitude and site of the H it builds
            for i in range(9):
                q[Q_R + i] = R_LtoB[i // 3, i % 3]
            for i in range(3):
                q[Q_NK + i] = c[C_PKNOWN + i]
    if st != OK:
        out[3], out[8] = 0, st
        return
    M = np.zeros((3, 3))
    for i in range(3):
        for j in range(3):
            for k in range(3):
                M[i, j] += c[C_RBC + 3 * i + k] * R_LtoB[k, j]
    plan_core(q, M, c[C_KFOV], c[C_TOL], xyz, det, exclude, c[C_GRID:C_GRID + 5], cells, out)


@warms
def _warm() -> None:
    from opnav.landing.landmarks import make_field

    xyz = make_field(500.0, 200, 1).xyz
    grid, cells = field_grid(xyz)
    det = np.arange(0, 200, 2, dtype=np.int64)
    P = np.eye(12)
    R = np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]])
    c = np.zeros(NC)
    c[:5], c[C_RBC:C_RBC + 9:4], c[C_BS + 2], c[C_GRID:C_SIGMA], c[C_SIGMA], c[C_NAV:NC] = (
        (1.0, 3.0, 1e-3, 0.5, 1e-6), 1.0, -1.0, grid, 1e-3, (5.0, 0.1, 3.0, 1.0, 0.0, 0.0, -3.711))
    work = np.zeros(work_size(3))
    for kind in KINDS.values():
        plan_run(kind, np.array([10.0, 0, 1000.0]), np.array([-5.0, 0, -20.0]), np.zeros(3), R, P, c,
                 xyz, det, np.int64(-1), cells, work)
        q = work[:-9]
        score_points(q, xyz, det)
        edge_pick(q, xyz, det, np.int64(-1))
        evaluations(q, np.array([-0.1, 0.1]), xyz, det, 1)
    valid_points(q, xyz)
    sv_metric(SVD, 1.0, 1.0, 1.0, 1.0)
    nearest(0.0, 0.0, xyz, det, np.int64(3), grid, cells)
