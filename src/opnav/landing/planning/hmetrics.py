"""The paper's H baselines in closed form (paper B sec. 2.2; SPEC B.3): svd, gdop, cond of the
four structural singular values of the two-landmark bearing Jacobian H (6 x 12, eq. 14-18),
their per-call constants, and the same metric by a real SVD of H (``svd_lapack``, timed beside
the closed form). The derivation and the rank choice: ``opnav.landing.metrics``; the paper's
definition (CasADi H, LAPACK): ``reference.h_metric_reference``. Larger is better.
"""
from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel
from opnav.landing import measurement as me
from opnav.landing.planning.layout import (COND, H_RANK, Q_BS_ON, Q_BSL, Q_C, Q_KNOWN_OK, Q_MINRANGE, Q_U,
                                           Q_XK, SVD)
from opnav.landing.planning.screens import in_view


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
def sv_metric(base, l1, l2, l3, l4) -> float:
    """svd = s4, cond = s4 / s1, gdop = 1 / sum s_i^-2 (``base`` SVD, COND, GDOP) from the
    squares l_i = s_i^2 of the four structural singular values (l1 the largest, l4
    the smallest); 0 if l4 <= 0."""
    if not l4 > 0.0:
        return 0.0
    return (math.sqrt(l4) if base == SVD else math.sqrt(l4 / l1) if base == COND
            else 1.0 / (1.0 / l1 + 1.0 / l2 + 1.0 / l3 + 1.0 / l4))


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
def metric_constants(r, R_LtoB, bs_B, has_bs, p_known, min_range, q) -> None:
    """Fill q's lander position (``Q_C``) and the H baselines' and validity rule's slots
    (``Q_U`` ... ``Q_BS_ON``) for lander r,
    attitude R_LtoB, boresight bs_B in {B} (unit; ``has_bs`` 0 disables the check),
    known landmark p_known (m)."""
    for i in range(3):
        q[Q_C + i] = r[i]
        q[Q_BSL + i] = R_LtoB[0, i] * bs_B[0] + R_LtoB[1, i] * bs_B[1] + R_LtoB[2, i] * bs_B[2]
    q[Q_MINRANGE], q[Q_BS_ON] = min_range, has_bs
    d0, d1, d2 = p_known[0] - r[0], p_known[1] - r[1], p_known[2] - r[2]
    rho = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    q[Q_KNOWN_OK] = 1.0 if in_view(d0, d1, d2, rho, q) else 0.0
    inv = 1.0 / rho if rho > 0 else math.nan
    q[Q_U], q[Q_U + 1], q[Q_U + 2], q[Q_XK] = d0 * inv, d1 * inv, d2 * inv, 1.0 / rho if rho > 0 else math.inf
