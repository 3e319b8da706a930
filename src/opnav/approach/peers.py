"""A-P1: Basilisk's pixel/line-bias UKF as a peer on paper A's measurements (issue 12).

Description
    Basilisk (AVSLab, ``bsk`` on PyPI) ships the flight-software module
    ``fswAlgorithms.pixelLineBiasUKF``: a square-root UKF (Wan & van der Merwe)
    with 9 states, the spacecraft position and velocity relative to the planet
    in an inertial frame N and a bias ``b`` of the planet's image (pixel, line,
    apparent radius, px). Nobody here wrote it; running it on the *same*
    measurements as the EM-EKF, the augmented EKF and batch ML gives an
    independent reading of paper A's misalignment.

    Module conventions (read from its source, ``src/fswAlgorithms/
    opticalNavigation/pixelLineBiasUKF/pixelLineBiasUKF.c``, Basilisk 2.12):

    * Units: messages and ``stateInit`` / ``covarInit`` in m, m/s (and px for
      the bias); internally km, km/s. ``qNoise`` is used unconverted, i.e. in
      km^2, (km/s)^2, px^2 per time update. The output covariance is scaled
      back by 1e6 in its position/velocity rows only.
    * Dynamics: two-body about the planet (``MU_MARS = 42828.314`` km^3/s^2 for
      planet id 2), RK4 over each time update; ``b' = 0``.
    * Measurement of sigma point ``(r_N, b)``: ``r_C = [CB][BN] r_N`` with
      ``[CB] = MRP2C(sigma_CB)`` (camera config message) and ``[BN] =
      MRP2C(sigma_BN)`` (attitude message); ``pixel = -r_C,x / r_C,z / X +
      res_x/2 - 0.5 - b_1``, ``line = -r_C,y / r_C,z / Y + res_y/2 - 0.5 - b_2``,
      ``radius = tan(asin(REQ_MARS / |r|)) / X - b_3``, with the pixel pitch
      ``X = 2 tan(FOV res_x / res_y / 2) / res_x`` (``Y`` with FOV along y) and
      ``REQ_MARS = 3396.19`` km.
    * The observation vector has 6 entries: the circle (pixel, line, radius)
      and a pseudo-measurement of the bias, ``round(h(x_hat) - circle)``, with
      the circle's 3x3 ``uncertainty`` (px^2, a covariance) as noise for both.
    * After every measurement update the three bias states are rounded to
      whole pixels (``state[6..8] = round(...)``).
    * UKF constants recommended by its user guide: alpha = 0.02, beta = 2,
      kappa = 0.

    Conversion of paper A's data (:func:`circles_from_los`): the measurement
    ``z_k`` of the pipeline is Mars' position in the *measured* camera frame,
    km. With the camera attitude the spacecraft believes (the calibrated frame
    ``A_c^i``, sent as ``sigma_BN`` of the body attitude ``A_b^i`` and
    ``sigma_CB`` of the installation ``A_c^b``), the module's model maps the
    true Mars-relative position to the noise-free circle of a perfectly
    aligned camera; ``z_k`` goes through the same pinhole formulas with the
    module's Mars radius, so the UKF reads exactly the information the other
    estimators read. The camera's field of view is set so that ``X`` equals
    the pipeline's IFOV. The circle noise (px^2) is the pipeline's km-level
    variance mapped through the same formulas to first order.

    Bias parameterisation: a misalignment ``theta`` (camera frame, paper eq. 5)
    moves Mars' image by ``+theta_y / X`` px in pixel and ``-theta_x / X`` px in
    line; the module models ``circle = h - b``, so ``b = (-theta_y, +theta_x) / X``
    (:func:`bias_px_from_theta`) and ``theta_x = b_line X``, ``theta_y = -b_pixel X``
    (:func:`theta_from_bias_px`); both pinned by tests, one against the module's
    own measurement model.

Why the bias hardly moves (read from ``pixelLineBiasUKF.c``, issue 44)
    Two lines of the module's source decide what its bias state can do on paper A's data:

    * ``pixelLineBiasUKFMeasModel``: ``obs[3..5] = round(h(x_hat) - circle)``, where ``h``
      uses the predicted *position* only. The bias "pseudo-measurement" is the rounded
      pre-fit residual, and its noise is the circle's own ``uncertainty`` (here about
      0.03 px 1-sigma). It tells the filter that the bias equals whatever the predicted
      position does not explain: at the first update the bias jumps to the whole pixel
      nearest (prior lateral position error + misalignment) / X, and afterwards the
      position absorbs the rest, so the residual keeps returning the same whole pixel.
    * ``pixelLineBiasUKFMeasUpdate``: ``state[6..8] = round(state[6..8])`` after every
      update: the bias lives on whole pixels (one pixel = the IFOV, 10 arcsec here), and a
      per-update step below 0.5 px is discarded.

    So the bias moves once (start -> first update) and afterwards only when the predicted
    position drifts by half a pixel against the data; its reported 3-sigma is that of a
    continuous state, not of its one-pixel resolution. Tuning (``peers.basilisk``) follows
    the module's user guide: bias covariance 5 px^2 (22.4 arcsec 1-sigma) and ``qNoise``
    bias (0.1 px)^2 per update; with the earlier 1e-6 px the per-step covariance growth was
    nil and the bias could never change after the first update. The summary records the
    value after the first update, how often the bias changed later, and the quantum
    (A-P1-summary.json ``ukf_first_update_*``, ``ukf_seeds_moving_after_first_update``,
    ``ukf_bias_quantum_arcsec``). The truth-start diagnostic lands on the truth exactly only
    because paper A's headline misalignment is a whole number of pixels (10, 20 arcsec).

Two-body approximation
    The module has no Sun. :func:`two_body_check` computes the Sun's tidal
    acceleration relative to Mars along the truth arc and the position error
    a pure two-body propagation makes over the arc (A-P1-summary.json,
    ``two_body``); the manuscript quotes both numbers.

Units: km, km/s, s, rad inside; px for the circle; arcsec in outputs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from opnav.core.tables import OMIT_NONE

from . import camera
from . import scenario as sc
from .dynamics import ARCSEC, MU_MARS, MU_SUN
from .setup import BasiliskSettings, Setup

#: Basilisk's constants for planet id 2 (astroConstants.h): the module's Mars.
BSK_REQ_MARS_KM = 3396.19
BSK_MU_MARS = 42828.314
BSK_PLANET_ID_MARS = 2




# ----------------------------------------------------------------- camera
@dataclass(frozen=True)
class PeerCamera:
    """The pipeline's camera in the module's parameters."""

    resolution: int  # px, square detector
    fov_rad: float  # edge to edge, along y
    pitch: float  # X = Y = 2 tan(fov/2) / resolution (tangent of one pixel)

    @classmethod
    def from_config(cls, cam_cfg: dict) -> "PeerCamera":
        """From a ``camera`` config mapping (``pixels``, ``ifov_arcsec``): :meth:`of`."""
        return cls.of(int(cam_cfg["pixels"]), float(cam_cfg["ifov_arcsec"]))

    @classmethod
    def of(cls, pixels: int, ifov_arcsec: float) -> "PeerCamera":
        """FOV chosen so that one pixel spans the pipeline's IFOV at the image centre."""
        res = int(pixels)
        pitch = np.tan(ifov_arcsec * ARCSEC)
        fov = 2.0 * np.arctan(0.5 * res * pitch)
        return cls(res, float(fov), float(2.0 * np.tan(fov / 2.0) / res))

    @property
    def centre(self) -> float:
        """Pixel coordinate of the optical axis in the module's convention."""
        return self.resolution / 2 - 0.5


def circles_from_los(z_km: np.ndarray, cam: PeerCamera) -> np.ndarray:
    """Circle (pixel, line, radius) in px (..., 3) of Mars at ``z_km`` (..., 3), camera frame.

    The module's pinhole model (module docstring) applied to the Mars vector
    ``z = -r_C``: ``pixel = -z_x / z_z / X + c``, ``line = -z_y / z_z / X + c``,
    ``radius = tan(asin(REQ_MARS / |z|)) / X``.
    """
    z = np.asarray(z_km, float)
    rho = np.linalg.norm(z, axis=-1)
    px = -z[..., 0] / z[..., 2] / cam.pitch + cam.centre
    ln = -z[..., 1] / z[..., 2] / cam.pitch + cam.centre
    rad = np.tan(np.arcsin(BSK_REQ_MARS_KM / rho)) / cam.pitch
    return np.stack([px, ln, rad], axis=-1)


def circle_variance(z_km: np.ndarray, Rvar_km2: np.ndarray, cam: PeerCamera) -> np.ndarray:
    """Circle noise variances (..., 3), px^2, from the pipeline's km^2 variances (first order).

    Lateral: ``sigma_px = sigma_x / (z_z X)``; radius: ``|d radius / d rho| sigma_rho``
    with ``d radius / d rho = -R / (X rho^2 cos^3(alpha))``, ``sin(alpha) = R / rho``.
    """
    z = np.asarray(z_km, float)
    rho = np.linalg.norm(z, axis=-1)
    sa = BSK_REQ_MARS_KM / rho
    ca = np.sqrt(1.0 - sa**2)
    drad = BSK_REQ_MARS_KM / (cam.pitch * rho**2 * ca**3)
    R = np.asarray(Rvar_km2, float)
    return np.stack([R[..., 0] / (z[..., 2] * cam.pitch) ** 2,
                     R[..., 1] / (z[..., 2] * cam.pitch) ** 2,
                     R[..., 2] * drad**2], axis=-1)


def bias_px_from_theta(theta_rad: np.ndarray, cam: PeerCamera) -> np.ndarray:
    """The module's (pixel, line) bias (..., 2) that a small misalignment ``theta`` causes.

    ``z = A_m u ~ u - theta x u`` with ``u`` on the boresight moves Mars by
    ``(-theta_y rho, +theta_x rho)`` laterally, i.e. the circle by
    ``(+theta_y / X, -theta_x / X)`` px; the module models ``circle = h - b``.
    """
    th = np.asarray(theta_rad, float)
    return np.stack([-th[..., 1], th[..., 0]], axis=-1) / cam.pitch


def theta_from_bias_px(b_px: np.ndarray, cam: PeerCamera) -> np.ndarray:
    """Inverse of :func:`bias_px_from_theta`: (tx, ty) in rad (..., 2) from (b_pixel, b_line)."""
    b = np.asarray(b_px, float)
    return np.stack([b[..., 1], -b[..., 0]], axis=-1) * cam.pitch


def mrp_from_dcm(C: np.ndarray) -> np.ndarray:
    """MRP (..., 3) of the direction cosine matrix ``C`` = [BN] (maps N components to B),
    shadow set chosen so that |sigma| <= 1 (Basilisk's ``C2MRP`` convention)."""
    # scipy.spatial (~0.17 s of import) here: only the UKF job calls this, not the table/figure jobs
    from scipy.spatial.transform import Rotation

    # [BN] is the passive matrix of the rotation that takes N's axes onto B's: R = C^T
    s = Rotation.from_matrix(np.swapaxes(np.asarray(C, float), -1, -2)).as_mrp()
    return s


# ------------------------------------------------------------ two-body check
@dataclass(frozen=True)
class TwoBodyCheck:
    """What the peer's two-body (Mars only) dynamics neglect along the truth arc
    (:func:`two_body_check`): the Sun's tidal acceleration at the start and its maximum (km/s^2),
    the start range (km), the arc (s), the largest two-body position error (km) and the relative
    difference of Basilisk's Mars GM from ours."""

    sun_tidal_kms2_start: float
    sun_tidal_kms2_max: float
    range_km_start: float
    arc_s: float
    two_body_pos_err_km: float
    mu_mars_relative_difference: float


def two_body_check(geo: sc.Geometry) -> TwoBodyCheck:
    """What the module's two-body (Mars only) dynamics neglect along the truth arc.

    ``sun_tidal_kms2``: |a_Sun(r_sc) - a_Sun(r_Mars)| at the start (the
    indirect term cancels Mars' own heliocentric acceleration), and its maximum
    over the arc; ``two_body_pos_err_km``: max |r_2body - r_true| (Mars-centred)
    of a two-body propagation from the true state at t0 over the arc.
    """
    from scipy.integrate import solve_ivp  # 0.3 s of import: only the jobs that call this pay it

    r_rel = geo.X_true[:, :3] - geo.X_mars[:, :3]

    def a_sun(r):
        return -MU_SUN * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3

    tidal = np.linalg.norm(a_sun(geo.X_true[:, :3]) - a_sun(geo.X_mars[:, :3]), axis=-1)

    def f(t, X):
        r = X[:3]
        return np.concatenate([X[3:], -MU_MARS * r / np.linalg.norm(r) ** 3])

    X0 = geo.X_true[0] - geo.X_mars[0]
    sol = solve_ivp(f, (geo.t[0], geo.t[-1]), X0, method="DOP853", t_eval=geo.t, rtol=1e-13, atol=1e-9)
    err = np.linalg.norm(sol.y[:3].T - r_rel, axis=-1)
    return TwoBodyCheck(sun_tidal_kms2_start=float(tidal[0]), sun_tidal_kms2_max=float(tidal.max()),
                        range_km_start=float(np.linalg.norm(r_rel[0])), arc_s=float(geo.t[-1] - geo.t[0]),
                        two_body_pos_err_km=float(err.max()),
                        mu_mars_relative_difference=float(abs(BSK_MU_MARS - MU_MARS) / MU_MARS))


# ------------------------------------------------------------------ the UKF
@dataclass(frozen=True)
class UKFSettings:
    """Tuning of the peer (config ``approach.peers.basilisk``)."""

    alpha: float = 0.02
    beta: float = 2.0
    kappa: float = 0.0
    bias_prior_sigma_px: float = 10.0  # pixel and line
    radius_bias_prior_sigma_px: float = 10.0
    bias_process_sigma_px: float = 1e-6  # per time update; > 0 (the module's Cholesky of qNoise)

    @classmethod
    def of(cls, b: BasiliskSettings, cam: PeerCamera) -> "UKFSettings":
        return cls(alpha=b.alpha, beta=b.beta, kappa=b.kappa,
                   bias_prior_sigma_px=b.bias_prior_sigma_arcsec * ARCSEC / cam.pitch,
                   radius_bias_prior_sigma_px=b.radius_bias_prior_sigma_px,
                   bias_process_sigma_px=b.bias_process_sigma_px)


@dataclass
class UKFRun:
    """Output of the module per sample (index 0 = the prior at t0)."""

    state: np.ndarray  # (n+1, 9) km, km/s, px (converted from the module's m)
    covar: np.ndarray  # (n+1, 9, 9) km^2..., px^2
    postfit: np.ndarray  # (n+1, 6) px


def run_ukf(circles: np.ndarray, circle_var: np.ndarray, t_s: np.ndarray, sigma_BN: np.ndarray,
            sigma_CB: np.ndarray, cam: PeerCamera, x0_km: np.ndarray, P0_km: np.ndarray,
            Q_km: np.ndarray, settings: UKFSettings, steps: int | None = None) -> UKFRun:
    """Run Basilisk's pixelLineBiasUKF over the samples 1..n (sample 0 is the prior).

    circles (n+1, 3) px; circle_var (n+1, 3) px^2; t_s (n+1,) s from t0 = 0;
    sigma_BN (n+1, 3) body attitude MRPs; sigma_CB (3,) camera-on-body MRP;
    x0_km (6,) Mars-centred prior mean (km, km/s); P0_km (6, 6); Q_km (6, 6)
    per step. The bias starts at 0 with the settings' prior.
    """
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import pixelLineBiasUKF
    from Basilisk.utilities import SimulationBaseClass

    n = len(t_s) - 1 if steps is None else min(steps, len(t_s) - 1)
    # the module runs inside a Basilisk simulation (which wires its logger; a bare
    # UpdateState() call crashes); one task step per measurement time
    sim = SimulationBaseClass.SimBaseClass()
    dt_ns = int(round((t_s[1] - t_s[0]) * 1e9))
    sim.CreateNewProcess("opnav").addTask(sim.CreateNewTask("peer", dt_ns))
    m = pixelLineBiasUKF.pixelLineBiasUKF()
    sim.AddModelToTask("peer", m)
    m.ModelTag = "opnavPeerUKF"
    m.planetIdInit = BSK_PLANET_ID_MARS
    m.alpha, m.beta, m.kappa = settings.alpha, settings.beta, settings.kappa
    m.stateInit = (np.asarray(x0_km, float) * 1e3).tolist() + [0.0, 0.0, 0.0]
    P = np.zeros((9, 9))
    P[:6, :6] = np.asarray(P0_km, float) * 1e6
    P[6:, 6:] = np.diag([settings.bias_prior_sigma_px**2] * 2 + [settings.radius_bias_prior_sigma_px**2])
    m.covarInit = P.ravel().tolist()
    Q = np.zeros((9, 9))
    Q[:6, :6] = Q_km
    Q[6:, 6:] = settings.bias_process_sigma_px**2 * np.eye(3)
    m.qNoise = Q.ravel().tolist()

    camp = messaging.CameraConfigMsgPayload()
    camp.fieldOfView = cam.fov_rad
    camp.resolution = [cam.resolution, cam.resolution]
    camp.sigma_CB = list(map(float, sigma_CB))
    cam_msg = messaging.CameraConfigMsg().write(camp)
    att_msg = messaging.NavAttMsg()
    circ_msg = messaging.OpNavCirclesMsg()
    m.cameraConfigInMsg.subscribeTo(cam_msg)
    m.attInMsg.subscribeTo(att_msg)
    m.circlesInMsg.subscribeTo(circ_msg)
    out = m.filtDataOutMsg

    state = np.full((n + 1, 9), np.nan)
    covar = np.full((n + 1, 9, 9), np.nan)
    post = np.full((n + 1, 6), np.nan)
    state[0] = np.r_[x0_km, 0.0, 0.0, 0.0]
    covar[0] = P
    covar[0, :6, :6] = P0_km
    sim.InitializeSimulation()  # Reset at t = 0; no measurement yet
    scale = np.ones(9)
    scale[:6] = 1e-3  # m -> km (the module's output message)
    cscale = np.ones((9, 9))
    cscale[:6, :] = 1e-6  # rows 0..5 are scaled by the module (and the first 6 of row 6)
    cscale[6, :6] = 1e-6
    # the inputs as Python floats for all samples at once; one payload of each kind, refilled
    # per sample (write() copies it into the message)
    tns_all = [int(round(t * 1e9)) for t in np.asarray(t_s, float)[: n + 1]]
    sig_all = np.asarray(sigma_BN, float)[: n + 1].tolist()
    circ_all = np.asarray(circles, float)[: n + 1].tolist()
    unc_all = (np.asarray(circle_var, float)[: n + 1, :, None] * np.eye(3)).reshape(-1, 9).tolist()
    att = messaging.NavAttMsgPayload()
    c = messaging.OpNavCirclesMsgPayload()
    c.valid = 1
    c.planetIds = [BSK_PLANET_ID_MARS]
    for k in range(1, n + 1):
        tns = tns_all[k]
        att.sigma_BN = sig_all[k]
        att_msg.write(att, tns)
        c.timeTag = tns
        c.circlesCenters = circ_all[k][:2]
        c.circlesRadii = circ_all[k][2:]
        c.uncertainty = unc_all[k]
        circ_msg.write(c, tns)
        sim.ConfigureStopTime(tns)
        sim.ExecuteSimulation()
        o = out.read()
        state[k] = np.asarray(o.state, float) * scale
        covar[k] = np.asarray(o.covar, float).reshape(9, 9) * cscale
        post[k] = np.asarray(o.postFitRes, float)
    return UKFRun(state, covar, post)


# --------------------------------------------------------- A-P1 on paper A's data
def peer_settings(setup: Setup) -> tuple[PeerCamera, UKFSettings]:
    """The module's camera and tuning from the setup."""
    cam = PeerCamera.of(setup.camera.pixels, setup.camera.ifov_arcsec)
    return cam, UKFSettings.of(setup.peers.basilisk, cam)


def ukf_inputs(geo: sc.Geometry, install_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Attitude inputs: body ``sigma_BN`` per sample (n+1, 3) and camera ``sigma_CB`` (3,).

    The spacecraft knows the calibrated camera frame ``A_c^i`` (with the roll of the
    variant) and the installation ``A_c^b = rot_x(install)``; the body attitude is
    ``A_b^i = A_c^b^T A_c^i``, so the module's ``[CB][BN]`` is ``A_c^i`` again.
    """
    A_b_i = camera.body_attitude(geo.C, install_deg)
    return mrp_from_dcm(A_b_i), mrp_from_dcm(camera.rot_x(np.deg2rad(install_deg)))


@dataclass(frozen=True)
class PeerRun:
    """The peer UKF on one case's measurements (:func:`run_peer`), per seed: the final (tx, ty, tz)
    estimate and its 3-sigma (arcsec), the estimate after the first update, the samples after it at
    which the (whole-pixel) bias state changed, the bias quantum (arcsec), the radius bias (px), the
    final and RMS position error (km), every ``stride`` samples the estimate history with its
    3-sigma (``t_hist_s``), the true bias in pixels; and the bound of the peer's information
    (``crlb_peer_arcsec``, Q = 0 beside; None until :func:`run_variant` sets it)."""

    variant: str
    case_id: str
    seed_indices: np.ndarray
    start: str
    truth_arcsec: np.ndarray
    theta_final_arcsec: np.ndarray
    sigma3_final_arcsec: np.ndarray
    theta_first_update_arcsec: np.ndarray
    bias_changes_after_first: np.ndarray
    bias_quantum_arcsec: float
    radius_bias_px: np.ndarray
    pos_err_final_km: np.ndarray
    pos_err_rms_km: np.ndarray
    t_hist_s: np.ndarray
    theta_hist_arcsec: np.ndarray
    sigma3_hist_arcsec: np.ndarray
    truth_bias_px: np.ndarray
    crlb_peer_arcsec: np.ndarray | None = None
    crlb_peer_q0_arcsec: np.ndarray | None = None


@dataclass(frozen=True)
class PeerVariant:
    """A-P1's job for one variant (:func:`run_variant`): the two-body check and each run of
    :data:`RUNS` by name."""

    variant: str
    two_body: TwoBodyCheck
    runs: dict[str, PeerRun]


def run_peer(setup: Setup, variant: str, case, seed_indices, truth_arcsec=None,
             geo: sc.Geometry | None = None, steps: int | None = None, stride: int = 10,
             start: str = "prior") -> PeerRun:
    """The peer UKF on the measurements of ``case`` (same streams as the EM-EKF) per seed.

    ``truth_arcsec`` overrides the case's truth (the bias-free sanity case uses
    zeros with the same noise). ``start="truth"`` puts the prior mean on the true
    state (prior covariance unchanged): a diagnostic, like the EM-EKF's
    reference-start, of what the module does when the position is known. Returns per seed the final (tx, ty) estimate and
    its 3-sigma in arcsec, the radius bias (px), the final and RMS position error
    (km) and, every ``stride`` samples, the estimate history for the figure.
    """
    from .cases import simulate_case
    geo = geo or sc.build_geometry(setup, variant)
    cam, settings = peer_settings(setup)
    truth = np.asarray(case.truth_arcsec if truth_arcsec is None else truth_arcsec, float)
    seeds = list(seed_indices)
    Rvar, z, dx0 = simulate_case(setup, geo, case, seeds, setup.initial_error.mode, truth)
    sBN, sCB = ukf_inputs(geo, case.install_deg)
    r_true = geo.X_true[:, :3] - geo.X_mars[:, :3]
    est, sig3, rad_b, pos_fin, pos_rms, hist, hist_sig, first, moves = [], [], [], [], [], [], [], [], []
    for s in range(z.shape[0]):
        x0 = (geo.X_true[0] if start == "truth" else geo.X_ref[0] + dx0[s]) - geo.X_mars[0]
        run = run_ukf(circles_from_los(z[s], cam), circle_variance(z[s], Rvar, cam), geo.t, sBN, sCB,
                      cam, x0, geo.P0, geo.Q, settings, steps=steps)
        n = run.state.shape[0] - 1
        th = sc.arcsec(theta_from_bias_px(run.state[:, 6:8], cam))  # (n+1, 2)
        sd_px = np.sqrt(np.diagonal(run.covar[:, 6:8, 6:8], axis1=1, axis2=2))
        sd = sc.arcsec(sd_px[:, ::-1] * cam.pitch)  # tx from the line bias, ty from the pixel bias
        est.append(th[-1])
        first.append(th[1])  # after the first measurement update
        # samples after the first update at which the (whole-pixel) bias state changed
        moves.append(int(np.count_nonzero(np.any(np.diff(run.state[1:, 6:8], axis=0) != 0, axis=1))))
        sig3.append(3.0 * sd[-1])
        rad_b.append(run.state[-1, 8])
        e = np.linalg.norm(run.state[:, :3] - r_true[:n + 1], axis=-1)
        pos_fin.append(e[-1])
        pos_rms.append(np.sqrt(np.mean(e[1:] ** 2)))
        hist.append(th[1::stride])  # from the first measurement (index 0: the prior)
        hist_sig.append(3.0 * sd[1::stride])
    n = len(geo.t) - 1 if steps is None else min(steps, len(geo.t) - 1)
    return PeerRun(variant=variant, case_id=case.case_id, seed_indices=np.asarray(seeds), start=start,
                   truth_arcsec=truth, theta_final_arcsec=np.stack(est), sigma3_final_arcsec=np.stack(sig3),
                   theta_first_update_arcsec=np.stack(first), bias_changes_after_first=np.asarray(moves),
                   bias_quantum_arcsec=float(sc.arcsec(cam.pitch)),
                   radius_bias_px=np.asarray(rad_b), pos_err_final_km=np.asarray(pos_fin),
                   pos_err_rms_km=np.asarray(pos_rms), t_hist_s=geo.t[1:n + 1:stride],
                   theta_hist_arcsec=np.stack(hist), sigma3_hist_arcsec=np.stack(hist_sig),
                   truth_bias_px=bias_px_from_theta(sc.rad(truth[:2].tolist() + [0.0]), cam))


def peer_bound(setup: Setup, geo: sc.Geometry, case, truth_arcsec=None, zero_q: bool = False) -> np.ndarray:
    """1-sigma CRLB (tx, ty, tz) in arcsec on the peer's information: every sample from t0
    with the prior ``P_X0`` and the peer's bias prior (the EM-EKF's ``literal`` set);
    ``zero_q``: the same without process noise (the truth has none)."""
    from dataclasses import replace

    from .crlb import crlb_curve

    cam, settings = peer_settings(setup)
    truth = np.asarray(case.truth_arcsec if truth_arcsec is None else truth_arcsec, float)
    Rvar = geo.measurement_variance(case.sigma3_px)
    sig = settings.bias_prior_sigma_px * cam.pitch
    win = geo.window(Rvar)
    win = replace(win, Q=np.zeros_like(win.Q)) if zero_q else win
    return sc.arcsec(crlb_curve(win, geo.u_true, geo.P0, sc.rad(truth), sig)[-1])


#: The A-P1 runs per variant: (name, truth override, prior-mean rule).
RUNS = (("headline", None, "prior"), ("bias_free", np.zeros(3), "prior"), ("truth_start", None, "truth"))
#: the peer UKF's key in A-P1's ``estimator`` column (the others': ``em_<scheme>``, ``augmented``,
#: ``batch_ml``); the words of the keys and of the runs are the report's (opnav.report.approach.text)
PEER = "ukf"


def run_variant(setup: Setup, variant: str, log=None) -> PeerVariant:
    """A-P1 simulation job: the headline case and the bias-free sanity case of ``variant``."""
    from .cases import headline_case
    geo = sc.build_geometry(setup, variant)
    case = headline_case(setup)
    seeds = range(setup.n_seeds)
    out = PeerVariant(variant=variant, two_body=two_body_check(geo), runs={})
    for name, truth, start in RUNS:
        r = run_peer(setup, variant, case, seeds, truth_arcsec=truth, geo=geo, start=start)
        r = replace(r, crlb_peer_arcsec=peer_bound(setup, geo, case, truth),
                    crlb_peer_q0_arcsec=peer_bound(setup, geo, case, truth, zero_q=True))
        out.runs[name] = r
        if log:
            log.info("A-P1 %s %s: UKF (tx, ty) %s +- %s arcsec (3 sigma, seed mean); truth %s",
                     variant, name, np.round(r.theta_final_arcsec.mean(0), 3),
                     np.round(r.sigma3_final_arcsec.mean(0), 4), r.truth_arcsec[:2])
    return out


# ------------------------------------------------------------ A-P1 table
@dataclass(frozen=True)
class TableRow:
    """One A-P1 row (:func:`comparison_frame`; the field order is the table's columns): the
    estimator and run, the truth, the seed mean and sd of (tx, ty), the RMS error, the estimator's
    own 3-sigma (median over seeds; NaN without one) and the seeds within it, the CRLB 3-sigma of
    the data the estimate used (Q = 0 beside) and the seeds within it; arcsec."""

    variant: str
    estimator: str
    run: str
    truth_x_arcsec: float
    truth_y_arcsec: float
    n_seeds: int
    est_x_mean_arcsec: float
    est_x_sd_arcsec: float
    est_y_mean_arcsec: float
    est_y_sd_arcsec: float
    rmse_xy_arcsec: float
    own_3sigma_x_arcsec: float
    own_3sigma_y_arcsec: float
    within_own_3sigma: float
    within_own_3sigma_text: str
    crlb_3sigma_x_arcsec: float
    crlb_3sigma_y_arcsec: float
    within_crlb_3sigma: float
    crlb_q0_3sigma_x_arcsec: float
    crlb_q0_3sigma_y_arcsec: float


def _row(variant, method, run, truth, th, own3=None, crlb3=None, crlb3_q0=None) -> TableRow:
    """One table row: seed mean and sd of (tx, ty), own 3-sigma, CRLB 3-sigma of the data the
    estimate used (and with Q = 0: ``crlb3_q0``), coverage."""
    th = np.asarray(th, float)[:, :2]
    err = th - np.asarray(truth, float)[:2]
    sd = th.std(0, ddof=1) if len(th) > 1 else np.full(2, np.nan)
    if own3 is not None:
        own3 = np.asarray(own3, float)[:, :2]
        inside = np.all(np.abs(err) <= own3, axis=1)
        own = (float(np.median(own3[:, 0])), float(np.median(own3[:, 1])), float(np.mean(inside)),
               f"{int(inside.sum())} of {len(inside)}")
    else:
        own = (np.nan, np.nan, np.nan, "--")
    c = np.full(2, np.nan) if crlb3 is None else np.asarray(crlb3, float)[:2]
    c0 = np.full(2, np.nan) if crlb3_q0 is None else np.asarray(crlb3_q0, float)[:2]
    return TableRow(
        variant=variant, estimator=method, run=run, truth_x_arcsec=float(truth[0]), truth_y_arcsec=float(truth[1]),
        n_seeds=len(th), est_x_mean_arcsec=float(th[:, 0].mean()), est_x_sd_arcsec=float(sd[0]),
        est_y_mean_arcsec=float(th[:, 1].mean()), est_y_sd_arcsec=float(sd[1]),
        rmse_xy_arcsec=float(np.sqrt(np.mean(err**2))), own_3sigma_x_arcsec=own[0], own_3sigma_y_arcsec=own[1],
        within_own_3sigma=own[2], within_own_3sigma_text=own[3],
        crlb_3sigma_x_arcsec=float(c[0]), crlb_3sigma_y_arcsec=float(c[1]),
        within_crlb_3sigma=float(np.mean(np.all(np.abs(err) <= c, axis=1))) if crlb3 is not None else np.nan,
        crlb_q0_3sigma_x_arcsec=float(c0[0]), crlb_q0_3sigma_y_arcsec=float(c0[1]))


def comparison_frame(peer: list[PeerVariant], em: list, alt: list, case_id: str = "T1-01"):
    """A-P1 table: per variant, the EM-EKF (each scheme), augmented EKF, batch ML and the
    peer UKF (headline, zero-misalignment sanity, truth-start diagnostic), arcsec; the
    ``estimator`` and ``run`` columns hold keys (``em_plain``, ``em_squarem``, growing windows
    ``em_growing_squarem`` ... :data:`PEER`; a key of
    :data:`RUNS`), their words are the report's (:func:`opnav.report.approach.text.p1_words`).

    ``peer``: :func:`run_variant` outputs; ``em``: EM-EKF Monte-Carlo runs
    (:func:`opnav.approach.pipeline.run_group`); ``alt``: A-X2 runs
    (:func:`opnav.approach.alternatives.run_case_alternatives`). Each estimate is set
    beside the bound of the data it used, with Q = 0 beside: the EM-EKF's last window when
    sliding (``crlb_arcsec``, ``crlb_q0_arcsec``), all the segments' data for the augmented
    EKF and batch ML (``crlb_total_arcsec``, ``crlb_total_q0_arcsec``); the peer's is
    :func:`peer_bound` on all data from t0.
    """
    import pandas as pd

    rows = []
    for p in peer:
        v = p.variant
        ems = [r for r in em if r.variant == v and r.case_id == case_id]
        bound = 3.0 * np.asarray(ems[0].bounds.crlb_total_arcsec, float) if ems else None
        bound0 = 3.0 * np.asarray(ems[0].bounds.crlb_total_q0_arcsec, float) if ems else None
        for r in ems:     # a scheme's key: em_<method> sliding, em_<mode>_<method> otherwise (no two alike)
            key = f"em_{r.method}" if r.mode == "sliding" else f"em_{r.mode}_{r.method}"
            rows.append(_row(v, key, "headline",
                             r.truth_arcsec, r.theta_final_arcsec, None, 3.0 * np.asarray(r.bounds.crlb_arcsec),
                             crlb3_q0=3.0 * np.asarray(r.bounds.crlb_q0_arcsec)))
        for a in (a for a in alt if a.variant == v and a.case_id == case_id):
            for m, d in a.methods():
                own = 3.0 * d.sigma_final_arcsec if getattr(d, "sigma_final_arcsec", None) is not None else None
                rows.append(_row(v, m, "headline", a.truth_arcsec,
                                 d.theta_final_arcsec, own, bound, crlb3_q0=bound0))
        for name, r in p.runs.items():
            rows.append(_row(v, PEER, name, r.truth_arcsec,
                             r.theta_final_arcsec, r.sigma3_final_arcsec, 3.0 * r.crlb_peer_arcsec,
                             crlb3_q0=3.0 * np.asarray(r.crlb_peer_q0_arcsec)))
    return pd.DataFrame([dataclasses.asdict(r) for r in rows])


#: the A-P1 table's columns each estimator's entry of A-P1-summary.json holds
P1_FIELDS = ("est_x_mean_arcsec", "est_x_sd_arcsec", "est_y_mean_arcsec", "est_y_sd_arcsec", "own_3sigma_x_arcsec",
             "own_3sigma_y_arcsec", "within_own_3sigma", "crlb_3sigma_x_arcsec", "crlb_3sigma_y_arcsec",
             "crlb_q0_3sigma_x_arcsec", "rmse_xy_arcsec", "within_own_3sigma_text")


@dataclass(frozen=True)
class P1Variant:
    """One variant of A-P1-summary.json (:func:`summary`): each estimator's table entry by its key
    (``em_plain`` ... ``ukf_headline``; written at the variant's top level) and the peer's own
    numbers: its final position error (km), the true bias in pixels, its bias after the first
    update (arcsec), the seeds whose bias moved later and how often, the bias quantum (arcsec),
    whether the bias-free run stays within its own 3-sigma, and the bound over its own 3-sigma."""

    estimators: dict[str, dict[str, Any]] = field(metadata={"json_flatten": True})
    ukf_pos_err_final_km: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_truth_bias_pixel_px: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_truth_bias_line_px: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_first_update_x_arcsec: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_first_update_y_arcsec: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_seeds_moving_after_first_update: int | None = field(default=None, metadata=OMIT_NONE)
    ukf_bias_changes_after_first_mean: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_bias_quantum_arcsec: float | None = field(default=None, metadata=OMIT_NONE)
    ukf_bias_free_within_own_3sigma_all: bool | None = field(default=None, metadata=OMIT_NONE)
    ukf_bound_over_own_3sigma_x: float | None = field(default=None, metadata=OMIT_NONE)
    #: its reading in words (the report layer's: opnav.report.approach.text.p1_summary_words)
    ukf_bound_over_own_reading: str | None = field(default=None, metadata=OMIT_NONE)


@dataclass(frozen=True)
class P1Summary:
    """A-P1-summary.json: per variant its :class:`P1Variant`, the two-body check and the seeds."""

    ran: bool
    variants: dict[str, P1Variant]
    two_body: TwoBodyCheck
    n_seeds: int


def summary(table, peer: list[PeerVariant]) -> P1Summary:
    """Numbers for the manuscript macros (A-P1-summary.json) from the A-P1 table and the peer runs."""
    entries: dict[str, dict[str, dict[str, Any]]] = {}
    for r in table.itertuples():
        k = f"{PEER}_{r.run}" if r.estimator == PEER else r.estimator
        entries.setdefault(r.variant, {})[k] = {c: getattr(r, c) for c in P1_FIELDS}
    variants = {v: P1Variant(estimators=e) for v, e in entries.items()}
    for p in peer:
        h, b = p.runs["headline"], p.runs["bias_free"]
        hr = entries.get(p.variant, {})["ukf_headline"]
        # what the bias state does (module docstring, 'Why the bias hardly moves'): its value after
        # the first update (seed mean), the seeds whose bias changed later in the arc, its quantum
        fx, fy = map(float, np.mean(h.theta_first_update_arcsec, axis=0))
        px, ln = map(float, h.truth_bias_px)
        variants[p.variant] = P1Variant(
            estimators=entries.get(p.variant, {}), ukf_pos_err_final_km=float(np.mean(h.pos_err_final_km)),
            ukf_truth_bias_pixel_px=px, ukf_truth_bias_line_px=ln, ukf_first_update_x_arcsec=fx,
            ukf_first_update_y_arcsec=fy,
            ukf_seeds_moving_after_first_update=int(np.count_nonzero(h.bias_changes_after_first)),
            ukf_bias_changes_after_first_mean=float(np.mean(h.bias_changes_after_first)),
            ukf_bias_quantum_arcsec=h.bias_quantum_arcsec,
            ukf_bias_free_within_own_3sigma_all=bool(np.all(np.abs(b.theta_final_arcsec) <= b.sigma3_final_arcsec)),
            ukf_bound_over_own_3sigma_x=hr["crlb_3sigma_x_arcsec"] / hr["own_3sigma_x_arcsec"])
    return P1Summary(ran=True, variants=variants, two_body=peer[0].two_body, n_seeds=int(table["n_seeds"].max()))


def seed_frame(peer: list[PeerVariant]):
    """Per seed and run: the peer's final (tx, ty), its 3-sigma and the position error (long CSV)."""
    import pandas as pd

    rows = []
    for p in peer:
        for name, r in p.runs.items():
            for i, s in enumerate(r.seed_indices):
                rows.append({"variant": p.variant, "run": name, "seed": int(s),
                             "truth_x_arcsec": r.truth_arcsec[0], "truth_y_arcsec": r.truth_arcsec[1],
                             "est_x_arcsec": r.theta_final_arcsec[i, 0], "est_y_arcsec": r.theta_final_arcsec[i, 1],
                             "sigma3_x_arcsec": r.sigma3_final_arcsec[i, 0],
                             "sigma3_y_arcsec": r.sigma3_final_arcsec[i, 1],
                             "radius_bias_px": r.radius_bias_px[i],
                             "pos_err_final_km": r.pos_err_final_km[i], "pos_err_rms_km": r.pos_err_rms_km[i]})
    return pd.DataFrame(rows)
