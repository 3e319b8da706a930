"""Paper B planner: visible interval, method dispatch, one planning call."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from opnav.config import load_config
from opnav.landing.camera import camera_from_config
from opnav.landing.depth_error import plane_geometry
from opnav.landing.descent import build_scenario
from opnav.landing.planner import (OBJECTIVES, PlanState, available_methods, plan,
                                   visible_intervals)


@pytest.fixture(scope="module")
def scn():
    return build_scenario(load_config()["landing"])


def test_exact_visible_interval_matches_a_fine_grid():
    rng = np.random.default_rng(5)
    cam = camera_from_config(dict(fov_deg=60, pixels=1024, sigma_px=0.5, tilt_deg=45,
                                  tilt_azimuth_deg=-107))
    n_cmp = 0
    for _ in range(300):
        r = np.r_[rng.uniform(-5e3, 5e3, 2), rng.uniform(100, 8e3)]
        v = np.r_[rng.normal(size=2) * 60, -rng.uniform(1, 100)]
        R = Rotation.random(random_state=rng).as_matrix()
        geom = plane_geometry(r, v)
        for margin in (0.0, 40.0):
            ex = visible_intervals(geom, R, cam, 0, margin)
            gr = visible_intervals(geom, R, cam, 72001, margin)
            assert len(ex) == len(gr)
            for (a, b), (c, d) in zip(ex, gr):
                step = 2 * math.pi / 72000
                assert abs(a - c) <= 1.5 * step and abs(b - d) <= 1.5 * step
                n_cmp += 1
    assert n_cmp > 100


def test_dispatch_is_table_driven_and_unknown_methods_fail(scn):
    for m in ("depth", "svd", "gdop", "cond"):
        assert m in available_methods()
    assert set(OBJECTIVES) >= {"depth", "svd", "gdop", "cond"}
    tr = scn.truth
    st = PlanState(tr.r[5], tr.v[5], tr.a[5], tr.R_LtoB[5], np.eye(12))
    vis = lambda p, margin=40.0: scn.camera.in_view((np.asarray(p) - tr.r[5]) @ tr.R_LtoB[5].T, margin)
    with pytest.raises(ValueError, match="unknown planning method"):
        plan("nope", st, scn.camera, scn.field, vis, scn.planner)


@pytest.mark.parametrize("method", ["depth", "svd", "gdop", "cond"])
def test_plan_picks_a_detected_landmark_near_the_optimum(scn, method):
    tr = scn.truth
    k = 20
    st = PlanState(tr.r[k], tr.v[k], tr.a[k], tr.R_LtoB[k], np.diag([1e4] * 3 + [4.0] * 3 + [1e-4] * 3 + [1e6] * 3))
    vis = lambda p, margin=40.0: scn.camera.in_view((np.asarray(p) - tr.r[k]) @ tr.R_LtoB[k].T, margin)
    res = plan(method, st, scn.camera, scn.field, vis, scn.planner, exclude={123})
    assert res.index >= 0 and res.index != 123
    assert vis(scn.field.xyz[res.index][None])[0]
    assert np.isfinite(res.beta) and res.n_evals > 10 and res.time_ns > 0
    assert np.linalg.norm(scn.field.xyz[res.index, :2] - res.ground[:2]) < 500.0
    assert abs(res.ground[2]) < 1e-6


def test_degenerate_geometry_falls_back_with_a_note(scn):
    tr = scn.truth
    k = 20
    st = PlanState(tr.r[k], np.array([10.0, 0.0, 5.0]), tr.a[k], tr.R_LtoB[k], np.eye(12))
    vis = lambda p, margin=40.0: scn.camera.in_view((np.asarray(p) - tr.r[k]) @ tr.R_LtoB[k].T, margin)
    res = plan("depth", st, scn.camera, scn.field, vis, scn.planner)
    assert "does not descend" in res.note and math.isnan(res.beta)


def test_landing_site_in_view_for_the_whole_descent(scn):
    tr = scn.truth
    d = np.einsum("nij,nj->ni", tr.R_LtoB[:-1], -tr.r[:-1])   # site direction in {B}
    assert scn.camera.in_view(d, margin_px=50.0).all()


def test_camera_measurement_noise_and_behind_camera_error(scn):
    cam = scn.camera
    d = cam.boresight_B * 1000.0 + np.array([30.0, -20.0, 10.0])
    rng = np.random.default_rng(0)
    b = np.array([cam.measure(d, rng.standard_normal(2)) for _ in range(4000)])
    u = d / np.linalg.norm(d)
    assert np.allclose(np.linalg.norm(b, axis=1), 1.0)
    tang = b - np.outer(b @ u, u)
    # per-component tangential spread ~ sigma_px / f (slightly less off-axis)
    s = np.sqrt(np.mean(np.sum(tang**2, axis=1)) / 2)
    assert 0.8 * cam.sigma_b < s < 1.05 * cam.sigma_b
    with pytest.raises(ValueError, match="behind the camera"):
        cam.measure(-cam.boresight_B, np.zeros(2))
    assert not cam.in_view(-cam.boresight_B[None])[0]


@pytest.mark.parametrize("method", ["random", "center", "logdet", "mineig"])
def test_beyond_paper_methods_plan_too(scn, method):
    tr = scn.truth
    k = 20
    st = PlanState(tr.r[k], tr.v[k], tr.a[k], tr.R_LtoB[k], np.diag([1e4] * 3 + [4.0] * 3 + [1e-4] * 3 + [1e6] * 3))
    vis = lambda p, margin=40.0: scn.camera.in_view((np.asarray(p) - tr.r[k]) @ tr.R_LtoB[k].T, margin)
    res = plan(method, st, scn.camera, scn.field, vis, scn.planner, rng=np.random.default_rng(1))
    assert res.index >= 0 and vis(scn.field.xyz[res.index][None])[0]


def test_pick_nearest_widens_until_a_detected_landmark():
    """The optimum may fall outside the true image: the pick is then the
    nearest *detected* landmark, never 'no landmark' while one is detected."""
    from opnav.landing.landmarks import make_field
    from opnav.landing.planner import _pick_nearest

    field = make_field(1000.0, 500, seed=3)
    point = np.array([0.0, 0.0, 0.0])
    far = np.argsort(np.hypot(*field.xyz[:, :2].T))[200]          # the 201st nearest
    visible = lambda p: np.isin(np.arange(len(field.xyz)), [far])[  # noqa: E731
        [int(np.flatnonzero((field.xyz == q).all(axis=1))[0]) for q in p]]
    assert _pick_nearest(field, point, visible, knn=16, exclude=set()) == far
    assert _pick_nearest(field, point, lambda p: np.zeros(len(p), bool), 16, set()) == -1
