"""The EM-EKF kernels' layouts and batched products give the same bits as the plain forms.

The Monte-Carlo pickles of paper A must not move when the kernels are made faster (the EM
is round-off sensitive): each fast path here is checked bit for bit against the formula it
replaces (the seed-major filter loop, the stacked 6x6 products, the scalar cofactors), and
the filter, smoother and EM map against the same rows run alone (a batch row's numbers do
not depend on the other rows, so the job layout cannot move them).
"""

import numpy as np
import pytest

from approach_helpers import small_window
from opnav.approach import em, kalman
from opnav.approach.camera import misalignment_small
from opnav.approach.ekf import POS, run_filter
from opnav.approach.smoother import bryson_frazier


def _spd(rng, d, lead=()):
    A = rng.standard_normal(lead + (d, d))
    return A @ np.swapaxes(A, -1, -2) + d * np.eye(d)


@pytest.mark.parametrize("S", [1, 2, 7, 80, 333])
def test_predict_single_product_equals_the_stacked_products_bit_for_bit(S):
    rng = np.random.default_rng(S)
    P = _spd(rng, 6, (S,)) * 10.0 ** rng.integers(-8, 8, (S, 1, 1))
    F = np.eye(6) + 0.3 * rng.standard_normal((6, 6))
    Q = np.diag(rng.random(6))
    m = rng.standard_normal((S, 6))
    m1, P1 = kalman.predict(m, P, F, Q)
    ref = np.stack([F @ P[s] @ F.T for s in range(S)]) + Q  # one gemm pair per member
    assert np.array_equal(P1, ref) and np.array_equal(P1, F @ P @ F.T + Q)
    assert np.array_equal(m1, m @ F.T)


def _inv_sym3_scalar(M):
    """The cofactor inverse written out entry by entry (the form inv_sym3 vectorises)."""
    a, b, c = M[..., 0, 0], M[..., 0, 1], M[..., 0, 2]
    d, e, f = M[..., 1, 1], M[..., 1, 2], M[..., 2, 2]
    A00, A01, A02 = d * f - e * e, c * e - b * f, b * e - c * d
    A11, A12, A22 = a * f - c * c, b * c - a * e, a * d - b * b
    det = a * A00 + b * A01 + c * A02
    r = 1.0 / det
    out = np.empty_like(M)
    out[..., 0, 0], out[..., 1, 1], out[..., 2, 2] = A00 * r, A11 * r, A22 * r
    out[..., 0, 1] = out[..., 1, 0] = A01 * r
    out[..., 0, 2] = out[..., 2, 0] = A02 * r
    out[..., 1, 2] = out[..., 2, 1] = A12 * r
    return out, det


@pytest.mark.parametrize("lead", [(), (1,), (40,), (5, 7)])
def test_inv_sym3_equals_the_scalar_cofactors_bit_for_bit(lead):
    rng = np.random.default_rng(len(lead))
    M = _spd(rng, 3, lead) * 10.0 ** rng.integers(-6, 6, lead + (1, 1))
    inv, det = kalman.inv_sym3(M)
    ref_inv, ref_det = _inv_sym3_scalar(M)
    assert np.array_equal(inv, ref_inv) and np.array_equal(det, ref_det)
    np.testing.assert_allclose(inv @ M, np.broadcast_to(np.eye(3), M.shape), atol=1e-9)


def _reference_filter(z, theta, x0, P0, win):
    """The seed-major EKF loop (opnav 6ee2648), kept as the reference of run_filter's bits."""
    S, n = z.shape[0], win.n
    A = misalignment_small(theta)
    Hrs = -(A[:, None, :, 0, None] * win.C[None, :, None, 0, :] + A[:, None, :, 1, None] * win.C[None, :, None, 1, :]
            + A[:, None, :, 2, None] * win.C[None, :, None, 2, :])
    d = z - np.einsum("sij,kj->ski", A, win.u_ref)
    xf, Pf = np.empty((S, n + 1, 6)), np.empty((S, n + 1, 6, 6))
    x, P = np.array(x0, float), np.broadcast_to(P0, (S, 6, 6)).copy()
    xf[:, 0], Pf[:, 0] = x, P
    Ks, Sinvs, nus, dets = (np.zeros((S, n + 1, 6, 3)), np.zeros((S, n + 1, 3, 3)), np.zeros((S, n + 1, 3)),
                            np.ones((S, n + 1)))
    for k in range(1, n + 1):
        x, P = x @ win.Phi[k].T, win.Phi[k] @ P @ win.Phi[k].T + win.Q
        nu = d[:, k] - (Hrs[:, k] @ x[:, :3, None])[..., 0]
        x, P, K, Sinv, det = kalman.condition_on(x, P, Hrs[:, k], win.Rvar[k], nu, cols=POS)
        xf[:, k], Pf[:, k] = x, P
        Ks[:, k], Sinvs[:, k], nus[:, k], dets[:, k] = K, Sinv, nu, det
    ll = kalman.innovation_loglik(nus[:, 1:], Sinvs[:, 1:], dets[:, 1:]).sum(1)
    return xf, Pf, Ks, Sinvs, nus, Hrs, ll


def _batch(S=9, n=40, seed=2):
    win, rng = small_window(n=n, seed=seed)
    z = rng.standard_normal((S, n + 1, 3)) + win.u_ref
    theta = 1e-3 * rng.standard_normal((S, 3))
    x0 = rng.standard_normal((S, 6))
    P0 = _spd(rng, 6, (S,))
    return z, theta, x0, P0, win


def test_time_major_filter_equals_the_seed_major_loop_bit_for_bit():
    z, theta, x0, P0, win = _batch()
    f = run_filter(z, theta, x0, P0, win, predicted=False)
    xf, Pf, Ks, Sinvs, nus, Hrs, ll = _reference_filter(z, theta, x0, P0, win)
    for got, ref in ((f.xf, xf), (f.Pf, Pf), (f.K, Ks), (f.Sinv, Sinvs), (f.nu, nus), (f.Hr, Hrs), (f.loglik, ll)):
        assert got.shape == ref.shape and np.array_equal(got, ref)
    fp = run_filter(z, theta, x0, P0, win, predicted=True)
    assert np.array_equal(fp.Pf, Pf) and fp.Pp.shape == Pf.shape and np.array_equal(fp.Pp[:, 0], np.zeros_like(P0))


@pytest.mark.parametrize("rows", [[0, 1], [3, 4, 5], [8, 1]])
def test_filter_smoother_and_em_map_of_a_row_do_not_depend_on_the_other_rows(rows):
    """A row run alone (or with others) gives the bits it has in the whole batch, per-seed
    variances (Rvar (n+1, S, 3)) included: a job's grouping of cases cannot move its numbers.
    (Two rows or more: a lone row's smoothed mean differs in its last bits, the einsum of
    bryson_frazier taking another inner loop for S = 1, as before the time-major layout.)"""
    z, theta, x0, P0, win = _batch()
    S = z.shape[0]
    win_s = type(win)(win.Phi, win.C, win.u_ref, np.repeat(win.Rvar[:, None], S, axis=1), win.Q)
    for w, wsub in ((win, win), (win_s, type(win)(win.Phi, win.C, win.u_ref, win_s.Rvar[:, rows], win.Q))):
        full = em.em_map(theta, z, x0, P0, w, 1e-6)
        part = em.em_map(theta[rows], z[rows], x0[rows], P0[rows], wsub, 1e-6)
        assert np.array_equal(part[0], full[0][rows]) and np.array_equal(part[1], full[1][rows])
        fs, fp = full[4], part[4]
        assert np.array_equal(fp.xs, fs.xs[rows]) and np.array_equal(fp.Ps, fs.Ps[rows])
        assert np.array_equal(part[3].Pf, full[3].Pf[rows])
    s_full = bryson_frazier(run_filter(z, theta, x0, P0, win, predicted=False), win)
    s_one = bryson_frazier(run_filter(z[rows], theta[rows], x0[rows], P0[rows], win, predicted=False), win)
    assert np.array_equal(s_one.xs, s_full.xs[rows]) and np.array_equal(s_one.Ps, s_full.Ps[rows])
