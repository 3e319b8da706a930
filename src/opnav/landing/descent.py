"""Simulated powered descents with the vision-aided inertial EKF and a
landmark-planning method (paper B sec. 3, SPEC B.1-B.3), flown as a batch of
Monte-Carlo runs.

Description
-----------
The shared scenario (truth trajectory, noise-free IMU, landmark field, camera,
process noise) is ``opnav.landing.scenario.build_scenario``;
:func:`run_descents` flies a batch of runs in lockstep, :func:`run_descent` is
the batch of one (the same code path):

* random streams from ``SeedSequence([base_seed, run_index])`` only (spawned
  into: initial error, IMU noise, pixel noise, picker), so a run is the same
  whatever the chunking or the batch it is flown in, and the same draws serve
  every method (paired);
* initial estimate = truth minus an error uniform within the Table 2 bounds
  per axis, initial covariance diag(bound^2 / 3);
* every ``dt_s`` the IMU increments propagate the filter; while the estimated
  altitude less ``update_altitude_margin_m`` (:func:`vision_cutoff_altitude`,
  filter quantities only, never the truth)
  exceeds ``min_update_altitude_m`` the camera measures the landing
  site (known landmark, {L} origin) and the current unknown landmark. The
  observation strategy of Fig. 3 (:func:`tracking_step`): a landmark is
  observed ``obs_per_landmark`` times (its first bearing initialises it), then
  a new one is planned, initialised and the old one dropped; a landmark that
  leaves the image before that is replaced at once. Below the altitude limit
  the filter coasts on the IMU (the site is then metres away and bearings are
  no longer linear in the position error; our guidance creeps the last ~30 s
  at a few metres). ``lm_updated`` marks the updates holding a landmark
  bearing (the landmark-tracking phase ends at its last one), ``cut_alt_m``
  the cut-off quantity at each image.

Batching: the state, covariance and errors of every run of the batch are
arrays (runs x ...); the filter steps of ``opnav.landing.ekf`` work on the
whole batch; per-run branching (landmark switch, no-pick cases, a landmark
leaving the image, the end of vision updates, failed initialisations) is done
by masks, and a bearing update is one batched call per kind of measurement
set (site only, landmark only, both). The runs that need a new landmark at a
step are planned together (``opnav.landing.planner.plan_batch``). The truth,
and hence the image's feature list, is the same for every run.

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
planning call (``opnav.landing.records``) its filter time, optimum, pick, edge
flag, pick ratio and evaluation count, and everything the planning call took,
to replay it exactly (``opnav.landing.timing``): the filter step (the truth
pose, hence the detected landmarks, follows from the scenario), the estimate
(r, v, a, R_LtoB, P), the excluded current landmark (-1: none) and the picker
stream's state. The descent times nothing: every batch, the batch of one
included, plans in lockstep (``planner.plan_batch``, the picks of the per-call
``planner.plan``), and planning time is measured by replaying the recorded calls
(``opnav.landing.timing``).
"""

from __future__ import annotations

import math

import numpy as np

from opnav.landing import ekf, imu
from opnav.landing.metrics import MetricContext
from opnav.landing.methods import MethodError
from opnav.landing.planner import PlanState, plan_batch
from opnav.landing.records import CallLog, Descent
from opnav.landing.scenario import Scenario, build_scenario
from opnav.landing.trajectory import euler_rpy_deg
from opnav.core.compiled import kernel, warms
from opnav.landing.linalg import cho_solve, cholesky_in_place
from opnav.core.rotations import exp_so3, log_so3_into

__all__ = ["Scenario", "Descent", "build_scenario", "run_descent", "run_descents", "initial_error",
           "tracking_step", "vision_cutoff_altitude"]

def initial_error(rng: np.random.Generator, bounds: tuple) -> np.ndarray:
    """Error state (truth - estimate) [dr, dv, dtheta] (9,), uniform per axis."""
    br, bv, bt = bounds
    return np.concatenate([rng.uniform(-br, br, 3), rng.uniform(-bv, bv, 3),
                           rng.uniform(-bt, bt, 3)])


def _wrap_deg(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


@kernel
def _record(truth, est, k, tracks) -> None:
    """Column ``k`` of the per-run ``tracks = (err_r, err_v, err_th, sig, sig_yaw, nees_r,
    nees_v)`` from the ``truth = (r_t, v_t, R_t)`` at step k and the estimates of every run
    ``est = (r (B, 3), v (B, 3), R (B, 3, 3), P (B, 12, 12))``: errors truth - estimate of
    position, velocity (m, m/s) and
    attitude (``dtheta`` rad, ``R_true = Exp(-dtheta) R_est``), the filter's
    1-sigma of the 9 navigation states, the 1-sigma (rad) of the heading error
    (the attitude error about the {L} vertical, i.e. along ``R_LtoB e_z`` in our
    body-side ``dtheta``: the attitude part of the unobservable direction,
    ``ekf.nullspace``), and the position and velocity NEES."""
    r_t, v_t, R_t = truth
    r, v, R, P = est
    err_r, err_v, err_th, sig, sig_yaw, nees_r, nees_v = tracks
    M = np.empty((3, 3))
    L = np.empty((3, 3))
    x = np.empty(3)
    for b in range(r.shape[0]):
        for i in range(3):
            err_r[b, k, i] = r_t[i] - r[b, i]
            err_v[b, k, i] = v_t[i] - v[b, i]
            for j in range(3):
                M[i, j] = R_t[i, 0] * R[b, j, 0] + R_t[i, 1] * R[b, j, 1] + R_t[i, 2] * R[b, j, 2]
        log_so3_into(M, x)
        for i in range(3):
            err_th[b, k, i] = -x[i]
        for i in range(9):
            sig[b, k, i] = math.sqrt(max(P[b, i, i], 0.0))
        q = 0.0
        for i in range(3):
            for j in range(3):
                q += R[b, i, 2] * P[b, 6 + i, 6 + j] * R[b, j, 2]
        sig_yaw[b, k] = math.sqrt(max(q, 0.0))
        for blk in range(2):
            e = err_r[b, k] if blk == 0 else err_v[b, k]
            for i in range(3):
                x[i] = e[i]
                for j in range(3):
                    L[i, j] = P[b, 3 * blk + i, 3 * blk + j]
            cholesky_in_place(L, 3)
            cho_solve(L, 3, x)
            s = e[0] * x[0] + e[1] * x[1] + e[2] * x[2]
            if blk == 0:
                nees_r[b, k] = s
            else:
                nees_v[b, k] = s


@warms
def _warm() -> None:
    tracks = [np.zeros((1, 2, 3)), np.zeros((1, 2, 3)), np.zeros((1, 2, 3)), np.zeros((1, 2, 9)),
              np.zeros((1, 2)), np.zeros((1, 2)), np.zeros((1, 2))]
    _record((np.zeros(3), np.zeros(3), np.eye(3)), (np.zeros((1, 3)), np.zeros((1, 3)),
            np.eye(3)[None].copy(), np.eye(12)[None].copy()), 1, tuple(tracks))


def vision_cutoff_altitude(r_est: np.ndarray, margin_m: float) -> np.ndarray:
    """The quantity the vision cut-off compares with ``min_update_altitude_m``:
    the filter's estimated altitude less a margin, ``z_est - margin_m`` (m),
    per run. Only filter quantities: the truth never decides when the camera
    stops. The margin covers the estimate's altitude error near the ground
    (without it, runs whose estimate sits a few metres high took site bearings
    with the lander on the ground). A margin in filter 1-sigmas was tried and
    rejected: a filter that cannot tell its altitude (e.g. the random picker's,
    sigma_z ~ 300 m at 1 km) then stops vision at 1 km."""
    return r_est[..., 2] - float(margin_m)


def tracking_step(cur: np.ndarray, n_obs: np.ndarray, still: np.ndarray, other: np.ndarray,
                  obs_per_landmark: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The landmark-tracking state machine of Fig. 3 at one image, per run.

    ``cur``: current landmark (field index, -1 none), ``n_obs`` its observations
    so far, ``still``: it is still in the image, ``other``: the image holds a
    landmark other than ``cur``. A new landmark is needed when there is none,
    the current one has been observed ``obs_per_landmark`` times, or it left
    the image; when the image holds no other landmark (e.g. low altitude) there
    is nothing to choose, so no planning call: the current one is kept while it
    is seen, else dropped. Returns ``(plan, observe, cur, n_obs)``: the runs
    that plan a new landmark, the runs that observe their current one (its count
    already incremented), and the updated tracking state."""
    need = (cur < 0) | (n_obs >= obs_per_landmark) | ~still
    drop = need & ~other & ~still
    cur = np.where(drop, -1, cur)
    n_obs = np.where(drop, 0, n_obs)
    plan_ = need & other
    observe = ~plan_ & (cur >= 0)
    return plan_, observe, cur, np.where(observe, n_obs + 1, n_obs)


def _draws(scn: Scenario, runs: list[int], seed: int, imu_noise: bool, init_error: bool):
    """Per run, from its own stream only: initial error (B, 9), IMU
    pre-integration (B, n_steps, ...), pixel noise (B, n+1, 2, 2), picker rng."""
    e0, fs, ws, px, picks = [], [], [], [], []
    for i in runs:
        ss = np.random.SeedSequence([seed, int(i)])
        rng_init, rng_imu, rng_px, rng_pick = (np.random.default_rng(s) for s in ss.spawn(4))
        e = initial_error(rng_init, scn.bounds)
        e0.append(e if init_error else np.zeros_like(e))
        if imu_noise:
            f, w = imu.add_noise(scn.f, scn.w, scn.sigma_a, scn.sigma_w, rng_imu)
        else:
            f, w = scn.f, scn.w
        fs.append(f)
        ws.append(w)
        px.append(rng_px.standard_normal((scn.n_steps + 1, 2, 2)))
        picks.append(rng_pick)
    B = len(runs)
    pre = imu.preintegrate(np.concatenate(fs), np.concatenate(ws), scn.dt_imu, scn.n_sub)
    n = scn.n_steps
    dR = pre.dR.reshape(B, n, 3, 3)
    dv = pre.dv.reshape(B, n, 3)
    dp = pre.dp.reshape(B, n, 3)
    return np.stack(e0), (dR, dv, dp), np.stack(px), picks


def run_descent(scn: Scenario, method: str, run_index: int, *, base_seed: int | None = None,
                imu_noise: bool = True, init_error: bool = True) -> Descent:
    """Fly one descent: the batch of one of :func:`run_descents`."""
    return run_descents(scn, method, [run_index], base_seed=base_seed, imu_noise=imu_noise,
                        init_error=init_error)[0]


def run_descents(scn: Scenario, method: str, run_indices, *, base_seed: int | None = None,
                 imu_noise: bool = True, init_error: bool = True, pick_ratio: bool = True) -> list[Descent]:
    """Fly the runs ``run_indices`` as one batch; one :class:`Descent` record per run (module docstring).

    A run's numbers do not depend on the batch it is flown in (to round-off).
    ``pick_ratio = False`` skips the pick-ratio diagnostic (every detected landmark
    scored once more per call; ``plan_ratio`` is NaN), which no pick depends on."""
    runs = [int(i) for i in run_indices]
    B = len(runs)
    if B == 0:
        return []
    seed = scn.base_seed if base_seed is None else int(base_seed)
    e0, (dR, dv, dp), noise_px, rng_pick = _draws(scn, runs, seed, imu_noise, init_error)
    tr = scn.truth
    cam = scn.camera
    sb = cam.sigma_b * scn.noise_scale      # the filter's bearing-noise model
    p_site = np.zeros(3)
    field_xyz = scn.field.xyz
    P0 = np.zeros((12, 12))
    br, bv, bt = scn.bounds
    P0[:9, :9] = np.diag(np.repeat([br**2 / 3, bv**2 / 3, bt**2 / 3], 3))
    P0[9:, 9:] = np.eye(3) * 1e8      # dormant until the first landmark is initialised
    st = ekf.NavState(r=tr.r[0] - e0[:, 0:3], v=tr.v[0] - e0[:, 3:6],
                      R=exp_so3(e0[:, 6:9]) @ tr.R_LtoB[0], p=np.zeros((B, 3)),
                      P=np.broadcast_to(P0, (B, 12, 12)).copy())
    n = scn.n_steps
    err_r = np.empty((B, n + 1, 3))
    err_v = np.empty((B, n + 1, 3))
    err_th = np.empty((B, n + 1, 3))
    sig = np.empty((B, n + 1, 9))
    sig_yaw = np.empty((B, n + 1))
    nees_r = np.empty((B, n + 1))
    nees_v = np.empty((B, n + 1))
    updated = np.zeros((B, n + 1), bool)
    lm_updated = np.zeros((B, n + 1), bool)      # a landmark bearing among the update's
    cut_alt = np.full((B, n + 1), np.nan)        # the cut-off quantity at each image, m
    calls = [CallLog() for _ in range(B)]      # per planning call: inputs (replay) and results
    cur = np.full(B, -1, np.int64)
    n_obs = np.zeros(B, np.int64)
    n_used = np.zeros(B, np.int64)

    def record(k):
        c = (lambda a: np.array(a, float, order="C"))      # writable: the warmed signature
        _record((c(tr.r[k]), c(tr.v[k]), c(tr.R_LtoB[k])), (c(st.r), c(st.v), c(st.R), c(st.P)), k,
                (err_r, err_v, err_th, sig, sig_yaw, nees_r, nees_v))

    record(0)
    # the planner's metric contexts skip validation: validate the descent's
    # inputs once, here, with the same kinds of values
    for b in range(B):
        MetricContext(r_L=st.r[b], v_L=st.v[b], R_LtoB=st.R[b],
                      p_known_L=np.asarray(scn.planner.p_known, float), P=st.P[b],
                      R_meas=scn.camera.sigma_b**2 * np.eye(6), boresight_B=cam.boresight_B)
    # observability constraint (OC-EKF): unobservable direction at the prior
    N = ekf.nullspace(st.r, st.v, st.R, st.p)
    C_prior = st.R.copy()
    margin = scn.planner.margin_px
    for j in range(n):
        v_prev = st.v
        oc = (N, C_prior) if scn.oc else None
        st = ekf.propagate(st, dR[:, j], dv[:, j], dp[:, j], scn.Dt, scn.g, scn.Q, oc)
        N = ekf.nullspace(st.r, st.v, st.R, st.p)
        C_prior = st.R.copy()      # st is updated in place below
        a_est = (st.v - v_prev) / scn.Dt
        k = j + 1
        cut_alt[:, k] = vision_cutoff_altitude(st.r, scn.update_margin_m)
        act = (cut_alt[:, k] > scn.min_update_alt) if k < n else np.zeros(B, bool)
        if act.any():
            r_t, R_t = tr.r[k], tr.R_LtoB[k]

            def visible(pts, margin=margin, r_t=r_t, R_t=R_t):
                # pose bound now (not late-bound), so a stored closure stays this image's
                return cam.in_view((np.asarray(pts) - r_t) @ R_t.T, margin)

            d_site = R_t @ (p_site - r_t)
            site_seen = bool(cam.in_view(d_site[None])[0])
            has = cur >= 0
            still = np.zeros(B, bool)
            still[has] = visible(field_xyz[cur[has]], 0.0)
            other = np.zeros(B, bool)
            if (act & tracking_step(cur, n_obs, still, ~other, scn.obs_per_landmark)[0]).any():
                det = visible(field_xyz)           # the image's feature list (truth pose)
                other = int(det.sum()) - np.where(has, det[np.maximum(cur, 0)], False) > 0
            need, observe, cur_new, n_obs_new = tracking_step(cur, n_obs, still, other,
                                                              scn.obs_per_landmark)
            need &= act
            observe &= act
            cur = np.where(act, cur_new, cur)
            n_obs = np.where(act, n_obs_new, n_obs)
            ip = np.flatnonzero(need)
            if ip.size:
                for b in ip:
                    calls[b].record_inputs(k, st.r[b], st.v[b], a_est[b], st.R[b], st.P[b],
                                       cur[b], rng_pick[b])
                states = PlanState(st.r[ip], st.v[ip], a_est[ip], st.R[ip], st.P[ip])
                try:
                    res = plan_batch(method, states, cam, scn.field, visible, scn.planner, cur[ip],
                                     [rng_pick[b] for b in ip], np.flatnonzero(det), diagnose=pick_ratio)
                except MethodError as exc:     # a user's method failed: name the run and the call
                    b = ip[getattr(exc, "batch_position", 0)]
                    raise MethodError(f"{exc} in run {runs[b]}, planning call {calls[b].n_calls} "
                                      f"(t = {k * scn.Dt:g} s; method {method!r})") from exc
                for b, rs in zip(ip, res):
                    calls[b].append(k * scn.Dt, rs)
                cur[ip] = [rs.index for rs in res]
                n_obs[ip] = 0
                ii = ip[cur[ip] >= 0]
                if ii.size:
                    b_new = cam.measure((field_xyz[cur[ii]] - r_t) @ R_t.T, noise_px[ii, k, 1])
                    new, ok = ekf.init_landmark(st.take(ii), b_new, scn.depth_sigma_frac, sb)
                    st.put(ii, new)
                    N[ii] = np.where(ok[:, None], ekf.nullspace(new.r, new.v, new.R, new.p), N[ii])
                    cur[ii[~ok]] = -1
                    n_obs[ii[ok]] = 1
                    n_used[ii[ok]] += 1
            b_lm = np.zeros((B, 3))
            if observe.any():
                io = np.flatnonzero(observe)
                b_lm[io] = cam.measure((field_xyz[cur[io]] - r_t) @ R_t.T, noise_px[io, k, 1])
            b_site = cam.measure(np.broadcast_to(d_site, (B, 3)), noise_px[:, k, 0]) if site_seen else None
            # one batched update per kind of measurement set (the same shapes in each)
            groups = ([(act & observe, True, True), (act & ~observe, True, False)] if site_seen
                      else [(observe, False, True)])
            for mask, with_site, with_lm in groups:
                ig = np.flatnonzero(mask)
                if not ig.size:
                    continue
                meas = ([ekf.Bearing(b_site[ig], p_site)] if with_site else []) + (
                    [ekf.Bearing(b_lm[ig])] if with_lm else [])
                # OC-EKF: the Jacobian at the prior annihilates N exactly; an iterated
                # update relinearises away from the prior, so it must project H on N's
                # complement (ekf.update), or yaw becomes spuriously observable
                new, _ = ekf.update(st.take(ig), meas, sb, N[ig] if scn.oc else None, scn.iterations)
                st.put(ig, new)
                updated[ig, k] = True
                lm_updated[ig, k] = with_lm
        record(k)

    rpy_t = euler_rpy_deg(tr.R_LtoB)
    out = []
    for b in range(B):
        out.append(Descent(
            t=tr.t.copy(),
            err_r=err_r[b], err_v=err_v[b], err_th_deg=np.degrees(err_th[b]),
            err_rpy_deg=_wrap_deg(rpy_t - _est_rpy(tr.R_LtoB, err_th[b])),
            sig_r=sig[b, :, 0:3], sig_v=sig[b, :, 3:6], sig_th_deg=np.degrees(sig[b, :, 6:9]),
            sig_yaw_deg=np.degrees(sig_yaw[b]),
            nees_r=nees_r[b], nees_v=nees_v[b], updated=updated[b],
            lm_updated=lm_updated[b], cut_alt_m=cut_alt[b],
            n_landmarks=int(n_used[b]), init_error=e0[b],
            **calls[b].arrays()))
    return out


def _est_rpy(R_true: np.ndarray, dth: np.ndarray) -> np.ndarray:
    """Estimated roll/pitch/yaw (deg) from the truth and dtheta (R_est = Exp(dtheta) R_true)."""
    R_est = exp_so3(dth) @ R_true
    return euler_rpy_deg(R_est)
