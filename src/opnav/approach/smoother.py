"""Fixed-interval Rauch-Tung-Striebel smoother and lag-one cross-covariance (paper A eq. 7-9, 18).

Description
    Backward pass over a :class:`~opnav.approach.ekf.FilterResult`:

        G_{k-1}   = P_{k-1} Phi_{k,k-1}^T P_{k,k-1}^-1                  (eq. 9)
        X_{k-1|N} = X_{k-1} + G_{k-1} (X_{k|N} - Phi X_{k-1})           (eq. 7)
        P_{k-1|N} = P_{k-1} + G_{k-1} (P_{k|N} - P_{k,k-1}) G_{k-1}^T   (eq. 8)

    The lag-one smoothed cross-covariance ``P_{k,k-1|N} = cov(X_k, X_{k-1} | Z)``
    (eq. 18), needed by the A term of the E-step (eq. 22), is returned in the
    gain form ``P_{k|N} G_{k-1}^T``; :func:`lag_one_recursive` computes it by
    the Shumway-Stoffer backward recursion, and a test checks both agree.

    The inverse of the predicted covariance is taken on the Jacobi-scaled
    matrix (unit diagonal), because position (km^2) and velocity ((km/s)^2)
    variances differ by up to ten orders of magnitude.
Units: as the filter (km, km/s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .ekf import FilterResult, Window


@dataclass
class SmootherResult:
    xs: np.ndarray  # (S, n+1, 6) X_{k|N}
    Ps: np.ndarray  # (S, n+1, 6, 6) P_{k|N}
    Plag: np.ndarray  # (S, n+1, 6, 6) P_{k,k-1|N}; index 0 unused
    G: np.ndarray  # (S, n+1, 6, 6) smoother gains G_k; index n unused


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


def bryson_frazier(f: FilterResult, win: Window, cols: slice = slice(None)) -> SmootherResult:
    """The same smoothed moments by the modified Bryson-Frazier recursion (fast path).

    Backward adjoint recursion that needs no 6x6 inverse (Bierman 1977):
    ``Lt_k = H^T S^-1 H + Ct^T Lh_k Ct``, ``lt_k = -H^T S^-1 nu + Ct^T lh_k``,
    ``Lh_{k-1} = Phi_k^T Lt_k Phi_k``, ``lh_{k-1} = Phi_k^T lt_k`` with
    ``Ct = I - K H``; ``X_{k|N} = X_k - P_k lh_k``, ``P_{k|N} = P_k - P_k Lh_k P_k``.
    Algebraically identical to :func:`rts` (a test checks it); used inside the
    EM iterations. The lag-one covariance is not formed (``Plag`` zeros); use
    :func:`rts` where it is needed. ``cols``: only these state components of the
    smoothed moments (``xs (S, n+1, c)``, ``Ps (S, n+1, c, c)``; the E-step needs the
    position only); each entry is the one of the full moments, bit for bit.
    """
    S, n1 = f.xf.shape[:2]
    n = n1 - 1
    Lh = np.zeros((S, n + 1, 6, 6))
    lh = np.zeros((S, n + 1, 6))
    L = np.zeros((S, 6, 6))
    lv = np.zeros((S, 6))
    HtSi = np.swapaxes(f.Hr, -1, -2) @ f.Sinv  # (S,n+1,3,3)
    HSH = HtSi @ f.Hr
    HSnu = (HtSi @ f.nu[..., None])[..., 0]
    KH = f.K @ f.Hr  # (S,n+1,6,3): the position columns of K H
    I6 = np.broadcast_to(np.eye(6), (S, 6, 6))
    for k in range(n, 0, -1):
        Ct = I6.copy()  # Ct = I - K H of sample k
        Ct[..., :3] -= KH[:, k]
        CtT = np.swapaxes(Ct, -1, -2)
        Lt = CtT @ L @ Ct
        Lt[:, :3, :3] += HSH[:, k]
        lt = (CtT @ lv[..., None])[..., 0]
        lt[:, :3] -= HSnu[:, k]
        Phi = win.Phi[k]
        L = np.matmul(Phi.T @ Lt, Phi, out=Lh[:, k - 1])  # Phi^T Lt Phi, stored in place
        lv = np.matmul(lt, Phi, out=lh[:, k - 1])
    Pr = f.Pf[..., cols, :]
    xs = f.xf[..., cols] - np.einsum("skij,skj->ski", Pr, lh)
    Ps = f.Pf[..., cols, cols] - Pr @ Lh @ f.Pf[..., :, cols]
    Ps = 0.5 * (Ps + np.swapaxes(Ps, -1, -2))
    return SmootherResult(xs, Ps, np.zeros(Ps.shape), np.zeros(Ps.shape))
