"""The one Kalman predict and the one measurement update of paper A (eq. 6), batched over seeds.

Description
    Every filter of paper A is built from these two steps, as dynamax builds
    its filters from one ``_predict`` and one ``_condition_on``:

    * the EM-EKF (:func:`opnav.approach.ekf.run_filter`, paper eq. 6, whose compiled
      window pass :func:`opnav.approach.ekf.filter_window` calls the kernels of the steps
      below) and the prior propagated without data (:func:`propagate`,
      :func:`opnav.approach.ekf.predict_only`);
    * the augmented EKF of ``[dX; theta]`` (:func:`opnav.approach.augmented.run_augmented`);
    * the Cramér-Rao bound recursion (:func:`opnav.approach.crlb.crlb_curve`),
      the covariance of the same augmented filter on the linear-Gaussian model.

    :func:`predict` (time update, eq. 6)::

        m_k|k-1 = F m_k-1,        P_k|k-1 = F P_k-1 F^T + Q

    :func:`condition_on` (measurement update with a diagonal noise ``R = diag(rvar)``
    and 3-vector measurements; ``H`` may cover only some state columns ``cols``,
    zeros elsewhere, e.g. the position block of the EKF)::

        S = H P H^T + R,   K = P H^T S^-1,   m = m + K nu
        P = P - K S K^T                        (standard form; ``joseph=False``)
        P = (I - K H) P (I - K H)^T + K R K^T  (Joseph form; ``joseph=True``)

    symmetrised as ``(P + P^T) / 2``. The innovation ``nu = z - h(m)`` is the
    caller's (it holds the measurement model). :func:`innovation_loglik` is the
    term of the prediction-error decomposition of the log-likelihood.

Implementation
    Each step is written once, for one batch member, as plain loops compiled with
    :func:`opnav.core.compiled.kernel` (``_predict_mean1``, ``_predict_cov1``, ``_condition1``, ``_loglik1``); the
    batched Python API (:func:`predict`, :func:`condition_on`, :func:`propagate`,
    :func:`innovation_loglik`) loops them over the members, and
    :func:`opnav.approach.ekf.filter_window` runs the EM-EKF's whole window for every seed
    in one call. A single batched call is no faster than numpy (the Python around it
    dominates); the gain is in the compiled window passes, where the loop over samples is
    compiled too (measurements: docs/performance.md, "Measurements formerly in docstrings").

Shapes
    Leading axes ``...`` (seeds, windows, or none) broadcast: ``m (..., d)``,
    ``P (..., d, d)``, ``F (d, d)`` or ``(..., d, d)``, ``Q (d, d)``, ``H (..., 3, c)``, ``rvar (..., 3)``.
    ``m`` and ``nu`` may be ``None`` for a covariance-only recursion.
Units: those of the state and measurement (km, km/s; theta in rad or arcsec).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from opnav.core.compiled import kernel, warms

LOG2PI = np.log(2.0 * np.pi)


# ----------------------------------------------------------------- one member (the kernels)
@kernel
def _inv_sym3(S, Sinv):
    """Inverse of the symmetric 3x3 ``S`` into ``Sinv`` (cofactors); returns det S."""
    a, b, c = S[0, 0], S[0, 1], S[0, 2]
    d, e, f = S[1, 1], S[1, 2], S[2, 2]
    A00, A01, A02 = d * f - e * e, c * e - b * f, b * e - c * d
    A11, A12, A22 = a * f - c * c, b * c - a * e, a * d - b * b
    det = a * A00 + b * A01 + c * A02
    r = 1.0 / det
    Sinv[0, 0] = A00 * r
    Sinv[0, 1] = Sinv[1, 0] = A01 * r
    Sinv[0, 2] = Sinv[2, 0] = A02 * r
    Sinv[1, 1] = A11 * r
    Sinv[1, 2] = Sinv[2, 1] = A12 * r
    Sinv[2, 2] = A22 * r
    return det


@kernel
def _predict_mean1(x, F, xo):
    """Time update of one member's mean: ``xo = F x`` (``xo`` may not alias ``x``)."""
    d = F.shape[0]
    for i in range(d):
        acc = 0.0
        for j in range(d):
            acc += F[i, j] * x[j]
        xo[i] = acc


@kernel
def _predict_cov1(P, F, Q, Po, FP):
    """Time update of one member's covariance: ``Po = F P F^T + Q``, P and Q symmetric (the
    upper triangle is computed and mirrored); ``FP`` (d, d) scratch."""
    d = P.shape[0]
    for i in range(d):
        for j in range(d):
            acc = 0.0
            for l in range(d):
                acc += F[i, l] * P[l, j]
            FP[i, j] = acc
    for i in range(d):  # symmetric: the upper triangle, mirrored
        for j in range(i, d):
            acc = 0.0
            for l in range(d):
                acc += FP[i, l] * F[j, l]
            Po[i, j] = acc + Q[i, j]
            Po[j, i] = Po[i, j]


@kernel
def _condition1(has_m, x, P, meas, joseph, out, work):
    """Measurement update of one member, in place on ``x`` (d,) (if ``has_m``) and ``P`` (d, d)
    (symmetric: the upper triangle of the result is computed and mirrored), Joseph form if
    ``joseph``. ``meas = (H, c0, rvar, nu)``: ``H`` (3, c) on the state columns ``c0..c0+c``,
    the noise variances ``rvar`` (3,) and the innovation ``nu`` (3,). ``out = (K, Sinv)``
    receives the gain (d, 3) and S^-1 (3, 3); returns det S. ``work = (PHt, S, T1, T2)``
    scratch (d, 3), (3, 3), (d, d), (d, d) (T1, T2 Joseph form only)."""
    H, c0, rvar, nu = meas
    K, Sinv = out
    PHt, S, T1, T2 = work
    d = P.shape[0]
    c = H.shape[1]
    for i in range(d):  # P H^T
        for a in range(3):
            acc = 0.0
            for j in range(c):
                acc += P[i, c0 + j] * H[a, j]
            PHt[i, a] = acc
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for j in range(c):
                acc += H[a, j] * PHt[c0 + j, b]
            S[a, b] = acc
        S[a, a] += rvar[a]
    det = _inv_sym3(S, Sinv)
    for i in range(d):  # K = P H^T S^-1
        for b in range(3):
            acc = 0.0
            for a in range(3):
                acc += PHt[i, a] * Sinv[a, b]
            K[i, b] = acc
    if has_m:
        for i in range(d):
            x[i] += K[i, 0] * nu[0] + K[i, 1] * nu[1] + K[i, 2] * nu[2]
    if joseph:
        for i in range(d):  # T1 = I - K H (H zero outside c0..c0+c)
            for j in range(d):
                T1[i, j] = 1.0 if i == j else 0.0
            for j in range(c):
                T1[i, c0 + j] -= K[i, 0] * H[0, j] + K[i, 1] * H[1, j] + K[i, 2] * H[2, j]
        for i in range(d):  # T2 = (I - K H) P
            for j in range(d):
                acc = 0.0
                for l in range(d):
                    acc += T1[i, l] * P[l, j]
                T2[i, j] = acc
        for i in range(d):  # P = T2 (I - K H)^T + K R K^T (symmetric: upper triangle, mirrored)
            for j in range(i, d):
                acc = 0.0
                for l in range(d):
                    acc += T2[i, l] * T1[j, l]
                acc += K[i, 0] * rvar[0] * K[j, 0] + K[i, 1] * rvar[1] * K[j, 1] + K[i, 2] * rvar[2] * K[j, 2]
                P[i, j] = acc
                P[j, i] = acc
    else:
        for i in range(d):  # P = P - K (P H^T)^T (symmetric: upper triangle, mirrored)
            for j in range(i, d):
                v = P[i, j] - (K[i, 0] * PHt[j, 0] + K[i, 1] * PHt[j, 1] + K[i, 2] * PHt[j, 2])
                P[i, j] = v
                P[j, i] = v
    return det


@kernel
def _loglik1(nu, Sinv, det):
    """``-1/2 (log det S + nu^T S^-1 nu + 3 log 2 pi)`` of one sample."""
    q = 0.0
    for a in range(3):
        for b in range(3):
            q += nu[a] * Sinv[a, b] * nu[b]
    return -0.5 * (np.log(det) + q + 3.0 * np.log(2.0 * np.pi))


# ----------------------------------------------------------------- batches of members
@kernel
def _predict_batch(m, P, F, Q, mo, Po):
    """Means ``m`` (Bm, d) (Bm may be 0) and covariances ``P`` (BP, d, d); F, Q one per member
    or one row shared."""
    d = P.shape[1]
    FP = np.empty((d, d))
    for b in range(max(m.shape[0], P.shape[0])):
        f = b if F.shape[0] > 1 else 0
        if b < m.shape[0]:
            _predict_mean1(m[b], F[f], mo[b])
        if b < P.shape[0]:
            _predict_cov1(P[b], F[f], Q[b if Q.shape[0] > 1 else 0], Po[b], FP)


@kernel
def _condition_batch(has_m, m, P, meas, joseph, out):
    """:func:`_condition1` of every member: ``meas = (H, c0, rvar, nu)`` with ``H`` and ``rvar``
    one per member or one row shared; ``out = (K, Sinv, det)``."""
    H, c0, rvar, nu = meas
    K, Sinv, det = out
    B, d = P.shape[0], P.shape[1]
    work = (np.empty((d, 3)), np.empty((3, 3)), np.empty((d, d)), np.empty((d, d)))
    for b in range(B):
        h = b if H.shape[0] > 1 else 0
        r = b if rvar.shape[0] > 1 else 0
        det[b] = _condition1(has_m, m[b], P[b], (H[h], c0, rvar[r], nu[b]), joseph, (K[b], Sinv[b]), work)


@kernel
def _loglik_batch(nu, Sinv, det, out):
    for b in range(nu.shape[0]):
        out[b] = _loglik1(nu[b], Sinv[b], det[b])


def carray(a) -> np.ndarray:
    """``a`` as the kernels take every array: float64, C-contiguous, writeable (a read-only
    or strided view is copied), so each kernel has one compiled signature per rank."""
    return np.require(a, dtype=np.float64, requirements="CW")


def _lead(*shapes: tuple) -> tuple:
    """``numpy.broadcast_shapes`` with a fast path for the usual case (one batch shape or none)."""
    first = ()
    for sh in shapes:
        if sh and sh != first:
            if first:
                return np.broadcast_shapes(*shapes)
            first = sh
    return first


def _flat(a, lead: tuple, tail: int, shared_ok: bool = True) -> np.ndarray:
    """``a`` as a kernel array (B or 1, *tail dims) over the batch ``lead``: one row when it
    has no batch axes and ``shared_ok``, else broadcast to ``lead``."""
    a = np.asarray(a, dtype=float)
    core = a.shape[a.ndim - tail:]
    if shared_ok and a.ndim == tail:
        a = a.reshape((1,) + core)
    else:
        if a.shape[:a.ndim - tail] != lead:
            a = np.broadcast_to(a, lead + core)
        a = a.reshape((-1,) + core)
    return a if a.flags.c_contiguous and a.flags.writeable else np.array(a, order="C")


def predict(m: np.ndarray | None, P: np.ndarray, F: np.ndarray, Q: np.ndarray
            ) -> tuple[np.ndarray | None, np.ndarray]:
    """Time update ``(F m, F P F^T + Q)`` (module docstring); ``m`` may be None.
    ``F`` (d, d) is shared by the batch, or (..., d, d) one per batch member."""
    lead = _lead(np.shape(P)[:-2], np.shape(F)[:-2], np.shape(Q)[:-2])
    mlead = lead if m is None else _lead(np.shape(m)[:-1], np.shape(F)[:-2])
    d = np.shape(P)[-1]
    Pf = _flat(P, lead, 2, shared_ok=False)
    mf = _flat(m, mlead, 1, shared_ok=False) if m is not None else np.zeros((0, d))
    if np.ndim(F) > 2 and mlead != lead:
        raise ValueError(f"predict: F per member {np.shape(F)} needs m and P over the same members")
    Ff = _flat(F, lead, 2)
    mo, Po = np.empty_like(mf), np.empty_like(Pf)
    _predict_batch(mf, Pf, Ff, _flat(Q, lead, 2), mo, Po)
    return (None if m is None else mo.reshape(mlead + (d,))), Po.reshape(lead + (d, d))


@kernel
def _propagate(x, P, Phi, Q, xs, Ps):
    """Moments at every sample 0..n of the prior propagated without data: x (B, d) (B may
    be 0), P (C, d, d), Phi (n+1, d, d); fills xs (n+1, B, d), Ps (n+1, C, d, d)."""
    d = P.shape[1]
    FP = np.empty((d, d))
    for b in range(x.shape[0]):
        for i in range(d):
            xs[0, b, i] = x[b, i]
    for c in range(P.shape[0]):
        for i in range(d):
            for j in range(d):
                Ps[0, c, i, j] = P[c, i, j]
    for k in range(1, Phi.shape[0]):
        for b in range(x.shape[0]):
            _predict_mean1(xs[k - 1, b], Phi[k], xs[k, b])
        for c in range(P.shape[0]):
            _predict_cov1(Ps[k - 1, c], Phi[k], Q, Ps[k, c], FP)


def propagate(m: np.ndarray | None, P: np.ndarray, Phi: np.ndarray, Q: np.ndarray
              ) -> tuple[np.ndarray | None, np.ndarray]:
    """:func:`predict` through ``Phi[1..n]`` (n+1, d, d) with one ``Q`` (d, d): the moments at
    every sample 0..n, ``(n+1, ..., d)`` (None without ``m``) and ``(n+1, ..., d, d)``, in one
    compiled pass (each sample's numbers are those of the step-by-step :func:`predict`)."""
    d = np.shape(P)[-1]
    mlead, Plead = (() if m is None else np.shape(m)[:-1]), np.shape(P)[:-2]
    mf = np.zeros((0, d)) if m is None else _flat(m, mlead, 1, shared_ok=False)
    Pf = _flat(P, Plead, 2, shared_ok=False)
    n1 = np.shape(Phi)[0]
    xs, Ps = np.empty((n1,) + mf.shape), np.empty((n1,) + Pf.shape)
    _propagate(mf, Pf, carray(Phi), carray(Q), xs, Ps)
    return (None if m is None else xs.reshape((n1,) + mlead + (d,))), Ps.reshape((n1,) + Plead + (d, d))


class Update(NamedTuple):
    """Result of :func:`condition_on`: posterior ``m, P``, gain ``K (..., d, 3)``,
    inverse innovation covariance ``Sinv (..., 3, 3)`` and ``det S (...)``."""

    m: np.ndarray | None
    P: np.ndarray
    K: np.ndarray
    Sinv: np.ndarray
    det: np.ndarray


def condition_on(m: np.ndarray | None, P: np.ndarray, H: np.ndarray, rvar: np.ndarray,
                 nu: np.ndarray | None, cols: slice = slice(None), joseph: bool = False) -> Update:
    """Measurement update with innovation ``nu`` (module docstring).

    ``H (..., 3, c)`` multiplies the state columns ``cols`` (c of them, contiguous); the
    other columns of the measurement Jacobian are zero.
    """
    d = np.shape(P)[-1]
    c0, c1, step = cols.indices(d)
    if step != 1 or c1 - c0 != np.shape(H)[-1]:
        raise ValueError(f"condition_on: cols {cols} must be a contiguous slice of H's {np.shape(H)[-1]} columns")
    shapes = [np.shape(P)[:-2], np.shape(H)[:-2], np.shape(rvar)[:-1]]
    if m is not None:
        shapes += [np.shape(m)[:-1], np.shape(nu)[:-1]]
    lead = _lead(*shapes)
    Pf = _flat(P, lead, 2, shared_ok=False).copy()
    B = Pf.shape[0]
    if m is None:
        mf, nuf = np.zeros((B, 0)), np.zeros((B, 3))
    else:
        mf, nuf = _flat(m, lead, 1, shared_ok=False).copy(), _flat(nu, lead, 1, shared_ok=False)
    K, Sinv, det = np.empty((B, d, 3)), np.empty((B, 3, 3)), np.empty(B)
    _condition_batch(m is not None, mf, Pf, (_flat(H, lead, 2), c0, _flat(rvar, lead, 1), nuf), joseph,
                     (K, Sinv, det))
    return Update(None if m is None else mf.reshape(lead + (d,)), Pf.reshape(lead + (d, d)),
                  K.reshape(lead + (d, 3)), Sinv.reshape(lead + (3, 3)), det.reshape(lead))


def innovation_loglik(nu: np.ndarray, Sinv: np.ndarray, det: np.ndarray) -> np.ndarray:
    """``-1/2 (log det S + nu^T S^-1 nu + 3 log 2 pi)`` per sample (...), the
    prediction-error decomposition term of the observed-data log-likelihood."""
    lead = _lead(np.shape(nu)[:-1], np.shape(Sinv)[:-2], np.shape(det))
    out = np.empty(int(np.prod(lead)))
    _loglik_batch(_flat(nu, lead, 1, False), _flat(Sinv, lead, 2, False), _flat(det, lead, 0, False), out)
    return out.reshape(lead)


@warms
def _warm() -> None:
    """Each kernel once with the pipeline's argument types (float64 arrays, int64, bool)."""
    P, F, Q = np.eye(6)[None], np.eye(6), np.eye(6)
    m, P1 = predict(np.zeros((1, 6)), P, F, Q)
    predict(None, P, F, Q)
    propagate(np.zeros((1, 6)), np.eye(6), np.broadcast_to(F, (2, 6, 6)), Q)
    u = condition_on(m, P1, np.eye(3)[None], np.ones((1, 3)), np.zeros((1, 3)), cols=slice(0, 3))
    condition_on(None, P1, np.ones((1, 3, 6)), np.ones((1, 3)), None, joseph=True)
    innovation_loglik(np.zeros((1, 3)), u.Sinv, u.det)
