"""One simulated powered descent with the vision-aided inertial EKF and a
landmark-planning method (paper B sec. 3, SPEC B.1-B.3).

Description
-----------
:func:`build_scenario` turns the ``landing`` config into everything shared by
all runs and methods (truth trajectory, noise-free IMU, landmark field,
camera, process noise); :func:`run_descent` flies one run:

* random streams from ``SeedSequence([base_seed, run_index])`` only (spawned
  into: initial error, IMU noise, pixel noise, picker), so a run is the same
  whatever the chunking and the same draws serve every method (paired);
* initial estimate = truth minus an error uniform within the Table 2 bounds
  per axis, initial covariance diag(bound^2 / 3);
* every ``dt_s`` the IMU increments propagate the filter; while the estimated
  altitude exceeds ``min_update_altitude_m`` the camera measures the landing
  site (known landmark, {L} origin) and the current unknown landmark. The
  observation strategy of Fig. 3: a landmark is observed ``obs_per_landmark``
  times (its first bearing initialises it), then a new one is planned,
  initialised and the old one dropped; a landmark that leaves the image before
  that is replaced at once. Below the altitude limit the filter coasts on the
  IMU (the site is then metres away and bearings are no longer linear in the
  position error; our guidance creeps the last ~30 s at a few metres).

Tuning (config ``landing.filter``)
----------------------------------
The filter is the paper's EKF with three documented departures, all switchable:
``observability_constrained`` (default on) applies the OC-EKF transition of
Hesch et al. (paper ref. [16]) so the unobservable yaw about the site keeps
its prior variance (a plain EKF reports yaw converging to 0.03 deg while its
error stays near 1-2 deg); ``iterations`` (default 3) relinearises each
bearing update at the iterate (iterated EKF), the Jacobian projected on the
complement of the unobservable direction at the prior, so the constraint
holds in every iteration (without the projection the yaw 1-sigma collapses);
``meas_noise_scale`` (default 5) is the ratio of the filter's bearing-noise
model to the true pixel noise. With the Table 2 initial errors (1 km, 10 m/s,
2 deg) the second-order terms of the bearings exceed the 0.5-pixel noise
at the first landmark triangulations, and the filter with the true noise is
overconfident (position NEES in the tens); with a tenth of those errors it is
consistent with the true noise (tests/test_landing_filter.py). The default
pair is the smallest scale whose position and velocity NEES over 40 seeded
runs lie in the 95 % chi-square band (benchmarks/bench_landing_filter.py,
which prints the evidence for the old default 8 / 1 iteration beside it).
A new landmark's depth guess is the ground cut of its first line of sight,
its covariance the Jacobian of that cut plus ``depth_sigma_frac`` (10 %).

Returned per run: errors (truth - estimate) of position, velocity (m, m/s),
attitude (small-angle ``dtheta`` and roll/pitch/yaw differences, deg) at the
filter times, 1-sigma of the filter, position and velocity NEES, and per
planning call its wall time (ns) and evaluation count, and everything
``planner.plan`` took, to replay the call exactly (``opnav.landing.timing``):
the filter step (the truth pose, hence the detected landmarks, follows from
the scenario), the estimate (r, v, a, R_LtoB, P), the excluded current
landmark (-1: none) and the picker stream's state.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from opnav.landing import ekf, imu
from opnav.landing.camera import Camera, camera_from_config
from opnav.landing.landmarks import LandmarkField, make_field
from opnav.landing.metrics import H_METRICS
from opnav.landing.planner import PlannerConfig, PlanState, alternative_path, plan
from opnav.landing.timing import RECORD_KEYS, record_plan_inputs, stack_plan_inputs
from opnav.landing.trajectory import Truth, euler_rpy_deg, truth_states

__all__ = ["Scenario", "build_scenario", "run_descent", "initial_error", "summarize_run",
           "yaw_sigma_rad", "last_update_index"]


@dataclass(frozen=True)
class Scenario:
    truth: Truth               # at the filter times (n_steps + 1)
    truth_imu: Truth           # at the IMU nodes
    f: np.ndarray              # noise-free IMU specific force (m, 3)
    w: np.ndarray              # noise-free IMU rate (m, 3)
    g: np.ndarray
    dt_imu: float
    n_sub: int
    Dt: float
    n_steps: int
    Q: np.ndarray
    sigma_a: float
    sigma_w: float             # rad/s
    camera: Camera
    field: LandmarkField
    planner: PlannerConfig
    planner_alt: PlannerConfig  # the same on the alternative metric evaluation path (timing)
    obs_per_landmark: int
    depth_sigma_frac: float
    min_update_alt: float
    oc: bool                   # observability-constrained EKF (ekf.oc_transition)
    iterations: int            # iterated-EKF relinearisations per update
    noise_scale: float         # filter bearing noise / true pixel noise
    bounds: tuple              # (m, m/s, rad)
    base_seed: int


def _scenario_from_json(text: str) -> Scenario:
    c = json.loads(text)
    T = float(c["duration_s"])
    Dt = float(c["filter"]["dt_s"])
    rate = float(c["imu"]["rate_hz"])
    n_sub = int(round(rate * Dt))
    if n_sub < 1 or abs(n_sub / rate - Dt) > 1e-9:
        raise ValueError(f"landing.imu.rate_hz ({rate}) times landing.filter.dt_s ({Dt}) "
                         "must be a positive integer")
    n_steps = int(round(T / Dt))
    if abs(n_steps * Dt - T) > 1e-9:
        raise ValueError(f"landing.duration_s ({T}) must be a multiple of landing.filter.dt_s ({Dt})")
    dt = Dt / n_sub
    g = np.asarray(c["gravity_mps2"], float)
    s0 = c["initial_state"]
    yaw = float(c.get("yaw_deg", 0.0))
    t_imu = np.arange(n_steps * n_sub + 1) * dt
    tr_imu = truth_states(t_imu, s0["r_m"], s0["v_mps"], T, g, yaw, c.get("terminal_accel_mps2"))
    tr = Truth(t=tr_imu.t[::n_sub], r=tr_imu.r[::n_sub], v=tr_imu.v[::n_sub],
               a=tr_imu.a[::n_sub], R_LtoB=tr_imu.R_LtoB[::n_sub])
    f, w = imu.synthesize(tr_imu.v, tr_imu.R_LtoB, dt, g)
    sa = float(c["imu"]["sigma_a_mps2"])
    sw = math.radians(float(c["imu"]["sigma_w_degps"]))
    pl = c["planner"]
    pcfg = PlannerConfig(t_s=Dt, n_sigma_v=float(pl["n_sigma_v"]), tol_rad=float(pl["tol_rad"]),
                         n_grid=int(pl["n_grid"]), margin_px=float(pl["margin_px"]),
                         knn=int(pl["knn"]), eval_path=str(pl["eval_path"]))
    lm = c["landmarks"]
    b = c["mc"]["bounds"]
    fl = c["filter"]
    return Scenario(truth=tr, truth_imu=tr_imu, f=f, w=w, g=g, dt_imu=dt, n_sub=n_sub, Dt=Dt,
                    n_steps=n_steps, Q=ekf.process_noise(sa, sw, dt, n_sub), sigma_a=sa, sigma_w=sw,
                    camera=camera_from_config(c["camera"]),
                    field=make_field(float(lm["half_width_m"]), int(lm["count"]), int(lm["seed"])),
                    planner=pcfg, planner_alt=alternative_path(pcfg), obs_per_landmark=int(fl["obs_per_landmark"]),
                    depth_sigma_frac=float(fl["depth_sigma_frac"]),
                    min_update_alt=float(fl["min_update_altitude_m"]),
                    oc=bool(fl["observability_constrained"]),
                    iterations=int(fl["iterations"]),
                    noise_scale=float(fl["meas_noise_scale"]),
                    bounds=(float(b["r_m"]), float(b["v_mps"]), math.radians(float(b["att_deg"]))),
                    base_seed=int(c["mc"]["base_seed"]))


_KEYS = ("duration_s", "gravity_mps2", "initial_state", "yaw_deg", "terminal_accel_mps2", "imu", "camera", "landmarks",
         "filter", "planner", "mc")


def build_scenario(landing_cfg: dict) -> Scenario:
    """The shared scenario of a ``landing`` config (cached per distinct config)."""
    sub = {k: landing_cfg[k] for k in _KEYS if k in landing_cfg}
    return _cached(json.dumps(sub, sort_keys=True))


@lru_cache(maxsize=4)
def _cached(text: str) -> Scenario:
    return _scenario_from_json(text)


def initial_error(rng: np.random.Generator, bounds: tuple) -> np.ndarray:
    """Error state (truth - estimate) [dr, dv, dtheta] (9,), uniform per axis."""
    br, bv, bt = bounds
    return np.concatenate([rng.uniform(-br, br, 3), rng.uniform(-bv, bv, 3),
                           rng.uniform(-bt, bt, 3)])


def _att_error(R_true: np.ndarray, R_est: np.ndarray) -> np.ndarray:
    """dtheta (rad) with R_true = Exp(-dtheta) R_est (log map; angles < pi/2)."""
    D = R_true @ R_est.T
    w = 0.5 * np.array([D[2, 1] - D[1, 2], D[0, 2] - D[2, 0], D[1, 0] - D[0, 1]])
    s = float(np.linalg.norm(w))
    c = 0.5 * (D[0, 0] + D[1, 1] + D[2, 2] - 1.0)
    if s < 1e-12:
        return -w
    return -w * (math.atan2(s, c) / s)


def _wrap_deg(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def run_descent(scn: Scenario, method: str, run_index: int, *, base_seed: int | None = None,
                imu_noise: bool = True, init_error: bool = True) -> dict:
    """Fly one descent; see the module docstring for the returned arrays."""
    seed = scn.base_seed if base_seed is None else int(base_seed)
    ss = np.random.SeedSequence([seed, int(run_index)])
    rng_init, rng_imu, rng_px, rng_pick = (np.random.default_rng(s) for s in ss.spawn(4))
    e0 = initial_error(rng_init, scn.bounds)
    if not init_error:
        e0[:] = 0.0
    if imu_noise:
        f, w = imu.add_noise(scn.f, scn.w, scn.sigma_a, scn.sigma_w, rng_imu)
    else:
        f, w = scn.f, scn.w
    noise_px = rng_px.standard_normal((scn.n_steps + 1, 2, 2))
    pre = imu.preintegrate(f, w, scn.dt_imu, scn.n_sub)

    tr = scn.truth
    cam = scn.camera
    sb = cam.sigma_b * scn.noise_scale      # the filter's bearing-noise model
    p_site = np.zeros(3)
    P0 = np.zeros((12, 12))
    br, bv, bt = scn.bounds
    P0[:9, :9] = np.diag(np.repeat([br**2 / 3, bv**2 / 3, bt**2 / 3], 3))
    P0[9:, 9:] = np.eye(3) * 1e8      # dormant until the first landmark is initialised
    st = ekf.NavState(r=tr.r[0] - e0[0:3], v=tr.v[0] - e0[3:6],
                      R=imu.exp_batch(e0[6:9][None])[0] @ tr.R_LtoB[0], p=np.zeros(3), P=P0)
    n = scn.n_steps
    err_r = np.empty((n + 1, 3))
    err_v = np.empty((n + 1, 3))
    err_th = np.empty((n + 1, 3))
    sig = np.empty((n + 1, 9))
    sig_yaw = np.empty(n + 1)
    nees_r = np.empty(n + 1)
    nees_v = np.empty(n + 1)
    updated = np.zeros(n + 1, bool)
    plan_ns, plan_cpu, plan_evals, plan_t, plan_beta, plan_idx = [], [], [], [], [], []
    plan_edge, plan_ratio, plan_ns_alt, plan_cpu_alt = [], [], [], []
    rec = {k: [] for k in RECORD_KEYS}      # every planning call's inputs (timing.replay)
    cur, n_obs, n_used = -1, 0, 0
    a_est = tr.a[0]

    def record(k):
        er = tr.r[k] - st.r
        ev = tr.v[k] - st.v
        err_r[k], err_v[k] = er, ev
        err_th[k] = _att_error(tr.R_LtoB[k], st.R)
        sig[k] = np.sqrt(np.clip(np.diag(st.P)[:9], 0, None))
        sig_yaw[k] = yaw_sigma_rad(st.R, st.P)
        nees_r[k] = er @ np.linalg.solve(st.P[0:3, 0:3], er)
        nees_v[k] = ev @ np.linalg.solve(st.P[3:6, 3:6], ev)

    record(0)
    # the planner's metric contexts skip validation (timed path): validate the
    # descent's inputs once, here, with the same kinds of values
    from opnav.landing.metrics import MetricContext

    MetricContext(r_L=st.r, v_L=st.v, R_LtoB=st.R, p_known_L=np.asarray(scn.planner.p_known, float),
                  P=st.P, R_meas=scn.camera.sigma_b**2 * np.eye(6), boresight_B=cam.boresight_B)
    # observability constraint (OC-EKF): unobservable direction at the prior
    N = ekf.nullspace(st.r, st.v, st.R, st.p)
    C_prior = st.R
    for j in range(n):
        v_prev = st.v
        oc = (N, C_prior) if scn.oc else None
        st = ekf.propagate(st, pre.dR[j], pre.dv[j], pre.dp[j], scn.Dt, scn.g, scn.Q, oc)
        N = ekf.nullspace(st.r, st.v, st.R, st.p)
        C_prior = st.R
        a_est = (st.v - v_prev) / scn.Dt
        k = j + 1
        if k < n and st.r[2] > scn.min_update_alt:
            r_t, R_t = tr.r[k], tr.R_LtoB[k]

            def visible(pts, margin=scn.planner.margin_px, r_t=r_t, R_t=R_t):
                # pose bound now (not late-bound), so a stored closure stays this image's
                return cam.in_view((np.asarray(pts) - r_t) @ R_t.T, margin)

            meas = []
            d_site = R_t @ (p_site - r_t)
            if cam.in_view(d_site[None])[0]:
                meas.append((cam.measure(d_site, noise_px[k, 0]), p_site))
            still = cur >= 0 and visible(scn.field.xyz[cur][None], 0.0)[0]
            need_new = cur < 0 or n_obs >= scn.obs_per_landmark or not still
            det = visible(scn.field.xyz) if need_new else None   # the image's feature list
            if need_new and not _detects_other(det, cur):
                # the image holds no other landmark (e.g. low altitude): nothing to
                # choose, so no planning call; keep the current one while it is seen
                need_new = False
                if not still:
                    cur, n_obs = -1, 0
            if need_new:
                record_plan_inputs(rec, k, st.r, st.v, a_est, st.R, st.P, cur, rng_pick)
                res = plan(method, PlanState(st.r, st.v, a_est, st.R, st.P), cam, scn.field,
                           visible, scn.planner, exclude={cur} if cur >= 0 else set(),
                           rng=rng_pick, detected=np.flatnonzero(det))
                plan_ns.append(res.time_ns)
                plan_cpu.append(res.cpu_ns)
                if method in H_METRICS:
                    # the paper's baselines on the alternative evaluation path too
                    # (closed-form singular values vs H + LAPACK): timing only, same pick
                    alt = plan(method, PlanState(st.r, st.v, a_est, st.R, st.P), cam, scn.field,
                               visible, scn.planner_alt, exclude={cur} if cur >= 0 else set(),
                               rng=None, detected=np.flatnonzero(det), diagnose=False)
                    plan_ns_alt.append(alt.time_ns)
                    plan_cpu_alt.append(alt.cpu_ns)
                else:
                    plan_ns_alt.append(res.time_ns)
                    plan_cpu_alt.append(res.cpu_ns)
                plan_evals.append(res.n_evals)
                plan_t.append(k * scn.Dt)
                plan_beta.append(res.beta)
                plan_idx.append(res.index)
                plan_edge.append(res.edge)
                plan_ratio.append(res.pick_ratio)
                cur, n_obs = res.index, 0
                if cur >= 0:
                    b = cam.measure(R_t @ (scn.field.xyz[cur] - r_t), noise_px[k, 1])
                    try:
                        st = ekf.init_landmark(st, b, scn.depth_sigma_frac, sb)
                        N = ekf.nullspace(st.r, st.v, st.R, st.p)
                        n_obs, n_used = 1, n_used + 1
                    except ValueError:
                        cur = -1
            elif cur >= 0:
                b = cam.measure(R_t @ (scn.field.xyz[cur] - r_t), noise_px[k, 1])
                meas.append((b, None))
                n_obs += 1
            if meas:
                # OC-EKF: the Jacobian at the prior annihilates N exactly; an iterated
                # update relinearises away from the prior, so it must project H on N's
                # complement (ekf.update), or yaw becomes spuriously observable
                st, _ = ekf.update(st, meas, sb, N if scn.oc else None, scn.iterations)
                updated[k] = True
        record(k)

    rpy_t = euler_rpy_deg(tr.R_LtoB)
    return {
        "t": tr.t.copy(),
        "err_r": err_r, "err_v": err_v, "err_th_deg": np.degrees(err_th),
        "err_rpy_deg": _wrap_deg(rpy_t - _est_rpy(tr.R_LtoB, err_th)),
        "sig_r": sig[:, 0:3], "sig_v": sig[:, 3:6], "sig_th_deg": np.degrees(sig[:, 6:9]),
        "sig_yaw_deg": np.degrees(sig_yaw),
        "nees_r": nees_r, "nees_v": nees_v, "updated": updated,
        "plan_ns": np.asarray(plan_ns, np.int64), "plan_cpu_ns": np.asarray(plan_cpu, np.int64),
        "plan_evals": np.asarray(plan_evals, np.int64),
        "plan_t": np.asarray(plan_t, float), "plan_beta": np.asarray(plan_beta, float),
        "plan_index": np.asarray(plan_idx, np.int64), "n_landmarks": n_used,
        "plan_edge": np.asarray(plan_edge, bool), "plan_ratio": np.asarray(plan_ratio, float),
        "plan_ns_alt": np.asarray(plan_ns_alt, np.int64),
        "plan_cpu_ns_alt": np.asarray(plan_cpu_alt, np.int64),
        "init_error": e0,
        **stack_plan_inputs(rec),
    }


def yaw_sigma_rad(R_LtoB: np.ndarray, P: np.ndarray) -> float:
    """1-sigma (rad) of the filter's heading error: the attitude error about the
    {L} vertical, i.e. along ``R_LtoB e_z`` in our body-side ``dtheta`` (the
    attitude part of the unobservable direction, :func:`ekf.nullspace`)."""
    u = R_LtoB[:, 2]
    return float(math.sqrt(max(float(u @ P[6:9, 6:9] @ u), 0.0)))


def last_update_index(updated: np.ndarray) -> int:
    """Index of the last filter time with a vision update (0 if none): after it
    the filter coasts on the IMU to touchdown."""
    idx = np.flatnonzero(np.asarray(updated, bool))
    return int(idx[-1]) if idx.size else 0


def _detects_other(detected: np.ndarray, cur: int) -> bool:
    """True if the camera detects a landmark other than ``cur`` (the image's
    feature list, from the truth pose: the same for every planning method)."""
    return bool(detected.sum() - (detected[cur] if cur >= 0 else 0) > 0)


def _est_rpy(R_true: np.ndarray, dth: np.ndarray) -> np.ndarray:
    """Estimated roll/pitch/yaw (deg) from the truth and dtheta (R_est = Exp(dtheta) R_true)."""
    R_est = imu.exp_batch(dth) @ R_true
    return euler_rpy_deg(R_est)


def summarize_run(run: dict) -> dict:
    """Final and RMS error norms of one run (m, m/s, deg) and its mean NEES."""
    out = {}
    for key, name in (("err_r", "pos_err_m"), ("err_v", "vel_err_mps"), ("err_th_deg", "att_err_deg")):
        nrm = np.linalg.norm(run[key], axis=1)
        out[f"final_{name}"] = float(nrm[-1])
        out[f"lastvis_{name}"] = float(nrm[last_update_index(run["updated"])])
        out[f"rms_{name}"] = float(np.sqrt(np.mean(nrm**2)))
    out["final_yaw_err_deg"] = float(run["err_rpy_deg"][-1, 2])
    out["mean_nees_pos"] = float(np.mean(run["nees_r"]))
    out["mean_nees_vel"] = float(np.mean(run["nees_v"]))
    out["n_landmarks"] = int(run["n_landmarks"])
    out["n_plans"] = int(len(run["plan_ns"]))
    out["median_plan_time_us"] = float(np.median(run["plan_ns"]) / 1e3) if len(run["plan_ns"]) else math.nan
    out["median_plan_evals"] = float(np.median(run["plan_evals"])) if len(run["plan_evals"]) else math.nan
    return out


def depth_map(scn: Scenario, time_s: float, n_curve: int = 721) -> dict:
    """B-F5 data: the depth estimation error of every landmark in the image at
    ``time_s`` (truth state; error ball from the Table 2 velocity bound,
    ``eps_v = n_sigma_v * bound_v / sqrt(3)``), the single optimum, and the
    in-plane curve over signed beta with the visible interval and the
    golden-section optimum."""
    from opnav.landing.depth_error import (baseline, depth_error_at_landmarks, ground_point,
                                           plane_geometry, signed_depth_error)
    from opnav.landing.planner import golden_section, visible_intervals

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
    ivs = visible_intervals(geom, R, cam, scn.planner.n_grid, 0.0)
    best_b, best_f = math.nan, math.inf
    for lo, hi in ivs:
        x, fx, _ = golden_section(lambda bb: float(signed_depth_error(bb, geom, b, r_e)), lo, hi,
                                  scn.planner.tol_rad)
        if fx < best_f:
            best_b, best_f = x, fx
    opt_uv = np.full(2, np.nan)
    opt_xy = np.full(2, np.nan)
    if math.isfinite(best_b):
        g = ground_point(best_b, geom)[0]
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
    return {"time_s": k * scn.Dt, "uv_px": uv, "dr_m": dr, "best": best, "points": pts,
            "half_px": cam.half_px, "beta_deg": np.degrees(betas), "curve_dr": curve,
            "interval_deg": [(math.degrees(lo), math.degrees(hi)) for lo, hi in ivs],
            "opt_beta_deg": math.degrees(best_b), "opt_dr": best_f, "opt_uv_px": opt_uv,
            "opt_ground_xy": opt_xy, "r_e_m": r_e, "n_visible": int(vis.sum()),
            "field_xy": scn.field.xyz[fin, :2], "field_dr": dr_all[fin],
            "field_best_xy": scn.field.xyz[best_all, :2], "field_best_dr": float(dr_all[best_all]),
            "unconstrained_beta_deg": math.degrees(unc_b), "unconstrained_dr": float(unc_f),
            "unconstrained_ground_xy": ground_point(unc_b, geom)[0, :2],
            "lander_xy": r[:2].copy(), "footprint_xy": footprint,
            "optimum_inside_image": bool(any(lo < unc_b < hi for lo, hi in
                                             visible_intervals(geom, R, cam, 0, 0.0)))}
