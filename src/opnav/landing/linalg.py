"""Linear algebra of paper B's compiled kernels: the Cholesky factor, its solve, the log-det.

One home for the lower Cholesky factor that the landing filter's gain (``opnav.landing.ekf``,
``K = P H^T S^-1`` with ``S = H P H^T + sigma_b^2 I``, eq. 11-18) and the planned-information
metrics (``opnav.landing.planning.information``: ``S = I + A P0 A^T``, log det) both need. Plain loops over
the leading ``n x n`` block of a square float64 array, so one scratch array of the largest size
serves every call; sums run in index order, so a result does not depend on the batch it is in.

Why not ``np.linalg.cholesky``: inside a kernel it allocates per call and raises on a matrix that
is not positive definite; the callers here need a bool (the planner rejects a candidate, the
filter marks the run NaN) and work in preallocated scratch.
"""
from __future__ import annotations

import math

import numpy as np

from opnav.core.compiled import kernel, warms

__all__ = ["cho_solve", "cholesky_in_place", "cholesky_shifted", "logdet_spd", "matmul", "symmetrize"]


@kernel
def cholesky_shifted(Q, n, mu, C) -> bool:
    """C[:n, :n] <- the lower Cholesky factor of Q[:n, :n] - mu I (lower triangle of Q read; the
    upper triangle of C left as it is); False if that is not positive definite (exact arithmetic:
    lambda_min <= mu; in floating point within a backward error of ~n eps max Q_ii), C then
    filled up to the failing column. ``C`` may be ``Q`` (factor in place): entry (i, j) of Q is
    read before entry (i, j) of C is written."""
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
def cholesky_in_place(S, n) -> bool:
    """S[:n, :n] <- its lower Cholesky factor (lower triangle of S read and written); where S is
    not positive definite (or holds a NaN) the block is filled with NaN and False returned, so
    what is solved with it is NaN (the filter's gain and state, a NEES) rather than a
    factor of a matrix that is not S."""
    if cholesky_shifted(S, n, 0.0, S):
        return True
    for i in range(n):
        for j in range(n):
            S[i, j] = np.nan
    return False


@kernel
def cho_solve(L, n, x) -> None:
    """``x[:n] <- (L L^T)^-1 x[:n]`` in place, ``L`` the lower factor (lower triangle of
    ``L[:n, :n]`` read): forward then backward substitution."""
    for i in range(n):
        s = x[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]


@kernel
def logdet_spd(A, n, C) -> float:
    """log det A[:n, :n] (symmetric) as ``planning.reference.chol_logdet`` defines it: 2 sum log diag of the
    Cholesky factor of the Jacobi-equilibrated D^-1/2 A D^-1/2 + j I, plus sum log D; j from n eps,
    x 1e3 while the Cholesky fails, up to 1e-8; -inf if it still fails or a diagonal entry is not
    positive (C: (n, n) scratch, receives the factor). The equilibration keeps the jitter relative
    to each variance, whose units differ (m^2, (m/s)^2, rad^2)."""
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
def matmul(A, B, C) -> None:
    """``C = A B`` (plain loops, sums in index order)."""
    for a in range(A.shape[0]):
        for b in range(B.shape[1]):
            s = 0.0
            for c in range(A.shape[1]):
                s += A[a, c] * B[c, b]
            C[a, b] = s


@kernel
def symmetrize(P) -> None:
    """``P <- (P + P^T) / 2`` in place (a covariance after a product that is symmetric only to
    round-off)."""
    n = P.shape[0]
    for a in range(n):
        for b in range(a + 1, n):
            m = 0.5 * (P[a, b] + P[b, a])
            P[a, b] = m
            P[b, a] = m


@warms
def _warm() -> None:
    A = np.eye(3) * 2.0
    C = np.empty((3, 3))
    cholesky_shifted(A, 3, 0.0, C)
    cholesky_in_place(A.copy(), 3)
    cho_solve(C, 3, np.ones(3))
    logdet_spd(A, 3, C)
    matmul(A, A, C)
    symmetrize(C)
