"""Finite-difference checks of the bearing Jacobians (paper B eq. 15-18), of
the attitude-error convention R_LtoB_true = Exp(-dtheta) R_LtoB_est, and of the
batched / tangent-plane forms of opnav.landing.measurement (the one numpy home
of eq. 12-18; its CasADi cross-check is in test_landing_metrics.py)."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from opnav.landing.measurement import (BehindCameraError, bearing, bearing_jacobian,
                                       selection_jacobian, tangent_basis, tangent_jacobian,
                                       tangent_jacobian_scalar)
from opnav.core.rotations import exp_so3, skew


def _case(seed):
    rng = np.random.default_rng(seed)
    r = rng.uniform(-5000, 5000, 3) + np.array([0, 0, 6000.0])
    p = np.r_[rng.uniform(-8000, 8000, 2), 0.0]
    R = Rotation.random(random_state=rng).as_matrix()
    return r, R, p


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000))
def test_jacobians_match_central_differences(seed):
    r, R, p = _case(seed)
    Hr, Ht, Hp = bearing_jacobian(r, R, p)
    h, ha = 1e-2, 1e-6
    for j in range(3):
        e = np.eye(3)[j]
        fd_r = (bearing(r + h * e, R, p) - bearing(r - h * e, R, p)) / (2 * h)
        fd_p = (bearing(r, R, p + h * e) - bearing(r, R, p - h * e)) / (2 * h)
        # attitude error on the body side: R_true = Exp(-dtheta) R_est
        fd_t = (bearing(r, exp_so3(-ha * e) @ R, p) - bearing(r, exp_so3(ha * e) @ R, p)) / (2 * ha)
        np.testing.assert_allclose(Hr[:, j], fd_r, rtol=1e-5, atol=1e-10)
        np.testing.assert_allclose(Hp[:, j], fd_p, rtol=1e-5, atol=1e-10)
        np.testing.assert_allclose(Ht[:, j], fd_t, rtol=1e-5, atol=1e-9)


def test_bearing_is_unit_and_points_at_landmark():
    r, R, p = _case(3)
    b = bearing(r, R, p)
    assert np.isclose(np.linalg.norm(b), 1.0)
    np.testing.assert_allclose(R.T @ b, (p - r) / np.linalg.norm(p - r), atol=1e-12)


def test_zero_range_is_a_clear_error():
    with pytest.raises(BehindCameraError):
        bearing(np.zeros(3), np.eye(3), np.zeros(3))
    with pytest.raises(ValueError):
        bearing(np.array([np.nan, 0, 0]), np.eye(3), np.zeros(3))


def _batch(seed, shape):
    rng = np.random.default_rng(seed)
    r = rng.uniform(-5000, 5000, shape + (3,)) + np.array([0, 0, 6000.0])
    p = np.concatenate([rng.uniform(-8000, 8000, shape + (2,)), np.zeros(shape + (1,))], axis=-1)
    R = Rotation.random(int(np.prod(shape)), random_state=seed).as_matrix().reshape(shape + (3, 3))
    return r, R, p


def test_jacobians_batch_over_leading_dims_with_the_bits_of_one_at_a_time():
    """runs x candidates: the same numbers as one landmark at a time (a batched
    caller reproduces a sequential one), broadcasting a per-run pose."""
    r, R, p = _batch(7, (3, 4))
    Hr, Ht, Hp = bearing_jacobian(r[:, :1], R[:, :1], p)     # pose (3, 1) broadcast over 4 candidates
    assert Hr.shape == (3, 4, 3, 3)
    for i in range(3):
        for j in range(4):
            one = bearing_jacobian(r[i, 0], R[i, 0], p[i, j])
            for got, want in zip((Hr[i, j], Ht[i, j], Hp[i, j]), one):
                assert np.array_equal(got, want)
            assert np.array_equal(bearing(r[:, :1], R[:, :1], p)[i, j], bearing(r[i, 0], R[i, 0], p[i, j]))


def test_eq16_identity_and_selection_jacobian_layout():
    """H_theta = H_C [rho x] R^T (eq. 16 as printed) = [b x]; H rows of the
    known landmark have no landmark columns; v columns are zero."""
    r, R, p = _case(5)
    Hr, Ht, Hp = bearing_jacobian(r, R, p)
    rho = p - r
    np.testing.assert_allclose(Ht, Hp @ skew(rho) @ R.T, atol=1e-13)
    pk = np.array([10.0, -20.0, 0.0])
    H = selection_jacobian(r, R, pk, np.stack([p, p + 100.0]))
    assert H.shape == (2, 6, 12)
    assert np.all(H[:, :, 3:6] == 0) and np.all(H[:, 0:3, 9:12] == 0)
    Hk = bearing_jacobian(r, R, pk)
    assert np.array_equal(H[0, 0:3, 0:3], Hk[0]) and np.array_equal(H[0, 0:3, 6:9], Hk[1])
    assert np.array_equal(H[0, 3:6, 0:3], Hr) and np.array_equal(H[0, 3:6, 9:12], Hp)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.1, 1e4))
def test_tangent_jacobian_is_the_projected_candidate_rows(seed, scale):
    """G = scale T^T H_c with T = R [t1, t2] orthonormal and orthogonal to b; its
    float-arithmetic twin gives the same bits."""
    r, R, p = _batch(seed, (5,))
    p[0] = r[0] + np.array([1e-3, -2e-3, -3000.0])        # near-nadir: the e_x branch
    G = tangent_jacobian(r, R, p, scale)
    u = (p - r) / np.linalg.norm(p - r, axis=1)[:, None]
    t1, t2 = tangent_basis(u)
    np.testing.assert_allclose(np.einsum("ni,ni->n", t1, u), 0, atol=1e-15)
    np.testing.assert_allclose(np.einsum("ni,ni->n", t2, u), 0, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(t1, axis=1), 1, atol=1e-15)
    TB = np.stack([t1, t2], axis=-1)                       # (n, 3, 2) in {L}
    H = selection_jacobian(r, R, np.zeros(3), p)[:, 3:6]   # candidate rows
    want = scale * np.swapaxes(R @ TB, -1, -2) @ H
    np.testing.assert_allclose(G, want, rtol=0, atol=1e-12 * np.abs(want).max())
    for k in range(5):
        d = (p[k] - r[k]).tolist()
        rho = float(np.sqrt(np.sum((p[k] - r[k]) ** 2)))
        assert np.array_equal(tangent_jacobian_scalar(R[k].tolist(), *d, rho, scale), G[k])


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.floats(1.0, 2e4))
def test_kernels_are_eq_12_and_18_as_printed(seed, dist):
    """The compiled blocks against the paper's printed forms: b = R rho / |rho|
    (eq. 12), H_C = R (|rho|^2 I - rho rho^T) / |rho|^3 (eq. 18); the kernel's
    inverse range; the tangent rows (one landmark) equal the batched form."""
    from opnav.landing.measurement import blocks, line_of_sight, tangent_rows

    rng = np.random.default_rng(seed)
    r = rng.normal(size=3) * 1000
    rho = rng.normal(size=3)
    rho *= dist / np.linalg.norm(rho)
    p = r + rho
    rho = p - r                                        # exactly what the kernel sees
    R = Rotation.random(random_state=rng).as_matrix()
    u = np.empty(3)
    inv = line_of_sight(r, p, u)
    n = np.linalg.norm(rho)
    np.testing.assert_allclose(inv, 1 / n, rtol=1e-14)
    b, HC = np.empty(3), np.empty((3, 3))
    blocks(R, u, inv, b, HC)
    np.testing.assert_allclose(b, R @ rho / n, atol=1e-14)
    want = R @ (n**2 * np.eye(3) - np.outer(rho, rho)) / n**3
    np.testing.assert_allclose(HC, want, rtol=0, atol=1e-13 * np.abs(want).max())
    G = np.empty((2, 12))
    tangent_rows(R, p - r, 3.0, G)
    np.testing.assert_array_equal(G, tangent_jacobian(r, R, p, 3.0))
    assert line_of_sight(r, r, u) == 0.0 and np.isnan(line_of_sight(r, p + np.nan, u))
