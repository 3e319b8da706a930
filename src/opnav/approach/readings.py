"""Two of paper A's statements read against the model (issue 44, item 5).

Installation (Table 1, group "installation matrix", 0..180 deg)
    Paper A sec. 3 varies the camera's installation matrix ``A_c^b`` and reports the same
    estimate for every angle. Its measurement (eq. 3-5) is ``z = A_m(theta) A_c^b A_b^i
    (X_M - r)`` with the body attitude ``A_b^i`` commanded so that the installed camera's
    boresight is on Mars, and ``theta`` the optical-axis deviation in the *camera* frame.
    Then ``A_c^b A_b^i`` is the Mars-tracking camera attitude whatever the installation,
    so the data, and every estimate, cannot depend on it: the claim holds by construction.
    :func:`installation_check` runs that chain for each angle and measures the largest
    change of the noise-free measurement (rounding only), and shows what a deviation
    defined in the *body* frame would do instead (the camera sees ``A_c^b theta_b``: the
    installation then swaps ty with the unobservable tz).

Sample time
    Paper A states a 0.5 s simulation step (sec. 3) and that 250 samples are "4 min" of
    navigation; 250 x 0.5 s is 125 s, while 4 min over 250 samples is 0.96 s a sample.
    :func:`sample_time_reading` puts the config's ``dt_s`` beside both readings with the
    minutes that 250 samples span in each, and the bound after 250 samples at each step
    (the roll variant turns further in a longer span).
Units: arcsec, s, deg.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import camera
from . import scenario as sc
from .setup import Setup


@dataclass(frozen=True)
class InstallationCheck:
    """:func:`installation_check`: the installation angles (deg), the largest relative change of the
    noise-free measurement against angle 0 (``max_rel_change``), whether it is rounding only
    (``by_construction``: below 1e-12), the camera-frame (tx, ty, tz) a body-frame deviation would
    become at each angle (arcsec), and ``why``: its words (the report's)."""

    install_deg: list
    max_rel_change: float
    by_construction: bool
    body_frame_theta_cam_arcsec: list
    why: str = ""


def installation_check(setup: Setup, install_deg, theta_arcsec, variant: str = "literal",
                       n: int = 200) -> InstallationCheck:
    """The measurement chain of paper A for each installation angle (module docstring), over the
    first ``n`` samples; ``theta_arcsec``: the deviation a body-frame reading would turn."""
    geo = sc.build_geometry(setup, variant, n=n)
    los = geo.X_mars[:, :3] - geo.X_true[:, :3]
    A_m = camera.misalignment_exact(sc.rad(theta_arcsec))
    z = []
    for a in install_deg:
        A_c_b = camera.rot_x(np.deg2rad(a))
        A_b_i = camera.body_attitude(geo.C, a)  # commanded: the installed boresight on Mars
        z.append(np.einsum("ij,jk,nkl,nl->ni", A_m, A_c_b, A_b_i, los))
    z = np.stack(z)
    rel = float(np.max(np.linalg.norm(z - z[0], axis=-1) / np.linalg.norm(z[0], axis=-1)))
    cam = [camera.rot_x(np.deg2rad(a)) @ np.asarray(theta_arcsec, float) for a in install_deg]
    return InstallationCheck(install_deg=[float(a) for a in install_deg], max_rel_change=rel,
                             by_construction=bool(rel < 1e-12), body_frame_theta_cam_arcsec=[c.tolist() for c in cam])


@dataclass(frozen=True)
class Steps:
    """A value at each reading of the sample time: the config's ``dt_s``, the paper's stated step
    and the step implied by "250 samples = 4 min"."""

    config: float
    paper_stated: float
    paper_4_min: float


@dataclass(frozen=True)
class BoundAtSteps:
    """The worse of the (tx, ty) bounds after the published samples at our step and at the step
    "4 min" implies, arcsec."""

    config: float
    paper_4_min: float


@dataclass(frozen=True)
class SampleTimeReading:
    """:func:`sample_time_reading`: the published samples, the three steps (s), the minutes the
    samples span at each, and per variant the bound after them at two of the steps."""

    samples: int
    dt_s: Steps
    minutes_for_samples: Steps
    bound_after_samples_arcsec: dict[str, BoundAtSteps]


def sample_time_reading(setup: Setup, pub_headline: dict, pub_simulation: dict,
                        variants=("literal", "roll")) -> SampleTimeReading:
    """Sample time: the config's ``dt_s``, the paper's stated step and the step implied by
    "250 samples = 4 min", with the minutes 250 samples span and the bound of (tx, ty) after
    them at each step (headline case, data after N0 / from t0 as for the variant's bound)."""
    from .cases import headline_case
    from .pipeline import bound_curve
    samples = int(pub_headline["data_to_converge_samples"])
    implied = 60.0 * float(pub_headline["data_to_converge_minutes"]) / samples
    steps = Steps(config=setup.dt_s, paper_stated=float(pub_simulation["dt_s"]), paper_4_min=implied)
    case = headline_case(setup)
    n = setup.segments.N0 + samples

    def bound(dt: float, v: str) -> float:
        s = replace(setup, dt_s=dt)
        geo = sc.build_geometry(s, v, n=n)
        c = bound_curve(s, geo, geo.measurement_variance(case.sigma3_px), case.truth_arcsec, v)
        return float(c[min(samples, len(c) - 1), :2].max())

    at = {v: BoundAtSteps(config=bound(steps.config, v), paper_4_min=bound(steps.paper_4_min, v)) for v in variants}
    minutes = Steps(*(x * samples / 60.0 for x in (steps.config, steps.paper_stated, steps.paper_4_min)))
    return SampleTimeReading(samples=samples, dt_s=steps, minutes_for_samples=minutes, bound_after_samples_arcsec=at)
