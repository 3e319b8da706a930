"""The stars variant (beyond the paper): star images measure the camera attitude directly."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from opnav.approach import alternatives, cases, pipeline, stars
from opnav.approach import scenario as sc
from opnav.approach.camera import misalignment_exact
from opnav.approach.setup import Setup

from approach_helpers import approach_cfg


@settings(max_examples=50, deadline=None)
@given(x=st.floats(-0.02, 0.02), y=st.floats(-0.02, 0.02), t=st.tuples(*[st.floats(-1e-4, 1e-4)] * 3))
def test_star_sensitivity_is_the_derivative_of_the_exact_model(x, y, t):
    """G = dp/dtheta at 0 against central differences of the exact rotation (the truth's model)."""
    v = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
    G = stars.sensitivity(v)
    h = 1e-7
    fd = np.stack([(stars.focal_plane(misalignment_exact(h * e) @ v) - stars.focal_plane(misalignment_exact(-h * e) @ v))
                   / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(G, fd, atol=1e-7)
    th = np.asarray(t)
    lin = G @ th
    exact = stars.focal_plane(misalignment_exact(th) @ v) - stars.focal_plane(v)
    assert np.abs(exact - lin).max() <= 2.0 * np.abs(th).max() ** 2 + 1e-15  # error O(theta^2)


def test_information_update_is_the_inverse_of_added_information():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(9, 9))
    P = A @ A.T + np.eye(9)
    G = rng.normal(size=(4, 3))
    J = G.T @ G
    E = np.zeros((9, 3))
    E[6:] = np.eye(3)
    np.testing.assert_allclose(stars.theta_information_update(P, J), np.linalg.inv(np.linalg.inv(P) + E @ J @ E.T),
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(stars.theta_information_update(P, np.zeros((3, 3))), P)  # no star: no change


def _stars_cfg(per_image=3, **stars):
    cfg = approach_cfg(N0=100, N=100, M=3, L=4)
    # ideal attitude knowledge: these tests check the machinery (the floor has its own tests)
    cfg["stars"].update(every_K=100, per_image=per_image, attitude_sigma_arcsec=0.0, mode_drift_arcsec=0.0)
    cfg["stars"].update(stars)
    cfg["growing"].update(N=100)
    return Setup.from_config(cfg)


def test_star_bound_is_the_star_information_when_the_mars_channel_carries_none():
    """With Mars measurements worthless (huge variance) the bound of theta is the inverse of the
    star images' summed information J = sum G^T W G (diffuse theta prior)."""
    cfg = _stars_cfg()
    geo = sc.build_geometry(cfg, "stars")
    Rvar = np.full((geo.t.size, 3), 1e16)
    c = pipeline.bound_curve(cfg, geo, Rvar, (10.0, 20.0, 10.0), "stars")
    J = geo.stars.info_per_sample(geo.t.size - 1).sum(0)
    expect = sc.arcsec(np.sqrt(np.diag(np.linalg.inv(J + np.eye(3) / cfg.crlb_prior_sigma_rad ** 2))))
    np.testing.assert_allclose(c[-1], expect, rtol=1e-4)


def test_stars_make_tz_observable_and_the_estimators_reach_their_bound():
    """Star images (10 per image here) observe tz, which the Mars vector cannot; the growing-window
    EM-EKF (SQUAREM) and the augmented EKF agree on the same data and land within 4 bound-sigma
    of the truth in tx, ty, tz; more stars per image lower the bound."""
    cfg = _stars_cfg(10)
    setup = cfg
    case = cases.headline_case(cfg)
    geo = sc.build_geometry(cfg, "stars")
    Rvar = geo.measurement_variance(case.sigma3_px)
    bound = pipeline.bound_curve(cfg, geo, Rvar, case.truth_arcsec, "stars")[-1]
    lit = pipeline.bound_curve(cfg, sc.build_geometry(cfg, "prior"), Rvar, case.truth_arcsec, "prior")[-1]
    assert bound[2] < 0.05 * lit[2]  # tz: from the diffuse prior to tens of arcsec
    assert np.all(bound[:2] < 0.1 * lit[:2])
    seeds = range(3)
    r = cases.run_case(setup.scheme("growing"), "stars", case, seeds, geo=geo, method="squarem")
    a = alternatives.run_case_alternatives(cfg, "stars", case, seeds, geo, methods=("augmented",))
    # the ML estimate of the EM's data (SQUAREM to a 1e-4 arcsec step): the EM's own iterate is slow
    # here (the stars' information is small beside the Mars data's complete-data information), and
    # its label says how far it got, in bounds of its data
    th_em, th_a = r.theta_ml_arcsec, a.augmented.theta_final_arcsec
    assert not r.tz_unobservable and r.ml_converged.all()
    assert np.all((r.label == "converged") == (r.dist_to_ml_over_bound <= 0.1))
    truth = np.asarray(case.truth_arcsec)
    assert np.all(np.abs(th_em - truth) < 4 * bound)
    assert np.all(np.abs(th_a - truth) < 4 * bound)
    np.testing.assert_allclose(th_em, th_a, atol=0.3 * bound.max())
    few = _stars_cfg(1)
    b1 = pipeline.bound_curve(few, sc.build_geometry(few, "stars"), Rvar, case.truth_arcsec, "stars")[-1]
    assert np.all(b1 > bound)


def test_a_field_without_enough_stars_stops_with_the_key():
    cfg = _stars_cfg(mag_limit=-2.0)
    with pytest.raises(ValueError, match="approach.stars"):
        sc.build_geometry(cfg, "stars")



def test_an_arc_with_no_star_image_is_refused_naming_the_key():
    """An arc that ends before its first star image (sample N0 + every_K) is refused with a
    line naming approach.stars.every_K (it failed later in a numpy reshape). Not a config
    check: the stars variant's own geometry raises it, so a run of another variant (the CLI
    with a short arc) is not refused for the stars settings."""
    from opnav.approach import stars

    C = np.repeat(np.eye(3)[None], 11, axis=0)
    with pytest.raises(ValueError, match=r"approach\.stars\.every_K.*sample N0 \+ every_K = 15.*last sample 10"):
        stars.star_field(C, 10, 5, 3, 6.0, 0.0, 0.1, lambda m: 1e-5, stars.catalogue())


# ------------------------------------------------------------ real stars (issue 44, item 1)
SIRIUS_HIP = 32349
SIRIUS_RA_DEC_DEG = (101.2872, -16.7161)  # J2000 (SIMBAD); 24 years of proper motion move it < 40 arcsec


def _pointing(ra_deg, dec_deg, n=3):
    """A fixed camera attitude (n+1 samples) whose boresight is the ecliptic direction of (RA, Dec)."""
    from opnav.approach.camera import rot_x, tracking_attitude

    ra, dec = np.deg2rad([ra_deg, dec_deg])
    d = rot_x(stars.OBLIQUITY_J2000_RAD) @ [np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)]
    return tracking_attitude(np.repeat(d[None], n + 1, axis=0), np.zeros(n + 1))


def test_a_known_bright_star_appears_where_it_should():
    """Boresight on Sirius (published J2000 position, rotated into the ecliptic frame): the
    image's brightest star is HIP 32349, magnitude -1.44, at the image centre (within the
    proper motion since 2000); turned 0.5 deg about the camera x axis, it moves to
    p_y = +tan(0.5 deg) (rot_x turns the frame; the star stays). Mutations tried: the
    equatorial-to-ecliptic rotation dropped, or its sign flipped, puts Sirius ~23 deg away and fails."""
    C = _pointing(*SIRIUS_RA_DEC_DEG)
    f = stars.star_field(C, 0, 1, 5, 8.0, 0.0, np.deg2rad(1.42), lambda m: 1e-5, stars.catalogue())
    assert f.hip[0, 0] == SIRIUS_HIP and f.mag[0, 0] == pytest.approx(-1.44, abs=0.01)
    assert np.hypot(*f.p0[0, :2]) < sc.rad(40.0)
    f2 = stars.star_field(C, 0, 1, 5, 8.0, 0.5, np.deg2rad(1.42), lambda m: 1e-5, stars.catalogue())
    assert f2.hip[0, 0] == SIRIUS_HIP
    assert f2.p0[0, 1] == pytest.approx(np.tan(np.deg2rad(0.5)), abs=sc.rad(40.0))
    assert abs(f2.p0[0, 0]) < sc.rad(40.0)


def _floor_bound(per_image, att_arcsec, drift_arcsec=0.0, images=10):
    """Stars-only 1-sigma bound (tx, ty), arcsec, of ``images`` images of a wide (16 deg) field
    towards Sirius holding hundreds of stars: the whitened information sum."""
    C = _pointing(*SIRIUS_RA_DEC_DEG, n=images)
    f = stars.star_field(C, 0, 1, per_image, 8.0, 0.0, np.deg2rad(8.0), lambda m: sc.rad(1.0),
                         stars.catalogue(), sc.rad(att_arcsec), sc.rad(drift_arcsec))
    assert f.n_stars.min() == per_image
    J = f.info_per_sample(images).sum(0)
    return sc.arcsec(np.sqrt(np.diag(np.linalg.inv(J))))[:2], f


def test_whitened_information_is_the_joint_covariance_information():
    """sum G~^T G~ equals G^T R^-1 G of the joint star covariance with attitude and drift terms."""
    b, f = _floor_bound(4, 5.0, 2.0, images=3)
    Gf = f.G_raw.reshape(-1, 3)
    R = np.diag(f.sigma.reshape(-1) ** 2) + f.drift_sigma_rad ** 2 * Gf @ Gf.T
    m2 = f.G_raw.shape[1]
    for i in range(3):
        blk = slice(i * m2, (i + 1) * m2)
        R[blk, blk] += f.attitude_sigma_rad ** 2 * f.G_raw[i] @ f.G_raw[i].T
    np.testing.assert_allclose(f.info_per_sample(3).sum(0), Gf.T @ np.linalg.solve(R, Gf), rtol=1e-8)


def test_attitude_knowledge_sets_a_floor_that_more_stars_cannot_pass():
    """Issue 44: with perfect attitude knowledge more stars lower the bound (about 1/sqrt(stars));
    with sigma_a per image the bound is at least sigma_a / sqrt(images) in tx and ty, grows with
    sigma_a, and 30 stars per image gain almost nothing over 10. Mutation tried: the per-image
    attitude term left out of the joint covariance fails every assertion on the floor."""
    ideal3, _ = _floor_bound(3, 0.0)
    ideal30, _ = _floor_bound(30, 0.0)
    assert np.all(ideal30 < 0.5 * ideal3)
    floor = 5.0 / np.sqrt(10)
    b10, _ = _floor_bound(10, 5.0)
    b30, _ = _floor_bound(30, 5.0)
    assert np.all(b30 >= 0.98 * floor) and np.all(b10 >= 0.98 * floor)
    assert np.all(b30 > 0.95 * b10)  # no gain past the floor
    b30_20, _ = _floor_bound(30, 20.0)
    assert np.all(b30_20 > 3.5 * b30)
    # the drift adds a floor of its own that more images cannot average down
    bd, _ = _floor_bound(30, 0.0, drift_arcsec=2.0, images=20)
    assert np.all(bd >= 0.98 * 2.0)


def _dense_window_bound(cfg, geo, Rvar, theta_arcsec, a, b):
    """Independent bound of one sliding window (a, b): the dense joint information of the
    window's states and theta (Mars rows of samples a+1..b, the prior propagated to a without
    data) plus its own star rows, G^T R^-1 G with R the joint covariance of just those images
    (centroid noise, per-image attitude error, drift), written out here."""
    from opnav.approach import crlb, kalman
    from opnav.approach.camera import misalignment_small

    setup = cfg
    win = geo.window(Rvar).slice(a, b)
    P_a = kalman.propagate(None, geo.P0, geo.Phi[:a + 1], geo.Q)[1][-1]
    A = misalignment_small(sc.rad(theta_arcsec))
    Hx = np.stack([-A @ C for C in win.C])
    J, _ = crlb.dense_information(win, P_a, Hx, crlb.theta_sensitivity(geo.u_true[a:b + 1]),
                                  setup.crlb_prior_sigma_rad)
    f = geo.stars
    k = (f.idx > a) & (f.idx <= b)
    Gr, sig = f.G_raw[k], f.sigma[k]
    Gf = Gr.reshape(-1, 3)
    R = np.diag(sig.reshape(-1) ** 2) + f.drift_sigma_rad ** 2 * Gf @ Gf.T
    m2 = Gr.shape[1]
    for i in range(Gr.shape[0]):
        blk = slice(i * m2, (i + 1) * m2)
        R[blk, blk] += f.attitude_sigma_rad ** 2 * Gr[i] @ Gr[i].T
    J[-3:, -3:] += Gf.T @ np.linalg.solve(R, Gf)
    return sc.arcsec(np.sqrt(np.diag(np.linalg.inv(J))[-3:]))


def test_sliding_window_star_bound_is_the_windows_own_data_marginalised_exactly():
    """Issue 54, item 2: the bound of a sliding window of the stars variant is that of its own
    Mars and star data, the star rows marginalised exactly over drift and attitude errors (a
    dense joint-information computation, independent of the recursion and of the whitening).
    Mutation tried: the window reading the arc's whitened rows (conditioned on the images before
    it, as before issue 54) fails on every window after the first image (it was 6.66 against 5.09
    arcsec on the last window of the full profile)."""
    cfg = approach_cfg(N0=100, N=60, M=3, L=4)
    cfg["stars"].update(every_K=30, per_image=3, attitude_sigma_arcsec=5.0, mode_drift_arcsec=3.0)
    cfg = Setup.from_config(cfg)
    geo = sc.build_geometry(cfg, "stars")
    case = cases.headline_case(cfg)
    Rvar = geo.measurement_variance(case.sigma3_px)
    seg = pipeline.segment_bounds(cfg, geo, Rvar, case.truth_arcsec, "stars")
    for l, (a, b) in enumerate(cfg.segments.windows()):
        np.testing.assert_allclose(seg[l], _dense_window_bound(cfg, geo, Rvar, case.truth_arcsec, a, b), rtol=2e-4)
    # the label reads the same exact bound (along the reference trajectory, at the start theta)
    lab = cases.label_bounds(cfg, geo, [case], "stars")[0]
    np.testing.assert_allclose(lab[:2], seg[-1][:2], rtol=1e-3)


def test_a_window_whitens_its_own_star_rows():
    """Window.slice re-whitens the window's images: its whitened rows reproduce the window's joint
    covariance information, and growing windows (from the first image) keep the arc's rows."""
    cfg = approach_cfg(N0=100, N=60, M=3, L=4)
    cfg["stars"].update(every_K=30, per_image=3, attitude_sigma_arcsec=5.0, mode_drift_arcsec=3.0)
    cfg = Setup.from_config(cfg)
    geo = sc.build_geometry(cfg, "stars")
    y = geo.simulate_stars(sc.rad((10.0, 20.0, 10.0)), 7, 1, range(2))
    win = geo.window(geo.measurement_variance((0.1, 0.1, 0.2)), y)
    w = win.slice(220, 280)
    f = w.stars
    assert np.all(f.idx == [30, 60])  # images at samples 250 and 280
    np.testing.assert_allclose(f.L @ f.L.T, stars.joint_covariance(f.G_raw, f.sigma, f.attitude_sigma_rad,
                                                                   f.drift_sigma_rad), rtol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,sj->si", f.L, w.star_yw.reshape(2, -1)), w.star_y.reshape(2, -1),
                               rtol=1e-10, atol=1e-18)
    g = win.slice(100, 280)
    keep = (geo.stars.idx > 100) & (geo.stars.idx <= 280)
    np.testing.assert_allclose(g.stars.G, geo.stars.G[keep], rtol=1e-10, atol=1e-3 * np.abs(geo.stars.G).max())
    np.testing.assert_allclose(g.star_yw, win.star_yw[:, keep], rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("counts", [(1, 3, 10, 30)])
def test_the_count_sweep_puts_that_many_stars_in_every_image(counts):
    """Issue 54, item 4: each count of the stars sweep is real: with the magnitude limit and field
    of stars.count_settings every image holds exactly that many stars; the limit is the brightest
    that does it in the camera's field (one step brighter leaves an image short), the field is
    widened only where the catalogue's limit is not enough, and the bound falls as the count grows."""
    from dataclasses import replace

    cfg = approach_cfg(N0=100, N=100, M=3, L=4)
    cfg["stars"].update(every_K=100)
    cfg = setup = Setup.from_config(cfg)
    geo = sc.build_geometry(cfg, "stars")
    cam = sc.camera_half_fov_rad(setup)
    case = cases.headline_case(cfg)
    Rvar = geo.measurement_variance(case.sigma3_px)
    bounds = []
    for c in counts:
        cs = stars.count_settings(geo.C, 100, 100, c, 8.0, setup.stars.slew_deg, cam, stars.catalogue())
        s_c = setup.replace(stars=replace(setup.stars, per_image=c, mag_limit=cs.mag_limit))
        g = sc.with_stars(geo, s_c, cs.half_fov_rad)
        assert np.all(g.stars.n_stars == c), (c, g.stars.n_stars)
        assert cs.widened == (cs.half_fov_rad > cam)
        if not cs.widened:  # the brightest limit: a hair brighter, some image is short
            s_b = setup.replace(stars=replace(setup.stars, per_image=c, mag_limit=cs.mag_limit - 1e-3))
            try:
                short = sc.with_stars(geo, s_b).stars.n_stars.min() < c
            except ValueError:  # an image with no star at all
                short = True
            assert short
        else:
            assert cs.mag_limit == 8.0
        bounds.append(pipeline.bound_curve(s_c, g, Rvar, case.truth_arcsec, "stars")[-1][:2].max())
    assert all(b1 < b0 for b0, b1 in zip(bounds, bounds[1:])), bounds


def test_the_stars_label_reads_tz(monkeypatch):
    """Issue 54, item 4: star images observe tz, so the stars variant's convergence label reads
    tz too: a run whose tx, ty sit on the ML estimate of its data but whose tz is 5 bounds from it
    is not converged with stars, and converged where tz is unobservable (prior). The distance
    the label reads is over (tx, ty, tz) with stars, (tx, ty) otherwise. Mutation tried: tx, ty
    only for stars (``cases.label_axes`` := 2) fails."""
    ml = cases.ml_estimate

    def off_in_tz(z, theta, *a, **k):  # the ML estimate: the run's own tx, ty; tz 5 bounds away
        th, done, tr = ml(z, theta, *a, **k)
        th = theta.copy()
        th[:, 2] += 5.0 * sc.rad(BOUND_TZ[0])
        return th, done, tr

    monkeypatch.setattr(cases, "ml_estimate", off_in_tz)
    cfg = _stars_cfg(3, attitude_sigma_arcsec=5.0, mode_drift_arcsec=1.0)
    case = cases.headline_case(cfg)
    setup = cfg.scheme("growing")
    for variant, nax in (("stars", 3), ("prior", 2)):
        geo = sc.build_geometry(cfg, variant)
        BOUND_TZ[0] = cases.label_bounds(setup, geo, [case], variant)[0][2]
        r = cases.run_case(setup, variant, case, range(2), geo=geo, method="squarem")
        rel = np.abs(r.theta_final_arcsec - r.theta_ml_arcsec) / r.label_bound_arcsec
        np.testing.assert_allclose(r.dist_to_ml_over_bound, rel[:, :nax].max(1), rtol=1e-9)
        assert np.all((r.label == "converged") == (variant != "stars")), (variant, r.label)


BOUND_TZ = [1.0]
