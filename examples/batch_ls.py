"""A misalignment estimator of one's own: batch least squares (docs/usage.md, "Your own method").

Linearised at theta = 0 and the reference trajectory (paper A eq. 3, 5), a measurement is
    z_k - u_ref_k = -C_k dr_k + [u_ref_k x] theta + v_k,   dr_k = (Phi_k ... Phi_1 dX_0)[:3],
linear in the unknowns y = (dX_0, theta): one weighted least-squares solve over the whole window
with the start's prior N(x0, P0) and a diffuse prior on theta, ignoring the process noise.
Returns theta (rad) and its covariance (rad^2).
"""
import numpy as np


def estimate(p):
    A = np.zeros((9, 9))                         # normal matrix of y = (dX_0 (km, km/s), theta (rad))
    b = np.zeros(9)
    P0i = np.linalg.inv(p.P0)
    A[:6, :6], b[:6] = P0i, P0i @ p.x0           # the start's prior
    w = p.theta_prior_sigma_rad ** -2
    A[6:, 6:], b[6:] = w * np.eye(3), w * p.theta0
    T = np.eye(6)                                # Phi_k ... Phi_1: sample 0 -> sample k
    for k in range(1, len(p.z)):
        T = p.Phi[k] @ T
        u = p.u_ref[k]
        H = np.hstack([-p.C[k] @ T[:3], [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]]])
        Wk = 1.0 / p.Rvar[k]
        A += H.T @ (Wk[:, None] * H)
        b += H.T @ (Wk * (p.z[k] - u))
    d = 1.0 / np.sqrt(np.diag(A))                # Jacobi scaling: km, km/s and rad differ by 1e9
    cov = d[:, None] * np.linalg.inv(d[:, None] * A * d[None, :]) * d[None, :]
    y = cov @ b
    return y[6:], cov[6:, 6:]
