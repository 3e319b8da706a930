"""The one Kalman predict / update of paper A (approach.kalman) and the batched bound recursion."""

import numpy as np
import pytest

from approach_helpers import approach_cfg, small_window
from opnav.approach import crlb, kalman, pipeline
from opnav.approach import scenario as sc
from opnav.approach.cases import headline_case


def _spd(rng, d, lead=()):
    A = rng.standard_normal(lead + (d, d))
    return A @ np.swapaxes(A, -1, -2) + d * np.eye(d)


def test_update_forms_agree_and_match_the_dense_gaussian_conditioning():
    """Standard and Joseph forms give the same posterior, equal to conditioning the joint
    Gaussian of (x, z) directly; an H on some columns equals the full H with zeros."""
    rng = np.random.default_rng(1)
    S, d = 4, 6
    m, P = rng.standard_normal((S, d)), _spd(rng, d, (S,))
    Hc = rng.standard_normal((S, 3, 3))
    H = np.zeros((S, 3, d))
    H[..., :3] = Hc
    rvar = 0.5 + rng.random((S, 3))
    nu = rng.standard_normal((S, 3))
    a = kalman.condition_on(m, P, Hc, rvar, nu, cols=slice(0, 3))
    b = kalman.condition_on(m, P, H, rvar, nu, joseph=True)
    np.testing.assert_allclose(a.m, b.m, rtol=1e-12)
    np.testing.assert_allclose(a.P, b.P, rtol=1e-10, atol=1e-12)
    for s in range(S):  # dense reference: x | z ~ N(m + P H^T S^-1 nu, P - P H^T S^-1 H P)
        Sm = H[s] @ P[s] @ H[s].T + np.diag(rvar[s])
        G = P[s] @ H[s].T @ np.linalg.inv(Sm)
        np.testing.assert_allclose(a.m[s], m[s] + G @ nu[s], rtol=1e-12)
        np.testing.assert_allclose(a.P[s], P[s] - G @ H[s] @ P[s], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(a.det[s], np.linalg.det(Sm), rtol=1e-12)
        ll = -0.5 * (np.log(np.linalg.det(Sm)) + nu[s] @ np.linalg.solve(Sm, nu[s]) + 3 * np.log(2 * np.pi))
        np.testing.assert_allclose(kalman.innovation_loglik(nu[s], a.Sinv[s], a.det[s]), ll, rtol=1e-12)


def test_predict_with_one_F_per_member_equals_the_loop():
    rng = np.random.default_rng(2)
    F, P, m, Q = rng.standard_normal((5, 6, 6)), _spd(rng, 6, (5,)), rng.standard_normal((5, 6)), _spd(rng, 6)
    mb, Pb = kalman.predict(m, P, F, Q)
    for i in range(5):
        mi, Pi = kalman.predict(m[i], P[i], F[i], Q)
        np.testing.assert_allclose(mb[i], mi, rtol=1e-13)
        np.testing.assert_allclose(Pb[i], Pi, rtol=1e-13)
        np.testing.assert_allclose(Pi, F[i] @ P[i] @ F[i].T + Q, rtol=1e-13)


def test_batched_bound_recursion_equals_each_window_alone():
    win, rng = small_window(n=5, seed=7)
    wins = [small_window(n=5, seed=s)[0] for s in (7, 8, 9)]
    U = [w.u_ref + rng.standard_normal(w.u_ref.shape) for w in wins]
    P0 = [_spd(rng, 6) for _ in wins]
    th = np.array([1e-4, -2e-4, 0.0])
    batch = crlb.crlb_curves(np.stack([w.Phi for w in wins]), np.stack([w.C for w in wins]),
                             np.stack([w.Rvar for w in wins]), win.Q, np.stack(U), np.stack(P0), th, 0.05)
    for i, w in enumerate(wins):
        np.testing.assert_allclose(batch[i], crlb.crlb_curve(w, U[i], P0[i], th, 0.05), rtol=1e-12)


@pytest.mark.parametrize("variant", ["prior", "reference-start"])
def test_segment_bounds_of_many_items_equal_each_alone(variant):
    cfg = approach_cfg(N0=20, N=10, L=3)
    geo = sc.build_geometry(cfg, variant)
    case = headline_case(cfg)
    R1, R2 = geo.measurement_variance(case.sigma3_px), geo.measurement_variance((0.5, 0.5, 1.0))
    items = [(R1, case.truth_arcsec, False), (R2, (5.0, -3.0, 1.0), True)]
    many = pipeline.segment_bounds_many(cfg, geo, items, variant)
    curves = pipeline.bound_curves(cfg, geo, items, variant)
    for (R, th, zq), seg, curve in zip(items, many, curves):
        np.testing.assert_allclose(seg, pipeline.segment_bounds(cfg, geo, R, th, variant, zq), rtol=1e-12)
        np.testing.assert_allclose(curve, pipeline.bound_curve(cfg, geo, R, th, variant, zq), rtol=1e-12)
    assert not np.allclose(many[0], many[1])  # the items differ: a batch that mixed them up would fail


@pytest.mark.parametrize("shape", [(1,), (7,), (40,), (3, 11)])
def test_batched_time_update_gives_each_members_bits(shape):
    """The covariance time update of a batch with one F gives every member the numbers of
    its own update, bit for bit, so batching seeds and cases never changes a covariance.
    (The mean's product is one matrix product over the batch, a vector product for a single
    member: their last bits may differ, so a job's batch is fixed by its seeds and cases.)"""
    rng = np.random.default_rng(len(shape) * 100 + shape[-1])
    F = rng.standard_normal((6, 6)) * np.logspace(-3, 3, 6)
    P = rng.standard_normal(shape + (6, 6))
    P = P @ np.swapaxes(P, -1, -2) * np.logspace(4, -6, 6)  # stiff scales, as km^2 beside (km/s)^2
    Q = np.diag(rng.random(6))
    _, Pb = kalman.predict(None, P, F, Q)
    for i in np.ndindex(shape):
        assert np.array_equal(Pb[i], kalman.predict(None, P[i], F, Q)[1])
