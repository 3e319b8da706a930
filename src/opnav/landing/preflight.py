"""Paper B's config checks that need its physics, run before any job (the workflow's
validation step, :func:`opnav.preflight.check_config`, and the CLI call them).

``duration_s`` a multiple of ``filter.dt_s``, ``imu.rate_hz x filter.dt_s`` an integer;
the lander above ground (and above the measurement cut-off altitude, and above its
initial position errors) and its nominal guidance trajectory not through the ground; a
planning margin that leaves part of the detector; the landing site in the configured
camera's view at the start and while the filter measures (a parameter study runs these
checks on every swept value: :func:`opnav.studies.planning.plan`); the B-F5 instant inside the
descent on a filter step; the IMU memory bound. (Method names are checked by the schema,
whose registry tests/test_bad_input.py keeps equal to
:func:`opnav.landing.planner.available_methods`.) One line per problem naming the key;
units as in the config.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping

import numpy as np

from opnav.core.checks import MAX_LANDING_IMU_SAMPLES, multiple as _multiple

if TYPE_CHECKING:
    from opnav.landing.setup import CameraSettings

__all__ = ["landing_problems"]


def landing_problems(section: Mapping) -> list[str]:
    """Cross-key problems of the ``landing`` section (see module docstring), parsed here, at the
    edge, into its :class:`~opnav.landing.setup.Setup`."""
    from opnav.landing.trajectory import nominal_truth
    from opnav.landing.setup import Setup

    c = Setup.from_config(section)
    out: list[str] = []
    k = "invalid config key 'landing."
    T, Dt, rate = c.duration_s, c.filter.dt_s, c.imu.rate_hz
    if not _multiple(T, Dt):
        out.append(f"{k}duration_s': {T} s is not a multiple of landing.filter.dt_s = {Dt} s")
    if not _multiple(rate * Dt, 1.0):
        out.append(f"{k}imu.rate_hz': rate_hz x filter.dt_s = {rate} x {Dt} = {rate * Dt:g} "
                   "is not a positive integer")
    n_steps = max(1, round(T / Dt))
    if T * rate > MAX_LANDING_IMU_SAMPLES:
        out.append(f"{k}imu.rate_hz': duration_s x rate_hz = {T * rate:.0f} IMU samples exceeds "
                   f"the limit {MAX_LANDING_IMU_SAMPLES} (memory)")
    f5 = c.figures.f5_time_s
    if not (0 <= f5 < T) or (f5 > 0 and not _multiple(f5, Dt)):
        out.append(f"{k}figures.f5_time_s': {f5} s must be a filter step "
                   f"(multiple of filter.dt_s = {Dt} s) in [0, duration_s = {T} s)")

    r0 = np.asarray(c.initial_state.r_m, float)
    alt_min = c.filter.min_update_altitude_m
    if r0[2] <= 0:
        out.append(f"{k}initial_state.r_m': the lander starts at altitude {r0[2]:g} m, "
                   "not above the ground z = 0")
        return out
    if c.mc.bounds.r_m >= r0[2]:
        out.append(f"{k}mc.bounds.r_m': initial position errors up to {c.mc.bounds.r_m:g} m "
                   f"would start estimates below the ground (the lander starts at {r0[2]:g} m)")
    out += _margin_problems(c.planner.margin_px, c.camera, f"{k}planner.margin_px'")
    scenarios = _scenario_cameras(c, out)
    for name, cam in scenarios.items():
        out += _margin_problems(c.planner.margin_px, cam, f"{k}scenarios.{name}'")
    if r0[2] <= alt_min:
        out.append(f"{k}initial_state.r_m': the lander starts at {r0[2]:g} m, not above "
                   f"filter.min_update_altitude_m = {alt_min:g} m (no measurement would be taken)")
    if out or not _multiple(T, Dt):
        return out
    t = Dt * np.arange(n_steps + 1)
    try:
        # the nominal trajectory without the terminal acceleration, as this check always read it
        tr = nominal_truth(c, t, terminal=False)
    except (ValueError, np.linalg.LinAlgError) as exc:
        return [*out, f"{k}initial_state': the nominal guidance trajectory is undefined: {exc}"]
    below = np.nonzero(tr.r[:-1, 2] < 0)[0]
    if below.size:
        out.append(f"{k}initial_state': the nominal guidance trajectory goes below ground at "
                   f"t = {t[below[0]]:g} s (initial_state.r_m / v_mps / duration_s)")
        return out
    measuring = tr.r[:, 2] > alt_min                 # where the filter takes bearings
    to_site_B = np.einsum("kij,kj->ki", tr.R_LtoB, -tr.r)
    for key, cam in {"camera": c.camera, **{f"scenarios.{n}": v for n, v in scenarios.items()}}.items():
        out += _view_problems(cam, f"{k}{key}'", t, to_site_B, measuring)
    if not out:    # the user's own methods: imported, signature, name, a probe on the sound start
        from opnav.landing.methods import problems as method_problems

        out += method_problems(c)
    return out


def _scenario_cameras(c, out: list[str]) -> dict[str, CameraSettings]:
    """``{scenario: merged camera}`` of the camera scenarios (``landing.scenarios``) whose
    camera differs from ``landing.camera`` (each is checked as the base camera is); a
    ``landing.headline_scenario`` that names none of them is appended to ``out``."""
    if not c.scenarios:
        return {}
    names = c.scenario_names()
    if c.headline_scenario is not None and c.headline_scenario not in names:
        out.append(f"invalid config key 'landing.headline_scenario': {c.headline_scenario!r} is not one of "
                   f"landing.scenarios ({', '.join(names)})")
        return {}
    merged = c.scenarios_by_name()
    return {n: s.camera for n, s in merged.items() if s.camera != c.camera}


def _margin_problems(margin: float, cam, key: str) -> list[str]:
    half = cam.pixels / 2.0
    if margin >= half:
        return [f"{key}: landing.planner.margin_px = {margin:g} px leaves no part of the "
                f"{cam.pixels} px detector to plan landmarks in (must be < {half:g})"]
    return []


def _view_problems(camera, key: str, t, to_site_B, measuring) -> list[str]:
    """The landing site in ``camera``'s view at the start and while the filter measures."""
    from opnav.landing.camera import make_camera

    fov = camera.fov_deg
    try:
        cam = make_camera(camera)
    except ValueError as exc:
        return [f"{key}: {exc}"]
    seen = cam.in_view(to_site_B)
    if not seen[0]:
        return [f"{key}: the landing site is not in the camera's view at t = 0 "
                f"(fov_deg {fov:g}, tilt_deg {camera.tilt_deg:g}, "
                f"tilt_azimuth_deg {camera.tilt_azimuth_deg:g})"]
    if not np.all(seen[measuring]):
        t_out = t[np.nonzero(measuring & ~seen)[0][0]]
        return [f"{key}: the landing site leaves the camera's view at t = {t_out:g} s "
                f"of the nominal descent (fov_deg {fov:g}, tilt_deg {camera.tilt_deg:g})"]
    return []
