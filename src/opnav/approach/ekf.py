"""Extended Kalman filter of the approach navigation, batched over Monte-Carlo seeds (paper A eq. 6).

Description
    The filter works in deviations ``dX = X - X_ref`` from a reference
    trajectory (the nonlinearly propagated prior mean), with the one-step state
    transition matrices ``Phi_{k,k-1}`` of the variational equations
    (:mod:`opnav.approach.dynamics`). The measurement (SPEC A.2, paper eq. 3)

        z_k = A_m^c(theta) A_c^i,k (X_M,k - r_k) + v_k
            = A_m(theta) (u_ref,k - C_k dr_k) + v_k,   C_k = A_c^i,k,

    is linear in the state: ``H_k = [-A_m(theta) C_k, 0_3x3]`` (the paper's
    eq. 27 has ``+`` because it differentiates with respect to the
    spacecraft-to-Mars vector). The estimator uses the small-angle ``A_m``.

    All arrays carry a leading seed axis ``S``; each seed may have its own
    ``theta``. Sample 0 of a window is its start (no measurement); samples
    1..n carry ``z``. ``Phi[k]`` maps sample k-1 to sample k.

Outputs (:class:`FilterResult`)
    filtered ``xf, Pf`` (index 0 = the start state), predicted ``xp, Pp``
    (index 0 unused), the observed-data log-likelihood by the prediction-error
    decomposition, and ``KH_last`` for the smoother's lag-one initialisation.

Units: km, km/s, rad.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from opnav.core.compiled import kernel, warms

from . import kalman
from .camera import misalignment_small
from .kalman import _condition1, _loglik1, _predict_cov1, _predict_mean1

POS = slice(0, 3)  # position columns of the state: the only ones H touches


@dataclass
class Window:
    """Model arrays of one data window (n samples after the start sample 0)."""

    Phi: np.ndarray  # (n+1, 6, 6), Phi[k] = Phi_{k,k-1}; Phi[0] unused
    C: np.ndarray  # (n+1, 3, 3) A_c^i at each sample; index 0 unused
    u_ref: np.ndarray  # (n+1, 3) A_c^i (X_M - r_ref), km
    Rvar: np.ndarray  # (n+1, 3) or per seed (n+1, S, 3) measurement variances, km^2
    Q: np.ndarray  # (6, 6) process noise per step
    stars: object = None  # stars.StarField of the window's star images (``stars`` variant), or None
    star_y: np.ndarray | None = None  # (S, I, 2m) raw star measurements, rad

    def slice(self, a: int, b: int) -> "Window":
        """Samples a..b (inclusive; a becomes the start sample 0; star images a+1..b, whitened by
        their own joint covariance: :meth:`opnav.approach.stars.StarField.select`)."""
        st, y = self.stars, self.star_y
        if st is not None:
            keep = (st.idx > a) & (st.idx <= b)
            st, y = st.select(a, b), (None if y is None else y[:, keep])
        return Window(self.Phi[a:b + 1], self.C[a:b + 1], self.u_ref[a:b + 1],
                      self.Rvar[a:b + 1], self.Q, st, y)

    @functools.cached_property
    def star_yw(self) -> np.ndarray | None:
        """The star measurements whitened by this window's field (S, I, 2m), rad: what the
        M-step, the likelihood and the augmented EKF read (None without star data)."""
        if self.stars is None or self.star_y is None:
            return None
        return self.stars.whiten(self.star_y)

    def rows(self, idx: np.ndarray) -> "Window":
        """The window of the seeds ``idx`` (per-seed variances and star data have a seed axis)."""
        y = None if self.star_y is None else self.star_y[idx]
        if self.Rvar.ndim == 2:
            return Window(self.Phi, self.C, self.u_ref, self.Rvar, self.Q, self.stars, y)
        return Window(self.Phi, self.C, self.u_ref, self.Rvar[:, idx], self.Q, self.stars, y)

    def weights(self, S: int) -> np.ndarray:
        """R^-1 diagonals of samples 1..n for every seed, (S, n, 3)."""
        w = 1.0 / self.Rvar[1:]
        if w.ndim == 2:
            return np.broadcast_to(w, (S,) + w.shape)
        return np.swapaxes(w, 0, 1)

    @property
    def n(self) -> int:
        return self.Phi.shape[0] - 1


@dataclass
class FilterResult:
    xf: np.ndarray  # (S, n+1, 6)
    Pf: np.ndarray  # (S, n+1, 6, 6)
    xp: np.ndarray  # (S, n+1, 6)
    Pp: np.ndarray  # (S, n+1, 6, 6)
    loglik: np.ndarray  # (S,)
    KH_last: np.ndarray  # (S, 6, 6)
    K: np.ndarray | None = None  # (S, n+1, 6, 3) gains
    Sinv: np.ndarray | None = None  # (S, n+1, 3, 3) inverse innovation covariances
    nu: np.ndarray | None = None  # (S, n+1, 3) innovations
    Hr: np.ndarray | None = None  # (S, n+1, 3, 3) position block of H


def predicted_measurement(theta: np.ndarray, C: np.ndarray, u_ref: np.ndarray,
                          dx: np.ndarray) -> np.ndarray:
    """``h(dX) = A_m(theta) (u_ref - C dr)`` (S, 3) for one sample."""
    A = misalignment_small(theta)
    return np.einsum("sij,sj->si", A, u_ref - np.einsum("ij,sj->si", C, dx[..., :3]))


def measurement_jacobian(theta: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``H = [-A_m(theta) C, 0]`` (S, 3, 6)."""
    A = misalignment_small(theta)
    H = np.zeros(A.shape[:-2] + (3, 6))
    H[..., :3] = -A @ C
    return H


@kernel(inline="always")
def ekf_step(prev, dyn, obs, post, work):
    """One sample of the EM-EKF (eq. 6): ``H_r = -A_m C_k`` into ``Hr``, the time update of
    ``prev = (xprev, Pprev)`` with ``dyn = (Phi, Q)`` into ``(x, P)`` (``_predict_mean1``,
    ``_predict_cov1``), the innovation ``nu = z - A_m u_ref - H_r x`` (the model is linear in
    the state) of ``obs = (A, C, u_ref, z, rvar)`` (A = A_m(theta), C = A_c^i,k, km, km^2) and
    the update in place (``_condition1``). ``post = (x, P, K, Sinv, nu, Hr)`` receives the
    sample's filter quantities; ``work = (FP, PHt, Sm, T)`` scratch (6, 6), (6, 3), (3, 3),
    (6, 6). Returns det S."""
    xprev, Pprev = prev
    Phi, Q = dyn
    A, C, u_ref, z, rvar = obs
    x, P, K, Sinv, nu, Hr = post
    FP, PHt, Sm, T = work
    for i in range(3):
        for j in range(3):
            Hr[i, j] = -(A[i, 0] * C[0, j] + A[i, 1] * C[1, j] + A[i, 2] * C[2, j])
    _predict_mean1(xprev, Phi, x)
    _predict_cov1(Pprev, Phi, Q, P, FP)
    for i in range(3):
        nu[i] = (z[i] - (A[i, 0] * u_ref[0] + A[i, 1] * u_ref[1] + A[i, 2] * u_ref[2])
                 - (Hr[i, 0] * x[0] + Hr[i, 1] * x[1] + Hr[i, 2] * x[2]))
    return _condition1(True, x, P, (Hr, 0, rvar, nu), False, (K, Sinv), (PHt, Sm, T, T))


@kernel
def filter_window(z, A, start, model, keep_pred, out):
    """The EM-EKF (eq. 6, :func:`run_filter`) over one window for every seed, :func:`ekf_step`
    by step.

    z (S, n+1, 3); A (S, 3, 3) = A_m(theta) per seed; ``start = (x0 (S, 6), P0 (S, 6, 6))``;
    the window's ``model = (Phi (n+1, 6, 6), C (n+1, 3, 3), u_ref (n+1, 3), Rvar (n+1, S, 3),
    Q (6, 6))``. Fills ``out = (xf, Pf, xp, Pp, K, Sinv, nu, Hr, ll, KH)``: xf, Pf, (xp, Pp
    when ``keep_pred``), K (S, n+1, 6, 3), Sinv (S, n+1, 3, 3), nu (S, n+1, 3), Hr
    (S, n+1, 3, 3) (sample 0: ``-A_m C_0``), the log-likelihood ll (S,) and KH (S, 6, 6) of
    the last sample. Returns the smallest det S (not positive: the filter broke)."""
    x0, P0 = start
    Phi, C, u_ref, Rvar, Q = model
    xf, Pf, xp, Pp, K, Sinv, nu, Hr, ll, KH = out
    S, n1 = z.shape[0], z.shape[1]
    FP = np.empty((6, 6))
    work = (FP, np.empty((6, 3)), np.empty((3, 3)), np.empty((6, 6)))
    dmin = np.inf
    for s in range(S):
        for i in range(3):
            for j in range(3):
                Hr[s, 0, i, j] = -(A[s, i, 0] * C[0, 0, j] + A[s, i, 1] * C[0, 1, j] + A[s, i, 2] * C[0, 2, j])
        for i in range(6):
            xf[s, 0, i] = x0[s, i]
            for j in range(6):
                Pf[s, 0, i, j] = P0[s, i, j]
        acc_ll = 0.0
        for k in range(1, n1):
            det = ekf_step((xf[s, k - 1], Pf[s, k - 1]), (Phi[k], Q), (A[s], C[k], u_ref[k], z[s, k], Rvar[k, s]),
                           (xf[s, k], Pf[s, k], K[s, k], Sinv[s, k], nu[s, k], Hr[s, k]), work)
            if keep_pred:  # the predicted moments again (the step updated them in place)
                _predict_mean1(xf[s, k - 1], Phi[k], xp[s, k])
                _predict_cov1(Pf[s, k - 1], Phi[k], Q, Pp[s, k], FP)
            dmin = min(dmin, det)
            if det > 0.0:
                acc_ll += _loglik1(nu[s, k], Sinv[s, k], det)
        ll[s] = acc_ll
        n = n1 - 1
        for i in range(6):
            for j in range(6):
                KH[s, i, j] = 0.0
            for j in range(3):
                KH[s, i, j] = K[s, n, i, 0] * Hr[s, n, 0, j] + K[s, n, i, 1] * Hr[s, n, 1, j] + K[s, n, i, 2] * Hr[s, n, 2, j]
    return dmin


def run_filter(z: np.ndarray, theta: np.ndarray, x0: np.ndarray, P0: np.ndarray,
               win: Window, predicted: bool = True) -> FilterResult:
    """EKF over a window for every seed at once (eq. 6): the compiled pass
    :func:`filter_window` (the one predict and update of :mod:`kalman`, with the
    position block of ``H``).

    z (S, n+1, 3) (index 0 ignored), theta (S, 3) rad, x0 (S, 6), P0 (S, 6, 6) or (6, 6).
    ``predicted=False``: ``xp, Pp`` are not kept (None; the RTS smoother needs them, the
    Bryson-Frazier smoother and the E-step do not); every other output is the same.
    """
    S, n = z.shape[0], win.n
    A = misalignment_small(np.asarray(theta, float))
    Rvar = win.Rvar if win.Rvar.ndim == 3 else win.Rvar[:, None, :]
    xf = np.empty((S, n + 1, 6))
    Pf = np.empty((S, n + 1, 6, 6))
    xp = np.zeros((S, n + 1, 6)) if predicted else np.empty((0, 0, 6))
    Pp = np.zeros((S, n + 1, 6, 6)) if predicted else np.empty((0, 0, 6, 6))
    Ks = np.zeros((S, n + 1, 6, 3))
    Sinvs = np.zeros((S, n + 1, 3, 3))
    nus = np.zeros((S, n + 1, 3))
    Hrs = np.empty((S, n + 1, 3, 3))
    ll = np.empty(S)
    KH = np.empty((S, 6, 6))
    c = kalman.carray
    dmin = filter_window(c(z), c(A), (c(np.broadcast_to(x0, (S, 6))), c(np.broadcast_to(P0, (S, 6, 6)))),
                         (c(win.Phi), c(win.C), c(win.u_ref), c(np.broadcast_to(Rvar, (n + 1, S, 3))), c(win.Q)),
                         predicted, (xf, Pf, xp, Pp, Ks, Sinvs, nus, Hrs, ll, KH))
    if not dmin > 0:
        raise FloatingPointError("innovation covariance not positive definite")
    return FilterResult(xf, Pf, xp if predicted else None, Pp if predicted else None, ll, KH, Ks, Sinvs, nus, Hrs)


def predict_only(x0: np.ndarray, P0: np.ndarray, win: Window, at=None):
    """Prior mean and covariance propagated through the window without data.

    ``at``: increasing sample indices; then the moments at each of them, as lists
    (one pass, :func:`kalman.propagate`: the moments at ``at[i]`` are those of the window
    ``slice(0, at[i])``).
    """
    stops = [win.n] if at is None else [int(a) for a in at]
    if any(b < a for a, b in zip(stops, stops[1:])) or (stops and not 0 <= stops[0] <= stops[-1] <= win.n):
        raise ValueError(f"predict_only: sample indices must increase within 0..{win.n}, got {stops}")
    last = stops[-1] if stops else 0
    xs, Ps = kalman.propagate(np.asarray(x0, float), np.asarray(P0, float), win.Phi[:last + 1], win.Q)
    if at is None:
        return xs[-1], Ps[-1]
    return [xs[a] for a in stops], [Ps[a] for a in stops]


@warms
def _warm() -> None:
    """The window pass once with the pipeline's argument types."""
    S, n1 = 1, 2
    win = Window(np.broadcast_to(np.eye(6), (n1, 6, 6)).copy(), np.broadcast_to(np.eye(3), (n1, 3, 3)).copy(),
                 np.zeros((n1, 3)), np.ones((n1, 3)), np.eye(6))
    run_filter(np.zeros((S, n1, 3)), np.zeros((S, 3)), np.zeros((S, 6)), np.eye(6), win)
    run_filter(np.zeros((S, n1, 3)), np.zeros((S, 3)), np.zeros((S, 6)), np.eye(6), win, predicted=False)
