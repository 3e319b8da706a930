"""The Schmidt (consider) EKF that compensates with an uncertain theta_hat (issue 44, item 4)."""

import numpy as np

from opnav.approach import cases, consider
from opnav.approach import scenario as sc
from opnav.approach.ekf import run_filter

from approach_helpers import approach_cfg
from opnav.approach.setup import Setup


def _data(variant="roll", seeds=range(8)):
    cfg = approach_cfg(N0=200, N=50, M=2, L=4)
    cfg["initial_error"]["mode"] = "sampled"
    cfg = Setup.from_config(cfg)
    case = cases.headline_case(cfg)
    geo = sc.build_geometry(cfg, variant)
    return geo, cases.prepare_cases(cfg, variant, [case], seeds, geo=geo), np.asarray(case.truth_arcsec)


def test_zero_theta_covariance_is_the_compensated_ekf():
    geo, d, truth = _data(seeds=range(2))
    th = sc.rad(truth + [1.0, -2.0, 0.5])[None].repeat(2, 0)
    c = consider.run_consider(d.z, th, np.zeros((3, 3)), d.dx0, geo.P0, d.win)
    f = run_filter(d.z, th, d.dx0, geo.P0, d.win, predicted=False)
    np.testing.assert_allclose(c.xf, f.xf, atol=1e-7)
    np.testing.assert_allclose(c.Pf, f.Pf, rtol=1e-7, atol=1e-9)


def test_consider_filter_is_consistent_where_the_compensated_filter_is_not():
    """theta_hat = truth + an error drawn from P_theta (5 arcsec 1-sigma in tx, ty): the filter
    that takes theta_hat as exact is overconfident (position NEES far above 3 over the second
    half), the Schmidt filter carrying P_theta is not (NEES within a chi-square band of 3 dof
    over 8 seeds x 200 correlated samples, generous: below 6). Mutation tried: the theta column
    of H set to zero (the consider term dropped) fails."""
    S = 8
    geo, d, truth = _data(seeds=range(S))
    rng = np.random.default_rng(44)
    sig = np.array([5.0, 5.0, 5.0])
    th = sc.rad(truth + rng.standard_normal((S, 3)) * sig)
    c = consider.run_consider(d.z, th, np.diag(sc.rad(sig) ** 2), d.dx0, geo.P0, d.win, dx_true=geo.dx_true,
                              keep_cov=False)
    f = run_filter(d.z, th, d.dx0, geo.P0, d.win, predicted=False)
    half = d.z.shape[1] // 2
    naive = cases.consistency(f, geo.dx_true).nees_pos[:, half:].mean()
    cons = c.nees_pos[:, half:].mean()
    assert naive > 20.0, naive
    assert 0.3 < cons < 6.0, cons


def _joseph_schmidt_reference(z, theta_hat, P_theta, x0, P0, win, solve=np.linalg.solve):
    """The hand-written Schmidt update consider.py had before issue 56 (numpy, Joseph form with
    the gain's theta rows zeroed), kept as the reference of the one-update form; ``solve``
    (a, b) -> a^-1 b."""
    from opnav.approach.camera import misalignment_small
    from opnav.core.rotations import skew

    S, n = z.shape[0], win.n
    A = misalignment_small(np.broadcast_to(theta_hat, (S, 3)))
    x = np.array(np.broadcast_to(x0, (S, 6)), float)
    P = np.zeros((S, 9, 9))
    P[:, :6, :6] = P0
    P[:, 6:, 6:] = P_theta
    Q = np.zeros((9, 9))
    Q[:6, :6] = win.Q
    Rvar = win.Rvar if win.Rvar.ndim == 3 else np.broadcast_to(win.Rvar[:, None, :], (n + 1, S, 3))
    F, I9, H = np.eye(9), np.eye(9), np.zeros((S, 3, 9))
    xs, Ps = [x], [P[:, :6, :6]]
    for k in range(1, n + 1):
        F[:6, :6] = win.Phi[k]
        x = x @ win.Phi[k].T
        P = F @ P @ F.T + Q
        u = win.u_ref[k] - x[:, :3] @ win.C[k].T
        H[:, :, :3] = -A @ win.C[k]
        H[:, :, 6:] = skew(u)
        nu = z[:, k] - np.einsum("sij,sj->si", A, u)
        R = Rvar[k][:, :, None] * np.eye(3)
        PHt = P @ np.swapaxes(H, 1, 2)
        K = solve(H @ PHt + R, np.swapaxes(PHt, 1, 2)).swapaxes(1, 2)
        K[:, 6:] = 0.0
        x = x + np.einsum("sij,sj->si", K[:, :6], nu)
        IKH = I9 - K @ H
        P = IKH @ P @ np.swapaxes(IKH, 1, 2) + K @ R @ np.swapaxes(K, 1, 2)
        P = 0.5 * (P + np.swapaxes(P, 1, 2))
        xs.append(x)
        Ps.append(P[:, :6, :6])
    return np.stack(xs, 1), np.stack(Ps, 1)


def test_the_update_through_kalman_equals_the_former_joseph_schmidt_update():
    """The consider filter's update is kalman.condition_on (the one measurement update, Joseph
    form) with the theta block put back (issue 56 item 3): on a fixed case (roll, 3 seeds, a
    5-arcsec P_theta, theta_hat off the truth) the means and covariances equal the former
    hand-written Joseph update with a zeroed theta gain to round-off: no farther from it than
    the same former update is from itself with S^-1 applied by an inverse instead of a solve
    (about 4e-10 of the largest mean, 8e-11 of the covariance scale, over 250 samples).
    Mutation tried: the theta block not put back (the full Kalman update) fails."""
    geo, d, truth = _data(seeds=range(3))
    th = sc.rad(truth + np.array([[3.0, -4.0, 1.0], [-2.0, 5.0, 0.0], [0.5, 0.5, -6.0]]))
    P_theta = np.diag(sc.rad(np.array([5.0, 5.0, 8.0])) ** 2)
    c = consider.run_consider(d.z, th, P_theta, d.dx0, geo.P0, d.win)
    xf, Pf = _joseph_schmidt_reference(d.z, th, P_theta, d.dx0, geo.P0, d.win)
    xi, Pi = _joseph_schmidt_reference(d.z, th, P_theta, d.dx0, geo.P0, d.win,
                                       solve=lambda a, b: np.linalg.inv(a) @ b)
    sx = np.abs(xf).max(axis=(0, 1))
    sd = np.sqrt(np.einsum("skii->ski", Pf))
    sP = sd[..., :, None] * sd[..., None, :]

    def dist(a, b, scale):
        return np.abs((a - b) / scale).max()

    assert dist(c.xf, xf, sx) <= 2 * max(dist(xi, xf, sx), 1e-13), (dist(c.xf, xf, sx), dist(xi, xf, sx))
    assert dist(c.Pf, Pf, sP) <= 2 * max(dist(Pi, Pf, sP), 1e-13), (dist(c.Pf, Pf, sP), dist(Pi, Pf, sP))
