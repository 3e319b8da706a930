"""Attitude knowledge of the Mars images (issue 54, item 3): simulated, and used by the estimators.

The truth's camera attitude is the known ``A_c^i`` turned by an independent error per image
(``camera.attitude_sigma_arcsec``, 1-sigma per axis); to first order it moves the Mars vector
sideways by ``rho delta``, so the filters, EM and the bounds add ``(rho sigma)^2`` to the lateral
variances (``Geometry.measurement_variance``).
"""

from dataclasses import replace

import numpy as np

from opnav.approach import cases, pipeline
from opnav.approach import scenario as sc

from approach_helpers import approach_cfg
from opnav.approach.setup import Setup


def _cfg(att):
    cfg = approach_cfg(N0=50, N=50, M=2, L=2)
    cfg["camera"]["attitude_sigma_arcsec"] = att
    return Setup.from_config(cfg)


def test_the_simulated_attitude_error_is_lateral_with_the_stated_variance():
    """z - u_true over 400 runs (theta = 0): lateral variance = pixel + (rho sigma_a)^2, range
    variance = pixel only (a rotation about an axis across the line of sight moves u sideways)."""
    geo = sc.build_geometry(_cfg(5.0), "literal")
    Rpix = geo.pixel_variance((0.1, 0.1, 0.2))
    z, _ = sc.simulate(geo, Rpix, np.zeros(3), sc.seed_streams(3, 1, range(400)))
    r = z[:, 1:] - geo.u_true[None, 1:]
    expect = geo.measurement_variance((0.1, 0.1, 0.2))[1:]
    ratio = (r ** 2).mean(0).mean(0) / expect.mean(0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.03)
    assert expect[0, 0] > 50 * Rpix[1, 0]  # 5 arcsec per image dominates the 0.1 px noise


def test_no_attitude_error_keeps_the_draws():
    """sigma_a = 0 draws nothing more: the measurements are those of a geometry without the key."""
    geo = sc.build_geometry(_cfg(0.0), "literal")
    Rpix = geo.pixel_variance((0.1, 0.1, 0.2))
    z0, e0 = sc.simulate(geo, Rpix, sc.rad([10.0, 20.0, 10.0]), sc.seed_streams(5, 1, range(2)))
    z1, e1 = sc.simulate(replace(geo, attitude_sigma_rad=sc.rad(5.0)), Rpix, sc.rad([10.0, 20.0, 10.0]),
                         sc.seed_streams(5, 1, range(2)))
    np.testing.assert_array_equal(e0, e1)
    assert not np.array_equal(z0, z1)
    np.testing.assert_array_equal(geo.measurement_variance((0.1, 0.1, 0.2)), Rpix)


def test_the_filters_know_the_attitude_error():
    """With 5 arcsec per Mars image, the theta = 0 filter of a run without misalignment has a mean
    NIS of 3 (the innovations match the covariance it assumes), and the bound of the roll variant
    grows, by at most the lateral noise's ratio (the prior holds part of it). Mutation tried: the estimators' variance
    without the attitude term (``Geometry.measurement_variance`` = pixel only) fails (NIS ~ 200)."""
    cfg = _cfg(5.0)
    case = replace(cases.headline_case(cfg), truth_arcsec=(0.0, 0.0, 0.0))
    d = cases.prepare_cases(cfg, "literal", [case], range(40))
    nis = np.nanmean(d.cons_before.nis)
    assert abs(nis - 3.0) < 0.3, nis
    geo = sc.build_geometry(cfg, "roll")
    g0 = replace(geo, attitude_sigma_rad=0.0)
    b = pipeline.bound_curve(cfg, geo, geo.measurement_variance(case.sigma3_px), (0.0, 0.0, 0.0), "roll")[-1]
    b0 = pipeline.bound_curve(cfg, g0, g0.measurement_variance(case.sigma3_px), (0.0, 0.0, 0.0), "roll")[-1]
    k = np.sqrt(geo.measurement_variance(case.sigma3_px)[-1, 0] / g0.measurement_variance(case.sigma3_px)[-1, 0])
    assert np.all(b[:2] > 1.2 * b0[:2]) and np.all(b[:2] < k * b0[:2]), (b, b0, k)  # grows, at most as the noise
