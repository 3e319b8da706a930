"""The Schmidt (consider) EKF that compensates with an uncertain theta_hat (issue 44, item 4)."""

import numpy as np

from opnav.approach import cases, consider
from opnav.approach import scenario as sc
from opnav.approach.ekf import run_filter

from approach_helpers import approach_cfg


def _data(variant="roll", seeds=range(8)):
    cfg = approach_cfg(N0=200, N=50, M=2, L=4)
    cfg["initial_error"]["mode"] = "sampled"
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
    naive = cases.consistency(f, geo.dx_true)["nees_pos"][:, half:].mean()
    cons = c.nees_pos[:, half:].mean()
    assert naive > 20.0, naive
    assert 0.3 < cons < 6.0, cons
