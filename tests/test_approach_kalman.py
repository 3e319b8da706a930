"""The one Kalman predict / update of paper A (approach.kalman) and the batched bound recursion."""

import numpy as np
import pytest

from approach_helpers import approach_setup, random_filter_problem, small_window
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
    cfg = approach_setup(N0=20, N=10, L=3)
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


# ----------------------------------------------------------------- compiled steps vs references
from hypothesis import given, settings, strategies as st  # noqa: E402


def _dense_update(m, P, H, rvar, nu):
    """x | z of the joint Gaussian: m + G nu, P - G H P, det S with G = P H^T S^-1 (numpy)."""
    Sm = H @ P @ H.T + np.diag(rvar)
    G = P @ H.T @ np.linalg.inv(Sm)
    return m + G @ nu, P - G @ H @ P, np.linalg.det(Sm), G


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), d=st.integers(3, 9), lead=st.sampled_from([(), (1,), (4,), (2, 3)]),
       joseph=st.booleans(), scale=st.sampled_from([1e-6, 1.0, 1e4]))
def test_condition_on_equals_dense_conditioning_over_random_inputs(seed, d, lead, joseph, scale):
    """The compiled update (any contiguous column block, either form, batched or not)
    equals conditioning the joint Gaussian in numpy, with H zero outside its columns."""
    rng = np.random.default_rng(seed)
    c = int(rng.integers(1, d - 1)) if d > 3 else 3
    c = max(c, 1)
    c0 = int(rng.integers(0, d - c + 1))
    m = rng.standard_normal(lead + (d,))
    P = _spd(rng, d, lead) * scale
    Hc = rng.standard_normal(lead + (3, c))
    rvar = (0.5 + rng.random(lead + (3,))) * scale
    nu = rng.standard_normal(lead + (3,))
    u = kalman.condition_on(m, P, Hc, rvar, nu, cols=slice(c0, c0 + c), joseph=joseph)
    assert u.P.shape == lead + (d, d) and u.K.shape == lead + (d, 3)
    for i in np.ndindex(lead):
        H = np.zeros((3, d))
        H[:, c0:c0 + c] = Hc[i]
        mr, Pr, det, G = _dense_update(m[i], P[i], H, rvar[i], nu[i])
        tol = 1e-9 * np.abs(P[i]).max()
        np.testing.assert_allclose(u.m[i], mr, rtol=1e-9, atol=1e-9 * np.abs(mr).max())
        np.testing.assert_allclose(u.P[i], Pr, rtol=1e-7, atol=tol)
        assert np.array_equal(u.P[i], u.P[i].T)  # symmetrised
        np.testing.assert_allclose(u.K[i], G, rtol=1e-9, atol=1e-9 * np.abs(G).max())
        np.testing.assert_allclose(u.det[i], det, rtol=1e-9)
        np.testing.assert_allclose(u.Sinv[i] @ (H @ P[i] @ H.T + np.diag(rvar[i])), np.eye(3), atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), d=st.integers(1, 9), lead=st.sampled_from([(), (1,), (5,), (2, 3)]),
       per_member_F=st.booleans(), with_mean=st.booleans())
def test_predict_equals_numpy_over_random_inputs(seed, d, lead, per_member_F, with_mean):
    rng = np.random.default_rng(seed)
    F = rng.standard_normal((lead if per_member_F else ()) + (d, d))
    P, Q = _spd(rng, d, lead), _spd(rng, d)
    m = rng.standard_normal(lead + (d,)) if with_mean else None
    mo, Po = kalman.predict(m, P, F, Q)
    np.testing.assert_allclose(Po, F @ P @ np.swapaxes(F, -1, -2) + Q, rtol=1e-12, atol=1e-12 * np.abs(Po).max())
    if with_mean:
        np.testing.assert_allclose(mo, np.einsum("...ij,...j->...i", F, m), rtol=1e-12, atol=1e-12 * np.abs(mo).max())
    else:
        assert mo is None


def _numpy_ekf(z, theta, x0, P0, win, s):
    """The EM-EKF of seed ``s`` written with numpy.linalg (an independent reference)."""
    from opnav.approach.camera import misalignment_small

    A = misalignment_small(theta[s][None])[0]
    R = win.Rvar[:, s] if win.Rvar.ndim == 3 else win.Rvar
    x, P, ll = x0[s].copy(), P0.copy(), 0.0
    xs, Ps = [x], [P]
    for k in range(1, win.n + 1):
        x, P = win.Phi[k] @ x, win.Phi[k] @ P @ win.Phi[k].T + win.Q
        H = np.zeros((3, 6))
        H[:, :3] = -A @ win.C[k]
        Sm = H @ P @ H.T + np.diag(R[k])
        nu = z[s, k] - A @ (win.u_ref[k] - win.C[k] @ x[:3])
        x, P, det, _ = _dense_update(x, P, H, R[k], nu)
        ll += -0.5 * (np.log(det) + nu @ np.linalg.solve(Sm, nu) + 3 * np.log(2 * np.pi))
        xs.append(x)
        Ps.append(P)
    return np.array(xs), np.array(Ps), ll


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), S=st.integers(1, 4), n=st.integers(1, 10), per_seed=st.booleans(),
       predicted=st.booleans())
def test_filter_window_equals_a_numpy_ekf_over_random_windows(seed, S, n, per_seed, predicted):
    """The compiled window pass of the EM-EKF (run_filter) equals a plain numpy EKF seed by
    seed: filtered moments, log-likelihood and the last sample's K H."""
    from opnav.approach import ekf

    win, _, z, theta, x0, P0 = random_filter_problem(seed, S, n, per_seed)
    f = ekf.run_filter(z, theta, x0, P0, win, predicted=predicted)
    assert (f.xp is not None) == predicted
    for s in range(S):
        xs, Ps, ll = _numpy_ekf(z, theta, x0, P0, win, s)
        np.testing.assert_allclose(f.xf[s], xs, rtol=1e-9, atol=1e-9 * np.abs(xs).max())
        np.testing.assert_allclose(f.Pf[s], Ps, rtol=1e-8, atol=1e-9 * np.abs(Ps).max())
        np.testing.assert_allclose(f.loglik[s], ll, rtol=1e-10)
        KH = np.zeros((6, 6))
        KH[:, :3] = f.K[s, -1] @ f.Hr[s, -1]
        np.testing.assert_allclose(f.KH_last[s], KH, rtol=1e-12, atol=1e-14 * np.abs(KH).max())
        assert not KH[:, 3:].any() and KH[:, :3].any()
        if predicted:
            np.testing.assert_allclose(f.Pp[s, 1:], win.Phi[1:] @ Ps[:-1] @ np.swapaxes(win.Phi[1:], -1, -2) + win.Q,
                                       rtol=1e-9, atol=1e-9 * np.abs(Ps).max())


def test_a_broken_filter_stops_with_one_clear_error():
    """A non-positive innovation covariance (negative variances) raises instead of going on."""
    from opnav.approach import ekf

    win, rng = small_window(n=3, seed=1)
    win = ekf.Window(win.Phi, win.C, win.u_ref, -1e6 * np.ones_like(win.Rvar), win.Q)
    with pytest.raises(FloatingPointError, match="not positive definite"):
        ekf.run_filter(np.zeros((1, 4, 3)), np.zeros((1, 3)), np.zeros((1, 6)), np.eye(6), win)
