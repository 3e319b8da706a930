"""Paper B depth-estimation-error model (eq. 19-26) and the golden-section planner."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from opnav.landing.planning import depth as D
from opnav.landing.planning import geometry as G
from opnav.landing.planning import reference as de
from opnav.landing.planning import search as S
from opnav.landing.planning.layout import DEPTH, Q_B, Q_KIND, Q_RE
from opnav.landing.planner import PlannerConfig, golden_section


def _compiled_objective(geom, b, r_e):
    """The compiled depth objective (search.objective, kind depth) as f(beta)."""
    q = geom.q
    q[Q_KIND], q[Q_B], q[Q_RE] = DEPTH, b, r_e
    return lambda x: S.objective(float(x), q)


def _intersect_2d(p1, d1, p2, d2):
    """Parameter s where the lines p1 + s d1 and p2 + t d2 cross (2-D)."""
    A = np.column_stack([d1, -d2])
    s, _ = np.linalg.solve(A, p2 - p1)
    return s


@settings(max_examples=60, deadline=None)
@given(beta=st.floats(0.05, 1.3), alpha=st.floats(0.2, 1.6), cd=st.floats(500, 20000),
       b=st.floats(20, 200), r_e=st.floats(0.1, 30))
def test_depth_error_equals_triangulation_with_a_perturbed_baseline(beta, alpha, cd, b, r_e):
    """Independent construction in the observation plane: C at the origin, the
    velocity along +x; the landmark p seen at angle beta, D on the velocity line
    with the angle alpha at D. Observe p from C and from C + b (along the
    velocity); shift the second line of sight sideways by +-r_e (the error ball)
    and triangulate: the two depths along the first line differ by dr."""
    if alpha + beta >= math.pi - 0.05:
        return
    C = np.zeros(2)
    D = np.array([cd, 0.0])
    u1 = np.array([math.cos(beta), math.sin(beta)])
    # p on the first line of sight with angle alpha at D
    d = cd * math.sin(alpha) / math.sin(alpha + beta)
    p = C + d * u1
    ang_D = math.acos(np.clip((C - D) @ (p - D) / (np.linalg.norm(C - D) * np.linalg.norm(p - D)), -1, 1))
    assert math.isclose(ang_D, alpha, rel_tol=1e-9, abs_tol=1e-9)
    C2 = np.array([b, 0.0])
    u2 = (p - C2) / np.linalg.norm(p - C2)
    n2 = np.array([-u2[1], u2[0]])
    depths = [_intersect_2d(C, u1, C2 + s * r_e * n2, u2) for s in (-1, 1)]   # signed, along u1
    expected = abs(depths[1] - depths[0])
    got = float(de.depth_error(beta, alpha, cd, b, r_e))
    assert got == pytest.approx(expected, rel=1e-5)


def test_compiled_objective_equals_the_papers_formula():
    """search.objective (eq. 26 ground point, eq. 23-25 at its range) equals the
    paper's law-of-sines formula over the whole signed-beta range, +inf (never
    NaN) outside the ground arc; the ground points lie on z = 0."""
    r = np.array([3000.0, 5000.0, 6000.0])
    v = np.array([-56.0, -66.0, -90.0])
    a = np.array([0.6, 0.2, 0.7])
    geom = G.plane_geometry(r, v)
    P = np.diag([1e4] * 3 + [4.0, 9.0, 1.0] + [1e-4] * 3 + [1e4] * 3)
    cfg = PlannerConfig()
    betas = np.linspace(-(math.pi - geom.gamma) - 0.1, geom.gamma + 0.1, 401)
    b = D.baseline(v, a, cfg.t_s)
    assert b == pytest.approx(np.linalg.norm(v + 0.5 * a))
    r_e = D.error_radius(P[3:6, 3:6], cfg.t_s, cfg.n_sigma_v)
    assert r_e == pytest.approx(3 * 3.0 * 1.0)
    f = _compiled_objective(geom, b, r_e)
    vec = de.signed_depth_error(betas, geom, b, r_e)
    sca = np.array([f(x) for x in betas])
    np.testing.assert_allclose(sca, vec, rtol=1e-10)
    assert np.isinf(vec[0]) and np.isinf(vec[-1]) and not np.isnan(sca).any()
    g = G.ground_points(betas, geom)
    fin = np.isfinite(g[:, 0])
    np.testing.assert_allclose(g[fin, 2], 0, atol=1e-6)
    sel = fin & np.isfinite(vec)
    m = de.depth_error_at_landmarks(r, v, a, g[sel], cfg.t_s, r_e)
    np.testing.assert_allclose(m, vec[sel], rtol=1e-6)


@settings(max_examples=80, deadline=None)
@given(x=st.floats(-5e3, 5e3), y=st.floats(-5e3, 5e3), z=st.floats(50, 8e3),
       vx=st.floats(-100, 100), vy=st.floats(-100, 100), vz=st.floats(-120, -0.5),
       beta=st.floats(-3.0, 1.5), pv=st.floats(0.01, 100), t_s=st.floats(0.1, 2.0))
def test_compiled_depth_error_matches_the_paper_over_drawn_states(x, y, z, vx, vy, vz, beta, pv, t_s):
    """Hypothesis-drawn states: compiled objective vs the paper's vectorised
    formula at signed beta (relative 1e-8 where finite, both infinite together),
    and the compiled score at the ground point's landmark vs the triangle-angle
    form (depth_error_at_landmarks), which the edge rule scores landmarks by."""
    r, v, a = np.array([x, y, z]), np.array([vx, vy, vz]), np.array([0.3, -0.2, 1.0])
    geom = G.plane_geometry(r, v)
    b = D.baseline(v, a, t_s)
    r_e = D.error_radius(pv * np.eye(3), t_s, 3.0)
    got = _compiled_objective(geom, b, r_e)(beta)
    want = float(de.signed_depth_error(beta, geom, b, r_e))
    assert np.isinf(got) == np.isinf(want)
    if np.isfinite(want):
        assert got == pytest.approx(want, rel=1e-8)
    if np.isfinite(want) and abs(beta) > 1e-6:   # (a ground point does not hold a smaller angle)
        p = G.ground_points(beta, geom)
        q = geom.q
        q[Q_KIND], q[Q_B], q[Q_RE] = DEPTH, b, r_e
        at_point = S.score_point(*p[0], q)              # the edge rule's form: range and angle
        assert at_point == pytest.approx(got, rel=1e-6)
        if abs(beta) > 1e-3:                            # (the triangle form's arccos: eps / beta^2)
            assert float(de.depth_error_at_landmarks(r, v, a, p, t_s, r_e)[0]) == pytest.approx(at_point, rel=1e-6)


@pytest.mark.parametrize("interval", [(-1.5, -0.01), (0.01, 0.7), (-0.35, -1e-9)])
def test_golden_section_matches_dense_grid(interval):
    r = np.array([2000.0, 3000.0, 4000.0])
    v = np.array([-40.0, -60.0, -70.0])
    geom = G.plane_geometry(r, v)
    f = _compiled_objective(geom, D.baseline(v, np.zeros(3), 1.0), 3.0)
    a, b = interval
    x, fx, n = golden_section(f, a, b, 1e-6)
    grid = np.linspace(a, b, 200001)
    vals = de.signed_depth_error(grid, geom, D.baseline(v, np.zeros(3), 1.0), 3.0)
    i = int(np.argmin(vals))
    assert abs(x - grid[i]) < 1e-4
    assert fx == pytest.approx(vals[i], rel=1e-5)
    assert 20 < n < 60


def test_golden_section_counts_and_bad_inputs():
    calls = []

    def f(x):
        calls.append(x)
        return (x - 0.3) ** 2

    x, fx, n = golden_section(f, 0.0, 1.0, 1e-3)
    assert abs(x - 0.3) < 1e-3 and n == len(calls)
    with pytest.raises(ValueError):
        golden_section(f, 1.0, 0.0, 1e-3)
    with pytest.raises(ValueError):
        golden_section(f, 0.0, 1.0, 0.0)


def test_bad_inputs_are_clear_errors_or_documented_values():
    # beta outside (0, pi - alpha): +inf (documented), never NaN
    out = de.depth_error(np.array([-0.1, 0.0, 2.0, math.pi]), 1.5, 1000.0, 50.0, 1.0)
    assert np.all(np.isinf(out))
    with pytest.raises(ValueError, match="zero velocity"):
        G.plane_geometry([0, 0, 100.0], [0, 0, 0])
    with pytest.raises(ValueError, match="does not descend"):
        G.plane_geometry([0, 0, 100.0], [10.0, 0, 1.0])
    with pytest.raises(ValueError, match="above the ground"):
        G.plane_geometry([0, 0, -1.0], [10.0, 0, -1.0])
    with pytest.raises(ValueError, match="baseline"):
        de.depth_error(0.3, 1.0, 1000.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="alpha"):
        de.depth_error(0.3, 0.0, 1000.0, 10.0, 1.0)
    with pytest.raises(ValueError, match="error radius"):
        de.depth_error(0.3, 1.0, 1000.0, 10.0, -1.0)


def test_max_eig_sym3_matches_lapack():
    rng = np.random.default_rng(4)
    for _ in range(200):
        A = rng.normal(size=(3, 3))
        A = A @ A.T
        assert D.max_eig_sym3(A) == pytest.approx(np.linalg.eigvalsh(A)[-1], rel=1e-9)
    assert D.max_eig_sym3(np.diag([1.0, 5.0, 2.0])) == 5.0


def test_compiled_golden_section_is_the_interpreted_one():
    """search.golden_section compiled (the planner's search) and run by the
    interpreter (planner.golden_section) make the same evaluations."""
    r, v = np.array([2000.0, 3000.0, 4000.0]), np.array([-40.0, -60.0, -70.0])
    geom = G.plane_geometry(r, v)
    q = geom.q
    q[Q_KIND], q[Q_B], q[Q_RE] = DEPTH, D.baseline(v, np.zeros(3), 1.0), 3.0
    for lo, hi in ((-1.5, -0.01), (0.01, 0.7)):
        assert S.golden_section(q, lo, hi, 1e-4) == golden_section(lambda x: S.objective(x, q), lo, hi, 1e-4)
