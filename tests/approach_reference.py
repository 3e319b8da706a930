"""Paper A's own smoother and E-step function in their textbook forms: references the
tests compare the pipeline's compiled passes with (the pipeline does not run them).

* :func:`rts` - the fixed-interval RTS smoother (eq. 7-9, 24-25) with the lag-one
  covariance in gain form (eq. 18), against :func:`opnav.approach.smoother.bryson_frazier`;
* :func:`lag_one_recursive` - ``P_{k,k-1|N}`` by the Shumway-Stoffer recursion (eq. 18);
* :func:`trace_RinvB` - Tr(sum R_k^-1 B_k(theta)) evaluated from eq. 23;
* :func:`expected_complete_loglik` - Q(theta | theta_r), eq. 21-22.
"""

import numpy as np

from opnav.approach.camera import misalignment_small
from opnav.approach.ekf import FilterResult, Window
from opnav.approach.smoother import SmootherResult


def _solve_spd(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A^-1 B for stacked SPD ``A`` via Jacobi scaling."""
    d = 1.0 / np.sqrt(np.diagonal(A, axis1=-2, axis2=-1))
    As = A * d[..., :, None] * d[..., None, :]
    return d[..., :, None] * np.linalg.solve(As, d[..., :, None] * B)


def rts(f: FilterResult, win: Window) -> SmootherResult:
    """Fixed-interval RTS smoother for every seed (eq. 7-9) with the lag-one covariance."""
    S, n1 = f.xf.shape[:2]
    n = n1 - 1
    xs = np.empty_like(f.xf)
    Ps = np.empty_like(f.Pf)
    Plag = np.zeros_like(f.Pf)
    G = np.zeros_like(f.Pf)
    xs[:, n], Ps[:, n] = f.xf[:, n], f.Pf[:, n]
    for k in range(n, 0, -1):
        Phi = win.Phi[k]
        Pk1 = f.Pf[:, k - 1]
        # G^T = Pp^-1 Phi P_{k-1}
        Gk = _solve_spd(f.Pp[:, k], Phi @ Pk1).transpose(0, 2, 1)
        G[:, k - 1] = Gk
        xs[:, k - 1] = f.xf[:, k - 1] + np.einsum("sij,sj->si", Gk, xs[:, k] - f.xp[:, k])
        Pk = Pk1 + Gk @ (Ps[:, k] - f.Pp[:, k]) @ Gk.transpose(0, 2, 1)
        Ps[:, k - 1] = 0.5 * (Pk + Pk.transpose(0, 2, 1))
        Plag[:, k] = Ps[:, k] @ Gk.transpose(0, 2, 1)
    return SmootherResult(xs, Ps, Plag, G)


def lag_one_recursive(f: FilterResult, s: SmootherResult, win: Window) -> np.ndarray:
    """``P_{k,k-1|N}`` by the Shumway-Stoffer recursion (eq. 18), for checking the gain form.

    P_{N,N-1|N}   = (I - K_N H_N) Phi_N P_{N-1}
    P_{k-1,k-2|N} = P_{k-1} G_{k-2}^T + G_{k-1} (P_{k,k-1|N} - Phi_k P_{k-1}) G_{k-2}^T
    """
    n = f.xf.shape[1] - 1
    out = np.zeros_like(f.Pf)
    I = np.eye(6)
    out[:, n] = (I - f.KH_last) @ win.Phi[n] @ f.Pf[:, n - 1]
    for k in range(n, 1, -1):
        Gt2 = s.G[:, k - 2].transpose(0, 2, 1)
        out[:, k - 1] = (f.Pf[:, k - 1] @ Gt2
                         + s.G[:, k - 1] @ (out[:, k] - win.Phi[k] @ f.Pf[:, k - 1]) @ Gt2)
    return out


def trace_RinvB(theta: np.ndarray, z: np.ndarray, s: SmootherResult, win: Window) -> np.ndarray:
    """Tr(sum R_k^-1 B_k(theta)) evaluated directly from eq. 23 (S,), for checks.

    ``B_k = H P_{k|N} H^T + (z_k - h(X_{k|N}))(...)^T`` with the small-angle ``H``.
    """
    A = misalignment_small(theta)  # (S,3,3)
    H = -np.einsum("sij,kjl->skil", A, win.C[1:])
    u = win.u_ref[1:] - np.einsum("kij,skj->ski", win.C[1:], s.xs[:, 1:, :3])
    res = z[:, 1:] - np.einsum("sij,skj->ski", A, u)
    w = win.weights(z.shape[0])
    HPH = np.einsum("skij,skjl,skml->skim", H, s.Ps[:, 1:, :3, :3], H)
    return (np.einsum("ski,skii->s", w, HPH) + np.einsum("ski,ski,ski->s", w, res, res))


def expected_complete_loglik(theta: np.ndarray, z: np.ndarray, s: SmootherResult, win: Window,
                             mu0: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """Eq. 21 without constants: the E-step function Q(theta | theta_r) (S,).

    Uses the A term (eq. 22) with the lag-one smoothed covariance ``P_{k,k-1|N}``.
    """
    n = win.n
    P0 = np.broadcast_to(P0, (z.shape[0], 6, 6))
    d0 = s.xs[:, 0] - mu0
    E0 = s.Ps[:, 0] + np.einsum("si,sj->sij", d0, d0)
    val = -0.5 * (np.linalg.slogdet(P0)[1] + np.trace(np.linalg.solve(P0, E0), axis1=1, axis2=2))
    Qinv = np.linalg.inv(win.Q)
    val -= 0.5 * n * np.linalg.slogdet(win.Q)[1]
    Aterm = 0.0
    for k in range(1, n + 1):
        Phi = win.Phi[k]
        dm = s.xs[:, k] - s.xs[:, k - 1] @ Phi.T
        Ak = (np.einsum("si,sj->sij", dm, dm) + s.Ps[:, k] - s.Plag[:, k] @ Phi.T
              - Phi @ s.Plag[:, k].transpose(0, 2, 1) + Phi @ s.Ps[:, k - 1] @ Phi.T)
        Aterm = Aterm + np.einsum("ij,sji->s", Qinv, Ak)
    val -= 0.5 * Aterm
    val += 0.5 * np.log(win.weights(z.shape[0])).sum(axis=(1, 2))
    val -= 0.5 * trace_RinvB(theta, z, s, win)
    return val
