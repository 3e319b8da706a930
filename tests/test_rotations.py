"""opnav.core.rotations: hat map, SO(3) exp / log against scipy, batching over
leading dimensions (same bits as one vector at a time), small-angle branch."""

import numpy as np
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from opnav.core.rotations import cross, exp_so3, log_so3, skew


def _vectors(seed, shape, scale):
    rng = np.random.default_rng(seed)
    return rng.normal(size=shape + (3,)) * scale


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from([1e-9, 1e-5, 1e-2, 1.0, 3.0]))
def test_exp_matches_scipy_and_log_inverts_it(seed, scale):
    phi = _vectors(seed, (7,), scale)
    n = np.linalg.norm(phi, axis=-1, keepdims=True)
    phi = np.where(n > 3.0, phi * (3.0 / n), phi)   # log: angles below pi
    R = exp_so3(phi)
    np.testing.assert_allclose(R, Rotation.from_rotvec(phi).as_matrix(), rtol=0, atol=2e-15)
    np.testing.assert_allclose(log_so3(R), Rotation.from_matrix(R).as_rotvec(), rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(log_so3(R), phi, rtol=1e-9, atol=1e-15)


def test_batched_over_leading_dims_gives_the_same_bits_as_one_at_a_time():
    phi = _vectors(1, (4, 5), 1e-2)
    phi[0, 0] = 0.0           # the small-angle branch inside a batch
    phi[1, 2] *= 1e-7
    R = exp_so3(phi)
    assert R.shape == (4, 5, 3, 3)
    one = np.array([[exp_so3(p) for p in row] for row in phi])
    assert np.array_equal(R, one)
    w = log_so3(R)
    assert w.shape == (4, 5, 3)
    assert np.array_equal(w, np.array([[log_so3(r) for r in row] for row in R]))
    S = skew(phi)
    assert S.shape == (4, 5, 3, 3)
    assert np.array_equal(S, np.array([[skew(p) for p in row] for row in phi]))


def test_skew_is_the_cross_product_and_exp_is_first_order_i_plus_skew():
    a, b = _vectors(2, (2,), 1.0)
    np.testing.assert_allclose(skew(a) @ b, np.cross(a, b), atol=1e-15)
    np.testing.assert_allclose(skew(a), -skew(a).T)
    d = np.array([1e-7, -2e-7, 3e-7])
    np.testing.assert_allclose(exp_so3(d), np.eye(3) + skew(d), atol=1e-13)
    # exp of the rotation vector rotates about it (active): axis fixed, e_x -> e_y for +90 deg about z
    np.testing.assert_allclose(exp_so3(np.array([0, 0, np.pi / 2])) @ [1.0, 0, 0], [0, 1, 0], atol=1e-15)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from([(), (5,), (4, 1), (3, 7)]), st.sampled_from([(), (7,), (1, 7), (3, 7)]))
def test_cross_is_numpys_bit_for_bit_under_broadcasting(seed, sa, sb):
    """rotations.cross: np.cross's values to the bit, on broadcast shapes (the batched
    planner's (runs, 1, 3) x (runs, n, 3)), with exact zeros among the components."""
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=sa + (3,)), rng.normal(size=sb + (3,))
    a[..., 2] = 0.0 if seed % 2 else a[..., 2]
    try:
        want = np.cross(a, b)
    except ValueError:                 # shapes that do not broadcast
        return
    got = cross(a, b)
    assert got.shape == want.shape and np.array_equal(got, want)
