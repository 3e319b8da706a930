"""The bearing update of the landing filter (paper B eq. 11-18): compiled kernels.

The stacked unit bearings of the known landmark and of the unknown one (``measurement.line_of_sight``
and ``measurement.blocks``, their one home) give the residual (eq. 12) and the Jacobian blocks
(eq. 15-18) of :func:`_linearise`; :func:`_update` is the iterated EKF update with isotropic noise
``sigma_b`` rad per component: gain ``K = P H^T S^-1`` by a Cholesky solve of ``S = H P H^T +
sigma_b^2 I`` (``opnav.landing.linalg``), Joseph form for the covariance, the correction applied by
:func:`_inject` (attitude on the body side, ``R <- Exp(-dtheta) R``). The Python API is
``opnav.landing.ekf`` (``update``, ``linearise``, ``inject``); each kernel takes one run, and a
``*_batch`` kernel loops over the runs of a batch.

Arguments are grouped by meaning in tuples (numba compiles one signature per tuple type): a run's
state ``(r, v, R, p, P)``, its bearings ``(bs, pk, known)``, the observability constraint
``(N, use_N)``, the update's settings ``(sigma_b, iterations)``, the outputs and the scratch.
Units: m, m/s, rad; ``P`` in those units squared.
"""

from __future__ import annotations

import numpy as np

from opnav.core.compiled import kernel, warms
from opnav.core.rotations import exp_so3_into
from opnav.landing.linalg import cho_solve, cholesky_in_place, matmul, symmetrize
from opnav.landing.measurement import blocks, line_of_sight

N_X = 12  # error-state dimension [dr, dv, dtheta, dp] (eq. 5)


@kernel
def _inject(r, v, R, p, dx, r_o, v_o, R_o, p_o, E) -> None:
    """``(r_o, v_o, R_o, p_o)`` <- the state corrected by ``dx`` (12,) (``ekf.inject``;
    ``E`` (3, 3) scratch)."""
    for a in range(3):
        r_o[a] = r[a] + dx[a]
        v_o[a] = v[a] + dx[3 + a]
        p_o[a] = p[a] + dx[9 + a]
    exp_so3_into(-dx[6:9], E)
    for a in range(3):
        for b in range(3):
            R_o[a, b] = E[a, 0] * R[0, b] + E[a, 1] * R[1, b] + E[a, 2] * R[2, b]


@kernel
def _linearise(r, R, p, meas, cons, H, res, work) -> bool:
    """Stacked Jacobian ``H`` (3m, 12) and residual ``res`` (3m,) of the ``m`` bearings at
    ``(r, R, p)`` (eq. 12, 15-18 by the measurement kernels). ``meas = (bs, pk, known)``: the
    unit bearings ``bs`` (m, 3) in {B}, of landmark ``pk[i]`` (m) if ``known[i]``, else of the
    state's ``p``. ``cons = (N, use_N)``: ``H`` projected on the complement of the unobservable
    direction ``N`` (12,) if ``use_N``. ``work = (u, bb, HC)`` scratch (3,), (3,), (3, 3).
    False at zero range or a non-finite position (``H``, ``res`` then meaningless)."""
    bs, pk, known = meas
    N, use_N = cons
    u, bb, HC = work
    m = bs.shape[0]
    for i in range(m):
        inv = line_of_sight(r, pk[i] if known[i] else p, u)
        if not inv > 0.0:
            return False
        blocks(R, u, inv, bb, HC)
        for a in range(3):
            k = 3 * i + a
            res[k] = bs[i, a] - bb[a]                                       # eq. 12
            for c in range(N_X):
                H[k, c] = 0.0
            for c in range(3):
                H[k, c] = -HC[a, c]                                         # eq. 15
                if not known[i]:
                    H[k, 9 + c] = HC[a, c]                                  # eq. 17
        # eq. 16: [b x]
        H[3 * i, 7], H[3 * i, 8] = -bb[2], bb[1]
        H[3 * i + 1, 6], H[3 * i + 1, 8] = bb[2], -bb[0]
        H[3 * i + 2, 6], H[3 * i + 2, 7] = -bb[1], bb[0]
    if use_N:
        nn = 0.0
        for c in range(N_X):
            nn += N[c] * N[c]
        for k in range(3 * m):
            hn = 0.0
            for c in range(N_X):
                hn += H[k, c] * N[c]
            f = hn / nn
            for c in range(N_X):
                H[k, c] -= f * N[c]
    return True


@kernel
def _update(x, meas, cons, setting, out, work) -> float:
    """One run's iterated bearing update (``ekf.update``): ``x = (r, v, R, p, P)`` the prior,
    ``meas``, ``cons`` as :func:`_linearise`, ``setting = (sigma_b, iterations)`` (rad, count),
    ``out = (r_o, v_o, R_o, p_o, P_o)`` the posterior, ``work = (H, K, res, S, col, delta, PHt,
    A, T, E, lin)`` scratch (``lin`` :func:`_linearise`'s). Returns the NIS at the prior (NaN if
    a bearing is undefined: the state is then returned unchanged)."""
    r, v, R, p, P = x
    bs = meas[0]
    sigma_b, iterations = setting
    r_o, v_o, R_o, p_o, P_o = out
    H, K, res, S, col, delta, PHt, A, T, E, lin = work
    m3 = 3 * bs.shape[0]
    for a in range(3):
        r_o[a], v_o[a], p_o[a] = r[a], v[a], p[a]
        for b in range(3):
            R_o[a, b] = R[a, b]
    for c in range(N_X):
        delta[c] = 0.0
    nis = 0.0
    s2 = sigma_b * sigma_b
    for it in range(max(1, iterations)):
        if not _linearise(r_o, R_o, p_o, meas, cons, H, res, lin):
            for a in range(3):
                r_o[a], v_o[a], p_o[a] = r[a], v[a], p[a]
                for b in range(3):
                    R_o[a, b] = R[a, b]
            for a in range(N_X):
                for b in range(N_X):
                    P_o[a, b] = P[a, b]
            return np.nan
        for a in range(N_X):                      # PHt = P H^T
            for k in range(m3):
                s = 0.0
                for c in range(N_X):
                    s += P[a, c] * H[k, c]
                PHt[a, k] = s
        for k in range(m3):                       # S = H P H^T + sigma_b^2 I
            for l in range(k + 1):
                s = 0.0
                for c in range(N_X):
                    s += H[k, c] * PHt[c, l]
                S[k, l] = s + (s2 if k == l else 0.0)
        cholesky_in_place(S, m3)
        for a in range(N_X):                      # K = P H^T S^-1 (row a: S^-1 (P H^T)[a])
            for k in range(m3):
                col[k] = PHt[a, k]
            cho_solve(S, m3, col)
            for k in range(m3):
                K[a, k] = col[k]
        if it == 0:                               # NIS = res^T S^-1 res
            for k in range(m3):
                col[k] = res[k]
            cho_solve(S, m3, col)
            for k in range(m3):
                nis += res[k] * col[k]
        for k in range(m3):                       # y = res + H delta
            s = res[k]
            for c in range(N_X):
                s += H[k, c] * delta[c]
            col[k] = s
        change = 0.0
        for a in range(N_X):                      # delta_new = K y
            s = 0.0
            for k in range(m3):
                s += K[a, k] * col[k]
            change = max(change, abs(s - delta[a]))
            delta[a] = s
        _inject(r, v, R, p, delta, r_o, v_o, R_o, p_o, E)
        if change < 1e-9:
            break
    for a in range(N_X):                          # A = I - K H
        for b in range(N_X):
            s = 1.0 if a == b else 0.0
            for k in range(m3):
                s -= K[a, k] * H[k, b]
            A[a, b] = s
    matmul(A, P, T)
    for a in range(N_X):                          # P_o = T A^T + sigma_b^2 K K^T (Joseph)
        for b in range(N_X):
            s = 0.0
            for c in range(N_X):
                s += T[a, c] * A[b, c]
            q = 0.0
            for k in range(m3):
                q += K[a, k] * K[b, k]
            P_o[a, b] = s + s2 * q
    symmetrize(P_o)
    return nis


# ---------------------------------------------------------------- kernels: batches of runs

@kernel
def _update_batch(x, meas, cons, setting, out, nis) -> None:
    """:func:`_update` of every run: ``x``, ``out`` (r, v, R, p, P) of (n, ...) arrays,
    ``meas = (bs (n, m, 3), pk (n, m, 3), known (m,))``, ``cons = (N (n, 12), use_N)``; the NIS
    per run into ``nis`` (n,)."""
    r, v, R, p, P = x
    bs, pk, known = meas
    N, use_N = cons
    r_o, v_o, R_o, p_o, P_o = out
    m3 = 3 * bs.shape[1]
    work = (np.empty((m3, N_X)), np.empty((N_X, m3)), np.empty(m3), np.empty((m3, m3)), np.empty(m3),
            np.empty(N_X), np.empty((N_X, m3)), np.empty((N_X, N_X)), np.empty((N_X, N_X)),
            np.empty((3, 3)), (np.empty(3), np.empty(3), np.empty((3, 3))))
    for k in range(r.shape[0]):
        nis[k] = _update((r[k], v[k], R[k], p[k], P[k]), (bs[k], pk[k], known), (N[k], use_N), setting,
                         (r_o[k], v_o[k], R_o[k], p_o[k], P_o[k]), work)


@kernel
def _linearise_batch(r, R, p, meas, cons, H, res) -> bool:
    """:func:`_linearise` of every run (arrays with a leading run axis); False at the first run
    whose bearing is undefined."""
    bs, pk, known = meas
    N, use_N = cons
    lin = (np.empty(3), np.empty(3), np.empty((3, 3)))
    for k in range(r.shape[0]):
        if not _linearise(r[k], R[k], p[k], (bs[k], pk[k], known), (N[k], use_N), H[k], res[k], lin):
            return False
    return True


@kernel
def _inject_batch(r, v, R, p, dx, r_o, v_o, R_o, p_o) -> None:
    E = np.empty((3, 3))
    for k in range(r.shape[0]):
        _inject(r[k], v[k], R[k], p[k], dx[k], r_o[k], v_o[k], R_o[k], p_o[k], E)


@warms
def _warm() -> None:
    """Each batch kernel once with the argument types ``opnav.landing.ekf``'s API passes (float64
    C-contiguous arrays with a run axis, a bool array ``known``, Python bool, float and int)."""
    st = (np.array([[10.0, 20.0, 3000.0]]), np.ones((1, 3)), np.eye(3)[None].copy(),
          np.array([[50.0, 0.0, 0.0]]), np.eye(N_X)[None].copy())
    bs = np.array([[[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]]])
    meas = (bs, np.zeros((1, 2, 3)), np.array([True, False]))
    cons = (np.ones((1, N_X)), True)
    out = tuple(np.empty_like(a) for a in st)
    _update_batch(st, meas, cons, (1e-3, 3), out, np.empty(1))
    _linearise_batch(st[0], st[2], st[3], meas, cons, np.empty((1, 6, N_X)), np.empty((1, 6)))
    _inject_batch(*st[:4], np.zeros((1, N_X)), *out[:4])
