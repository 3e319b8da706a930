"""opnav.landing.linalg (the one Cholesky of paper B's kernels) against numpy.linalg over
hypothesis-drawn symmetric positive-definite matrices: the factor, the solve, the log-det, the
in-place factorisation the filter uses, and the failure flag."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from opnav.landing import linalg


def _spd(seed: int, n: int, cond_exp: float) -> np.ndarray:
    """A random SPD matrix (n, n) with eigenvalues spread over 10**cond_exp, scaled by 10**k."""
    rng = np.random.default_rng(seed)
    Qo, _ = np.linalg.qr(rng.normal(size=(n, n)))
    lam = 10.0 ** rng.uniform(-cond_exp / 2, cond_exp / 2, n) * 10.0 ** rng.uniform(-3, 3)
    A = (Qo * lam) @ Qo.T
    return 0.5 * (A + A.T)


CASE = (st.integers(0, 2**31), st.integers(1, 14), st.floats(0.0, 6.0))


@settings(max_examples=60, deadline=None)
@given(*CASE)
def test_cholesky_is_numpys(seed, n, cond_exp):
    A = _spd(seed, n, cond_exp)
    big = np.full((n + 2, n + 2), np.nan)          # a larger scratch: only [:n, :n] is touched
    big[:n, :n] = A
    big[:n, :n][np.triu_indices(n, 1)] = np.nan    # the upper triangle is not read
    C = np.full((n + 2, n + 2), 7.0)
    assert linalg.cholesky_shifted(big, n, 0.0, C)
    L = np.linalg.cholesky(A)
    np.testing.assert_allclose(np.tril(C[:n, :n]), L, rtol=0, atol=1e-12 * np.abs(L).max())
    assert np.all(C[:n, :n][np.triu_indices(n, 1)] == 7.0) and np.all(C[n:] == 7.0)


@settings(max_examples=40, deadline=None)
@given(*CASE)
def test_in_place_factor_equals_the_separate_one(seed, n, cond_exp):
    """The filter factors S in place (C is Q): bit-equal to factoring into a separate array."""
    A = _spd(seed, n, cond_exp)
    C = np.zeros((n, n))
    assert linalg.cholesky_shifted(A, n, 0.0, C)
    S = A.copy()
    assert linalg.cholesky_shifted(S, n, 0.0, S)
    assert np.array_equal(np.tril(S), np.tril(C))


@settings(max_examples=40, deadline=None)
@given(*CASE, st.floats(-1.0, 0.9))
def test_shift_and_failure(seed, n, cond_exp, frac):
    """Q - mu I factors iff mu < lambda_min (away from the boundary)."""
    A = _spd(seed, n, cond_exp)
    lmin = np.linalg.eigvalsh(A)[0]
    mu = frac * lmin
    C = np.empty((n, n))
    assert linalg.cholesky_shifted(A, n, mu, C)
    np.testing.assert_allclose(np.tril(C), np.linalg.cholesky(A - mu * np.eye(n)), rtol=0,
                               atol=1e-11 * np.sqrt(np.abs(A).max()))
    assert not linalg.cholesky_shifted(A, n, 1.1 * lmin, C)
    B = A.copy()
    B[n - 1, n - 1] = np.nan
    assert not linalg.cholesky_shifted(B, n, 0.0, C)


@settings(max_examples=40, deadline=None)
@given(*CASE)
def test_cho_solve_is_numpys(seed, n, cond_exp):
    A = _spd(seed, n, min(cond_exp, 4.0))
    rng = np.random.default_rng(seed + 1)
    b = rng.normal(size=n)
    C = np.empty((n, n))
    assert linalg.cholesky_shifted(A, n, 0.0, C)
    x = b.copy()
    linalg.cho_solve(C, n, x)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-8, atol=1e-8 * np.abs(np.linalg.solve(A, b)).max())


@settings(max_examples=40, deadline=None)
@given(*CASE)
def test_logdet_is_numpys(seed, n, cond_exp):
    A = _spd(seed, n, cond_exp)
    got = linalg.logdet_spd(A, n, np.empty((n, n)))
    sign, want = np.linalg.slogdet(A)
    assert sign == 1.0
    # the jitter is n eps relative to each variance: log det moves by at most ~n^2 eps cond(A)
    assert abs(got - want) <= 1e-9 * max(1.0, abs(want)) + n * n * 2.0**-52 * 10.0**cond_exp
    B = A.copy()
    B[0, 0] = -1.0
    assert linalg.logdet_spd(B, n, np.empty((n, n))) == -np.inf


@settings(max_examples=30, deadline=None)
@given(*CASE)
def test_in_place_is_the_factor_or_nan(seed, n, cond_exp):
    """What the filter's gain and the NEES use: the factor in place where S is SPD, an all-NaN
    block (so the solve is NaN) where it is not."""
    A = _spd(seed, n, cond_exp)
    S = A.copy()
    assert linalg.cholesky_in_place(S, n)
    np.testing.assert_allclose(np.tril(S), np.linalg.cholesky(A), rtol=0, atol=1e-12 * np.sqrt(np.abs(A).max()))
    B = A - 1.1 * np.linalg.eigvalsh(A)[0] * np.eye(n)
    assert not linalg.cholesky_in_place(B, n)
    assert np.isnan(B).all()
    x = np.ones(n)
    linalg.cho_solve(B, n, x)
    assert np.isnan(x).all()
