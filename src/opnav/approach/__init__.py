"""Paper A: EM-EKF camera optical-axis bias estimation on Mars approach.

Equation -> function (paper A's equation numbers; SPEC section A for what is ours)

=========  ==========================================================  ==============================================  ====================
eq.        what                                                        function                                        units
=========  ==========================================================  ==============================================  ====================
1-2        heliocentric dynamics, Sun + Mars third body                dynamics.acceleration, dynamics.propagate       km, km/s, s
1-2 (lin.) one-step STM Phi_{k,k-1} of the variational equations        dynamics.propagate_with_stm                     --
3-4        Mars vector in the measured camera frame, the measurement   ekf.predicted_measurement; scenario.simulate     km
                                                                       (truth, exact rotation)
3 (noise)  pixel 3-sigma -> km at the reference range                  camera.noise_sigma_km,                          km, km^2
                                                                       scenario.Geometry.measurement_variance
5          misalignment A_m^c = I - [theta x]; the exact rotation      camera.misalignment_small,                      rad
                                                                       camera.misalignment_exact
6          EKF time and measurement update (the one predict and the   kalman.predict, kalman.condition_on;            km, km/s
           one update of every filter here), batched over seeds        ekf.run_filter, ekf.predict_only
7-9        RTS smoother (gain, mean, covariance)                       smoother.bryson_frazier (the same moments;      km, km/s
                                                                       RTS form: tests/approach_reference.rts)
10-14      observed-data log-likelihood, prediction-error form         kalman.innovation_loglik (ekf.run_filter)       nats
18         lag-one smoothed cross-covariance P_{k,k-1|N}               tests/approach_reference.rts (gain form),       km^2...
                                                                       .lag_one_recursive (the E-step needs none)
21-22      expected complete-data log-likelihood Q(theta|theta_r)      tests/approach_reference.expected_complete_loglik nats
23, 26     Tr(R^-1 B(theta)) and its closed-form minimiser (M-step)    em.estep, em.mstep (reference: .trace_RinvB)    rad
24-25      smoothed moments X_{k|N}, P_{k|N}                           smoother.bryson_frazier                         km, km/s
27         H_k = [-A_m^c A_c^i, 0] (sign: d/d r, not d/d r_pM)         ekf.measurement_jacobian                        km/km
sec. 2.3   segment-wise EM-EKF (N0, N, M, L), Table 1                  cases.run_cases, setup.Segments.windows,        arcsec, km, samples
                                                                       em.em_window
SPEC A.3b  Cramér-Rao bound of theta with the unknown state            crlb.crlb_curve (the augmented filter's         rad (1-sigma)
                                                                       covariance via kalman.*), crlb.batch_crlb
SPEC A.3c  convergence labels: distance to the ML estimate of the      em.ml_estimate, em.contraction_per_map,         arcsec
           data used, contraction per map toward it                    em.convergence_labels
SPEC A.4   A-X2 alternatives: augmented EKF, batch ML (CasADi/IPOPT)   augmented.run_augmented, batch_ml.BatchML,      rad, arcsec
                                                                       alternatives.run_case_alternatives
issue 44   compensation carrying theta_hat's covariance (Schmidt EKF)  consider.run_consider                           km, rad
issue 44   star images of Hipparcos stars, attitude knowledge, drift   stars.star_field, stars.simulate,               rad, px
                                                                       scenario.star_field_of
issue 44   installation rows and the sample time read against model   readings.installation_check,                    arcsec, s
                                                                       readings.sample_time_reading
issue 54   Mars images' attitude knowledge (lateral (rho sigma)^2)     scenario.Geometry.measurement_variance,         km^2, rad
                                                                       scenario.simulate
issue 54   a window's star rows whitened by their own covariance       stars.StarField.select, stars.joint_covariance  rad
issue 54   navigation error against arc length; tz on and off          navfloor.nav_floor_by_arc, navfloor.tz_nav_effect km, s
=========  ==========================================================  ==============================================  ====================

Layers
    ``setup`` (the config parsed once, frozen) -> ``dynamics``, ``camera``, ``kalman`` ->
    ``ekf``, ``smoother``, ``augmented``, ``crlb``, ``em``, ``batch_ml``, ``consider`` ->
    ``scenario``, ``labels`` (a run's convergence label), ``cases`` -> ``pipeline``,
    ``alternatives``, ``study``, ``peers``, ``readings``, ``navfloor`` -> ``summaries``, ``alternatives_summary``
    (the tables' numbers, A-summary.json's typed records; the frozen ``HeadlineSummary``,
    ``ClaimsSummary`` and ``MethodSummary`` the report reads); ``cli`` at the edge. Every engine
    returns typed records (``cases.CaseRun``, ``ConvergenceStudy``, ``alternatives.AltRun``,
    ``StarsRow``, ``peers.PeerVariant``, ``navfloor.NavFloor`` ...); dicts only at the workflow
    scripts' edge (JSON, pickles). The package draws and words nothing (issue 56 item 2,
    ``tests/test_layers_presentation.py``): the figures, the readings and sentences, the methods'
    and runs' words are in the report layer (``opnav.report.approach``: ``plots``, ``star_plots``,
    ``peer_plots``, ``estimator_plots``, ``text``; ``opnav.report.approach_views``,
    ``approach_scorecard``, ``approach_text``).
"""

from opnav.core.compiled import register_kernel_modules as _register_kernel_modules

# The modules holding this paper's compiled kernels, or whose source a kernel folds in
# (landing.planning.layout's slot numbers), in warm-up order: they key the kernels' on-disk
# cache and the workflow's compile_kernels job warms them (opnav.core.compiled).
_register_kernel_modules(__name__, (
    "opnav.approach.kalman",
    "opnav.approach.ekf",
    "opnav.approach.smoother",
    "opnav.approach.em",
    "opnav.approach.augmented",
))
