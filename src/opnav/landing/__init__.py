"""Paper B: Mars powered descent, vision-aided inertial EKF, landmark selection.

Li, Wang, Dong, Li, Xu (J. Deep Space Explor. 2023): landmark selection by the
depth estimation error, compared with SVD / GDOP / condition-number baselines.

Equation -> function (each equation has one home; the modules' docstrings give
the derivations, conventions and tests)
-----------------------------------------------------------------------------

=========  ==========================================================  ===============================
eq.        function                                                    units
=========  ==========================================================  ===============================
1          ``trajectory.truth_states`` (truth), ``imu.apply_increment``  m, m/s, m/s^2, s
           (r, v, attitude propagation)
2          ``imu.synthesize``, ``imu.add_noise``, ``imu.preintegrate``    m/s^2 (specific force), rad/s
           (IMU model; planet rotation neglected, assumption 1)
3-5        ``ekf.NavState`` (state r, v, R_LtoB, p), error state          m, m/s, rad, m
           [dr, dv, dtheta, dp] with ``R_true = Exp(-dtheta) R_est``
           (``measurement`` docstring; ``opnav.core.rotations.exp_so3``)
6-10       ``ekf.transition_matrix`` (Phi, eq. 8-10),                     Phi: m, s, dimensionless blocks
           ``ekf.propagate``, ``ekf.process_noise``
11-12      ``measurement.bearing`` (unit line of sight in {B})            dimensionless
13         ``ekf.update`` (bearing update, noise ``camera.Camera``          rad (sigma_b = sigma_px / f)
           ``sigma_b``)
14         ``measurement.selection_jacobian`` (n_s = n_p = 1, 6 x 12);     1/m (r, p columns),
           the filter stacks ``measurement.bearing_jacobian`` rows         1 (attitude columns)
15-18      ``measurement.bearing_jacobian`` (H_r, H_theta, H_p),          1/m; H_theta dimensionless
           ``measurement.blocks`` (H_C, [b x], compiled);
           tangent-plane form ``measurement.tangent_jacobian``
           (cross-check: ``casadi_model.jacobian_function``, CasADi)
19-20      ``planning.depth.baseline`` (estimated baseline |b|)            m
21-22      ``planning.depth.error_radius`` (r = eps_v t_s)                 m
23-25      ``planning.depth.depth_error`` (compiled, the planner's);       m
           the paper's formula ``planning.reference.depth_error`` /
           ``signed_depth_error`` (law of sines ``reference.depth``),
           landmarks ``reference.depth_error_at_landmarks``
26         ``planning.geometry.ground_point`` (law of sines               rad (beta), m (ground point)
           ``geometry.plane_depth``); the call ``planning.search.plan_core``
           (``planner.plan_batch``): plane, visible interval,
           ``search.golden_section``, nearest pick
sec. 2.2   ``metrics.make_metric`` (svd, gdop, cond from the 6 x 12 H,     1/m (svd), 1/m^2 (gdop), 1 (cond)
           closed form ``planning.hmetrics.h_metric``),
           ``planner.OBJECTIVE_METHODS``; B-X1 information baselines:
           ``planning.reference.planned_metric``
=========  ==========================================================  ===============================
"""

from opnav.core.compiled import register_kernel_modules as _register_kernel_modules

# The modules holding this paper's compiled kernels, or whose source a kernel folds in
# (landing.planning.layout's slot numbers), in warm-up order: they key the kernels' on-disk
# cache and the workflow's compile_kernels job warms them (opnav.core.compiled).
_register_kernel_modules(__name__, (
    "opnav.landing.measurement",
    "opnav.landing.linalg",
    "opnav.landing.ekf",
    "opnav.landing.ekf_update",
    "opnav.landing.planning.layout",
    "opnav.landing.planning.geometry",
    "opnav.landing.planning.depth",
    "opnav.landing.planning.screens",
    "opnav.landing.planning.hmetrics",
    "opnav.landing.planning.information",
    "opnav.landing.planning.search",
    "opnav.landing.planning.warmup",
    "opnav.landing.descent",
    "opnav.landing.imu",
))
