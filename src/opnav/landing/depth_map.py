"""B-F5 data: the depth estimation error (paper B eq. 23-25) over the image and
the landmark field at one planning instant, from the truth state (no filter).

Description
-----------
:func:`depth_map` evaluates, at the filter time ``time_s``, the depth error of
every landmark the camera detects and of the whole field (error ball from the
Table 2 velocity bound, ``eps_v = n_sigma_v * bound_v / sqrt(3)``), the
in-plane curve over signed beta with the visible interval and its
golden-section optimum (the planner's own search), and the unconstrained
in-plane optimum with its ground point. Units: m, deg (outputs), s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from opnav.landing.planning.depth import baseline
from opnav.landing.planning.geometry import ground_points, plane_geometry
from opnav.landing.planning.reference import depth_error_at_landmarks, signed_depth_error
from opnav.landing.planner import golden_section, visible_intervals
from opnav.landing.scenario import Scenario

__all__ = ["depth_map", "DepthMap"]


@dataclass(frozen=True, eq=False)
class DepthMap:
    """B-F5's data at one filter time ``time_s`` (:func:`depth_map`; m, deg, px). In the image:
    each detected landmark's pixel ``uv_px``, depth error ``dr_m`` and ground point ``points``,
    the best one's index ``best``, the detector's half size ``half_px``, the in-plane curve
    (``beta_deg``, ``curve_dr``), the visible intervals and the golden-section optimum (``opt_*``)
    with its pixel and ground point, the error ball ``r_e_m`` and the detected count. Over the
    field: every landmark's ground point and depth error, the best one, the unconstrained in-plane
    optimum with its ground point, the lander's ground point, the image footprint and whether the
    unconstrained optimum lies in the image."""

    time_s: float
    uv_px: np.ndarray
    dr_m: np.ndarray
    best: int
    points: np.ndarray
    half_px: float
    beta_deg: np.ndarray
    curve_dr: np.ndarray
    interval_deg: list[tuple[float, float]]
    opt_beta_deg: float
    opt_dr: float
    opt_uv_px: np.ndarray
    opt_ground_xy: np.ndarray
    r_e_m: float
    n_visible: int
    field_xy: np.ndarray
    field_dr: np.ndarray
    field_best_xy: np.ndarray
    field_best_dr: float
    unconstrained_beta_deg: float
    unconstrained_dr: float
    unconstrained_ground_xy: np.ndarray
    lander_xy: np.ndarray
    footprint_xy: np.ndarray
    optimum_inside_image: bool


def depth_map(scn: Scenario, time_s: float, n_curve: int = 721) -> DepthMap:
    """B-F5 data: the depth estimation error of every landmark in the image at
    ``time_s`` (truth state; error ball from the Table 2 velocity bound,
    ``eps_v = n_sigma_v * bound_v / sqrt(3)``), the single optimum, and the
    in-plane curve over signed beta with the visible interval and the
    golden-section optimum."""
    k = int(round(time_s / scn.Dt))
    if not 0 <= k < scn.n_steps:
        raise ValueError(f"landing.figures.f5_time_s = {time_s} outside the descent")
    tr = scn.truth
    r, v, a, R = tr.r[k], tr.v[k], tr.a[k], tr.R_LtoB[k]
    cam = scn.camera
    dirs = (scn.field.xyz - r) @ R.T
    vis = cam.in_view(dirs)
    pts = scn.field.xyz[vis]
    dc = dirs[vis] @ cam.R_BtoC.T
    uv = cam.focal_px * dc[:, :2] / dc[:, 2:3]
    r_e = scn.planner.n_sigma_v * scn.bounds[1] / math.sqrt(3.0) * scn.Dt
    dr = depth_error_at_landmarks(r, v, a, pts, scn.Dt, r_e)
    best = int(np.nanargmin(np.where(np.isfinite(dr), dr, np.nan)))
    geom = plane_geometry(r, v)
    b = baseline(v, a, scn.Dt)
    betas = np.linspace(-(math.pi - geom.gamma) + 1e-3, geom.gamma - 1e-3, n_curve)
    curve = signed_depth_error(betas, geom, b, r_e)
    ivs = visible_intervals(geom, R, cam, 0.0)
    best_b, best_f = math.nan, math.inf
    for lo, hi in ivs:
        x, fx, _ = golden_section(lambda bb: float(signed_depth_error(bb, geom, b, r_e)), lo, hi,
                                  scn.planner.tol_rad)
        if fx < best_f:
            best_b, best_f = x, fx
    opt_uv = np.full(2, np.nan)
    opt_xy = np.full(2, np.nan)
    if math.isfinite(best_b):
        g = ground_points(best_b, geom)[0]
        opt_xy = g[:2]
        d = cam.R_BtoC @ (R @ (g - r))
        if d[2] > 0:
            opt_uv = cam.focal_px * d[:2] / d[2]
    # the whole field (no image constraint): every landmark's depth error and the
    # unconstrained in-plane optimum (golden section over the whole ground arc)
    dr_all = depth_error_at_landmarks(r, v, a, scn.field.xyz, scn.Dt, r_e)
    fin = np.isfinite(dr_all)
    best_all = int(np.argmin(np.where(fin, dr_all, np.inf)))
    unc = []
    for lo, hi in ((-(math.pi - geom.gamma) + 1e-6, -1e-9), (1e-9, geom.gamma - 1e-6)):
        unc.append(golden_section(lambda bb: float(signed_depth_error(bb, geom, b, r_e)), lo, hi,
                                  scn.planner.tol_rad)[:2])
    unc_b, unc_f = min(unc, key=lambda x: x[1])
    # image footprint on the ground: the four detector corners' lines of sight
    hp = cam.half_px
    corners = np.array([[-hp, -hp], [hp, -hp], [hp, hp], [-hp, hp]], float)
    rays = np.column_stack([corners, np.full(4, cam.focal_px)]) @ cam.R_BtoC @ R
    with np.errstate(divide="ignore", invalid="ignore"):
        tcut = np.where(rays[:, 2] < 0, -r[2] / rays[:, 2], np.nan)
    footprint = (r + tcut[:, None] * rays)[:, :2]
    return DepthMap(time_s=k * scn.Dt, uv_px=uv, dr_m=dr, best=best, points=pts,
                    half_px=cam.half_px, beta_deg=np.degrees(betas), curve_dr=curve,
                    interval_deg=[(math.degrees(lo), math.degrees(hi)) for lo, hi in ivs],
                    opt_beta_deg=math.degrees(best_b), opt_dr=best_f, opt_uv_px=opt_uv,
                    opt_ground_xy=opt_xy, r_e_m=r_e, n_visible=int(vis.sum()),
                    field_xy=scn.field.xyz[fin, :2], field_dr=dr_all[fin],
                    field_best_xy=scn.field.xyz[best_all, :2], field_best_dr=float(dr_all[best_all]),
                    unconstrained_beta_deg=math.degrees(unc_b), unconstrained_dr=float(unc_f),
                    unconstrained_ground_xy=ground_points(unc_b, geom)[0, :2],
                    lander_xy=r[:2].copy(), footprint_xy=footprint,
                    optimum_inside_image=bool(any(lo < unc_b < hi for lo, hi in
                                                  visible_intervals(geom, R, cam, 0.0))))
