"""The record a user's own landmark-selection metric receives (``landing.custom_methods``;
``opnav.landing.methods``, issue 58): one named tuple of float64 arrays and numbers, which a
numba-compiled metric takes as it is (``planning.custom``)."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Candidate"]


class Candidate(NamedTuple):
    """What a selection metric receives for one candidate ground point: the candidate's
    geometry and the filter's estimate at the planning instant (what the paper's metrics read:
    the depth error reads r, v, a, P's velocity block and t_s; the H baselines r, R_LtoB, the
    site and the candidate; the information baselines all of it). Units SI, frames as named.
    Read-only: do not modify the arrays."""

    p_L: np.ndarray          #: (3,) the candidate landmark / ground point, {L}, m
    r_L: np.ndarray          #: (3,) estimated lander position, {L}, m
    v_L: np.ndarray          #: (3,) estimated velocity, {L}, m/s
    a_L: np.ndarray          #: (3,) estimated acceleration over the last filter step (gravity included), {L}, m/s^2
    R_LtoB: np.ndarray       #: (3, 3) estimated attitude: v_B = R_LtoB v_L
    P: np.ndarray            #: (12, 12) filter covariance of [r (m), v (m/s), dtheta (rad), p (m)] (p: the current landmark)
    p_site_L: np.ndarray     #: (3,) the known landmark (landing site), {L}, m
    R_BtoC: np.ndarray       #: (3, 3) camera mounting: v_C = R_BtoC v_B (boresight = row 2)
    sigma_b_rad: float       #: true bearing noise, 1-sigma per component, rad (pixel noise / focal length)
    noise_scale: float       #: the filter's bearing-noise model / sigma_b_rad
    t_s: float               #: observation interval (the filter step), s
    n_obs: int               #: observations of a landmark before the next is planned (Fig. 3)
