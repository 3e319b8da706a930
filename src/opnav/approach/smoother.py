"""The fixed-interval smoother of paper A (eq. 7-9, 24-25), as the pipeline runs it.

Description
    Paper A's RTS backward pass over a :class:`~opnav.approach.ekf.FilterResult`:

        G_{k-1}   = P_{k-1} Phi_{k,k-1}^T P_{k,k-1}^-1                  (eq. 9)
        X_{k-1|N} = X_{k-1} + G_{k-1} (X_{k|N} - Phi X_{k-1})           (eq. 7)
        P_{k-1|N} = P_{k-1} + G_{k-1} (P_{k|N} - P_{k,k-1}) G_{k-1}^T   (eq. 8)

    The lag-one smoothed cross-covariance ``P_{k,k-1|N} = cov(X_k, X_{k-1} | Z)``
    (eq. 18), needed by the A term of the E-step (eq. 22), is returned in the
    gain form ``P_{k|N} G_{k-1}^T``.

    The pipeline computes the same smoothed moments by the Bryson-Frazier recursion
    (:func:`bryson_frazier`, compiled; its E-step needs no lag-one term). The RTS form
    and the Shumway-Stoffer recursion for ``P_{k,k-1|N}`` are kept as the references
    the tests compare with (tests/approach_reference.py).
Units: as the filter (km, km/s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.core.compiled import kernel, warms

from .ekf import FilterResult, Window
from .kalman import carray


@dataclass
class SmootherResult:
    xs: np.ndarray  # (S, n+1, 6) X_{k|N}
    Ps: np.ndarray  # (S, n+1, 6, 6) P_{k|N}
    Plag: np.ndarray  # (S, n+1, 6, 6) P_{k,k-1|N}; index 0 unused
    G: np.ndarray  # (S, n+1, 6, 6) smoother gains G_k; index n unused


@kernel(inline="always")
def bf_moments(x, P, L, lv, c0, xs, Ps, T):
    """Smoothed moments of the components ``c0..c0+c`` at one sample from its filtered ``x, P``
    and the adjoint ``(Lh, lh)`` there: ``xs = x - P lh``, ``Ps = P - P Lh P`` (symmetrised);
    ``T`` (>= c, 6) scratch."""
    c = xs.shape[0]
    for i in range(c):
        acc = 0.0
        for j in range(6):
            acc += P[c0 + i, j] * lv[j]
        xs[i] = x[c0 + i] - acc
        for j in range(6):
            acc = 0.0
            for l in range(6):
                acc += P[c0 + i, l] * L[l, j]
            T[i, j] = acc  # (P Lh) rows of the components
    for i in range(c):
        for m in range(c):
            acc = 0.0
            for j in range(6):
                acc += T[i, j] * P[j, c0 + m]
            Ps[i, m] = P[c0 + i, c0 + m] - acc
    for i in range(c):
        for m in range(i + 1, c):
            v = 0.5 * (Ps[i, m] + Ps[m, i])
            Ps[i, m] = v
            Ps[m, i] = v


@kernel(inline="always")
def bf_back(upd, Phi, adj, work):
    """The adjoint ``adj = (L, lv)`` (Lh, lh) from sample k to k-1, in place, with the filter's
    ``upd = (K, Hr, Sinv, nu)`` of sample k (gain (6, 3), H's position columns (3, 3), S^-1,
    innovation) and ``Phi = Phi_k``: ``Lt = H^T S^-1 H + Ct^T Lh Ct``,
    ``lt = -H^T S^-1 nu + Ct^T lh``, ``Lh <- Phi^T Lt Phi``, ``lh <- Phi^T lt`` with
    ``Ct = I - K H``. ``work = (KH, T, Lt, lt, HS)`` scratch (6, 3), (6, 6), (6, 6), (6,), (3, 3)."""
    K, Hr, Sinv, nu = upd
    L, lv = adj
    KH, T, Lt, lt, HS = work
    # Ct differs from I only in its first 3 columns, by -K H_r (6 x 3)
    for i in range(6):
        for j in range(3):
            KH[i, j] = K[i, 0] * Hr[0, j] + K[i, 1] * Hr[1, j] + K[i, 2] * Hr[2, j]
    for i in range(6):  # T = Lh Ct
        for j in range(3):
            acc = L[i, j]
            for l in range(6):
                acc -= L[i, l] * KH[l, j]
            T[i, j] = acc
        for j in range(3, 6):
            T[i, j] = L[i, j]
    for i in range(6):  # Lt = Ct^T T (symmetric: upper triangle, mirrored), lt = Ct^T lh
        for j in range(i, 6):
            acc = T[i, j]
            if i < 3:
                for l in range(6):
                    acc -= KH[l, i] * T[l, j]
            Lt[i, j] = acc
            Lt[j, i] = acc
        acc = lv[i]
        if i < 3:
            for l in range(6):
                acc -= KH[l, i] * lv[l]
        lt[i] = acc
    for i in range(3):  # H^T S^-1 (3 x 3)
        for a in range(3):
            HS[i, a] = Hr[0, i] * Sinv[0, a] + Hr[1, i] * Sinv[1, a] + Hr[2, i] * Sinv[2, a]
    for i in range(3):  # + H^T S^-1 H, - H^T S^-1 nu
        for j in range(3):
            Lt[i, j] += HS[i, 0] * Hr[0, j] + HS[i, 1] * Hr[1, j] + HS[i, 2] * Hr[2, j]
        lt[i] -= HS[i, 0] * nu[0] + HS[i, 1] * nu[1] + HS[i, 2] * nu[2]
    for i in range(6):  # Lh_{k-1} = Phi^T Lt Phi (symmetric), lh_{k-1} = Phi^T lt
        for j in range(6):
            acc = 0.0
            for l in range(6):
                acc += Lt[i, l] * Phi[l, j]
            T[i, j] = acc
    for i in range(6):
        for j in range(i, 6):
            acc = 0.0
            for l in range(6):
                acc += Phi[l, i] * T[l, j]
            L[i, j] = acc
            L[j, i] = acc
        acc = 0.0
        for l in range(6):
            acc += Phi[l, i] * lt[l]
        lv[i] = acc


@kernel
def _bryson_frazier_window(xf, Pf, K, Hr, Sinv, nu, Phi, c0, xs, Ps):
    """The modified Bryson-Frazier pass of :func:`bryson_frazier` for every seed, one seed
    at a time backwards in time (:func:`bf_moments`, :func:`bf_back`), keeping only the
    adjoint of the current sample: fills ``xs (S, n+1, c)`` and ``Ps (S, n+1, c, c)`` with the
    smoothed moments of the state components ``c0..c0+c``."""
    S, n1 = xf.shape[0], xf.shape[1]
    L = np.zeros((6, 6))
    lv = np.zeros(6)
    T = np.empty((6, 6))
    work = (np.empty((6, 3)), T, np.empty((6, 6)), np.empty(6), np.empty((3, 3)))
    for s in range(S):
        L[:, :] = 0.0
        lv[:] = 0.0
        for k in range(n1 - 1, -1, -1):
            bf_moments(xf[s, k], Pf[s, k], L, lv, c0, xs[s, k], Ps[s, k], T)
            if k > 0:
                bf_back((K[s, k], Hr[s, k], Sinv[s, k], nu[s, k]), Phi[k], (L, lv), work)


def bryson_frazier(f: FilterResult, win: Window, cols: slice = slice(None)) -> SmootherResult:
    """The same smoothed moments by the modified Bryson-Frazier recursion (fast path).

    Backward adjoint recursion that needs no 6x6 inverse (Bierman 1977):
    ``Lt_k = H^T S^-1 H + Ct^T Lh_k Ct``, ``lt_k = -H^T S^-1 nu + Ct^T lh_k``,
    ``Lh_{k-1} = Phi_k^T Lt_k Phi_k``, ``lh_{k-1} = Phi_k^T lt_k`` with
    ``Ct = I - K H``; ``X_{k|N} = X_k - P_k lh_k``, ``P_{k|N} = P_k - P_k Lh_k P_k``.
    Algebraically identical to the RTS form (tests/approach_reference.py; a test checks
    it); used inside the EM iterations. The lag-one covariance is not formed (``Plag``
    zeros). ``cols``: only these state components (a contiguous
    slice) of the smoothed moments (``xs (S, n+1, c)``, ``Ps (S, n+1, c, c)``; the E-step
    needs the position only); each entry is the one of the full moments, bit for bit.
    Compiled (:func:`_bryson_frazier_window`, with the steps :func:`bf_moments` and
    :func:`bf_back` that the EM map's fused pass shares).
    """
    c0, c1, step = cols.indices(6)
    if step != 1 or c1 <= c0:
        raise ValueError(f"bryson_frazier: cols must be a contiguous slice of the 6 states, got {cols}")
    S, n1 = f.xf.shape[:2]
    xs = np.empty((S, n1, c1 - c0))
    Ps = np.empty((S, n1, c1 - c0, c1 - c0))
    c = carray
    _bryson_frazier_window(c(f.xf), c(f.Pf), c(f.K), c(f.Hr), c(f.Sinv), c(f.nu), c(win.Phi), c0, xs, Ps)
    return SmootherResult(xs, Ps, np.zeros(Ps.shape), np.zeros(Ps.shape))


@warms
def _warm() -> None:
    from .ekf import FilterResult as FR

    S, n1 = 1, 3
    P = np.broadcast_to(np.eye(6), (S, n1, 6, 6)).copy()
    f = FR(np.zeros((S, n1, 6)), P, None, None, np.zeros(S), np.zeros((S, 6, 6)), np.zeros((S, n1, 6, 3)),
           np.broadcast_to(np.eye(3), (S, n1, 3, 3)).copy(), np.zeros((S, n1, 3)), np.zeros((S, n1, 3, 3)))
    bryson_frazier(f, Window(P[0], np.zeros((n1, 3, 3)), np.zeros((n1, 3)), np.ones((n1, 3)), np.eye(6)), slice(0, 3))
