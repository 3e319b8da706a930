"""Paper A's config checks that need its physics, run before any job (the workflow's
validation step, :func:`opnav.preflight.check_config`, and the CLI call them).

The arc and roll-step durations versus ``approach.dt_s``; the navigation-floor arcs
(``nav_floor.arcs_s``: past N0, within the memory limit, not reaching Mars); the approach direction
non-zero and not along the ecliptic pole (the aim-offset direction is ``v_inf_dir x z``);
the arc starting outside Mars and not hitting it (two-body Mars-centred hyperbola);
Mars at its closest fitting the detector; the truth misalignment keeping Mars on the
detector; memory bounds (data length, seeds x samples). Every check reads the
package's own models (dynamics, scenario), so it follows them when they change. Units as
in the config; one line per problem naming the key.
"""

from __future__ import annotations

import math

import numpy as np

from opnav.core.checks import MAX_APPROACH_SAMPLES, MAX_APPROACH_SEED_SAMPLES, multiple as _multiple

__all__ = ["approach_problems"]


def _approach_min_range_km(a: dict, T: float) -> float:
    """Closest range to Mars over [0, T] (s) of the arc that
    :func:`opnav.approach.scenario.initial_truth` starts, km: Mars-centred two-body
    motion, in closed form (the hyperbolic Kepler equation; e.g. Vallado,
    *Fundamentals of Astrodynamics and Applications*, ch. 2). The arc is a hyperbola (its energy is v_inf^2 / 2 > 0): the range
    falls until periapsis and rises after it, so the minimum is the periapsis radius
    p / (1 + e) if periapsis comes within [0, T], else the range at the nearer end
    (at T from the hyperbolic Kepler equation e sinh H - H = M). At or below Mars'
    radius the arc has reached the surface: Mars' radius. (The Sun's tide over an
    approach arc moves it by far less than Mars' radius.) This runs in every
    Snakemake parse, where importing scipy.integrate cost more than the check; a
    nearly parabolic arc (energy lost in round-off) is integrated instead
    (:func:`_integrated_min_range_km`)."""
    from opnav.approach import dynamics, scenario
    from opnav.approach.setup import Setup

    X0 = scenario.initial_truth(Setup.from_config(a)) - dynamics.kepler_state(
        dynamics.KeplerElements.from_config(a["mars_elements"]), 0.0)
    args = (X0[:3], X0[3:], T, dynamics.MU_MARS, dynamics.R_MARS_KM)
    try:
        return _hyperbola_min_range_km(*args)
    except ValueError:                               # nearly parabolic
        return _integrated_min_range_km(*args)


def _hyperbola_min_range_km(r0, v0, T: float, mu: float, r_surface: float) -> float:
    """Closest range over [0, T] s of the two-body hyperbola through (r0 km, v0 km/s)
    about a body of ``mu`` (km^3/s^2), floored to ``r_surface`` km (see
    :func:`_approach_min_range_km`)."""
    r0, v0 = np.asarray(r0, float), np.asarray(v0, float)
    r, v2, rv = float(np.linalg.norm(r0)), float(v0 @ v0), float(r0 @ v0)
    energy = v2 / 2.0 - mu / r
    if not energy > 1e-6 * mu / r:                   # relative to its two ~equal terms
        raise ValueError("not a well-conditioned hyperbola (nearly parabolic)")
    a = mu / (2.0 * energy)                              # |semi-major axis|, km
    h2 = float(np.sum(np.cross(r0, v0) ** 2))
    e = math.sqrt(1.0 + 2.0 * energy * h2 / mu ** 2)
    n = math.sqrt(mu / a ** 3)                           # mean motion, rad/s
    # hyperbolic anomaly now: r = a (e cosh H - 1), r . v = sqrt(mu a) e sinh H
    H0 = math.asinh(rv / (math.sqrt(mu * a) * e))
    M0 = e * math.sinh(H0) - H0
    if rv >= 0.0:                                        # receding already
        rmin = r
    elif -M0 / n <= T:                                   # periapsis within the arc
        rmin = h2 / mu / (1.0 + e)
    else:                                                # still approaching at T
        M, H = M0 + n * T, H0
        for _ in range(100):                             # Newton; f' = e cosh H - 1 > 0
            step = (e * math.sinh(H) - H - M) / (e * math.cosh(H) - 1.0)
            H -= step
            if abs(step) <= 1e-14 * max(1.0, abs(H)):
                break
        rmin = min(r, a * (e * math.cosh(H) - 1.0))
    return r_surface if rmin <= r_surface else rmin


def _integrated_min_range_km(r0, v0, T: float, mu: float, r_surface: float) -> float:
    """:func:`_hyperbola_min_range_km` by scipy's DOP853 integration of the same
    two-body motion (stopped at the surface) and a bounded search around the
    closest sample: any conic, and the reference the closed form is tested against."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar

    def rhs(t, X):
        return np.concatenate([X[3:], -mu * X[:3] / np.linalg.norm(X[:3]) ** 3])

    def surface(t, X):
        return np.linalg.norm(X[:3]) - r_surface

    surface.terminal = True
    sol = solve_ivp(rhs, (0.0, T), np.concatenate([r0, v0]), method="DOP853", rtol=1e-11,
                    atol=1e-7, dense_output=True, events=surface)
    if sol.status == 1:                              # reached the surface
        return r_surface
    rng = np.linalg.norm(sol.y[:3], axis=0)
    i = int(np.argmin(rng))
    lo, hi = sol.t[max(i - 1, 0)], sol.t[min(i + 1, len(sol.t) - 1)]
    rmin = float(rng[i])
    if hi > lo:
        best = minimize_scalar(lambda t: np.linalg.norm(sol.sol(t)[:3]), bounds=(lo, hi),
                               method="bounded", options={"xatol": 1e-7 * max(T, 1.0)})
        rmin = min(rmin, float(best.fun))
    # a grazing dip below the surface within one step has no sign change for the event
    return r_surface if rmin <= r_surface else rmin


def _nav_floor_problem(a: dict) -> str | None:
    """What is wrong with ``approach.nav_floor.arcs_s`` (an arc ending before N0, or longer than
    the memory limit), or None."""
    from opnav.approach import navfloor
    from opnav.approach.setup import Setup

    try:
        nmax = max(navfloor.arcs_samples_of(Setup.from_config(a)))
    except ValueError as exc:
        return str(exc).split(": ", 1)[1]
    if nmax > MAX_APPROACH_SAMPLES:
        return f"the longest arc's {nmax} samples exceed the limit {MAX_APPROACH_SAMPLES} (memory)"
    return None


def approach_problems(a: dict) -> list[str]:
    """Cross-key problems of the ``approach`` section (see module docstring)."""
    from opnav.approach import dynamics, scenario
    from opnav.approach.setup import Setup

    out: list[str] = []
    k = "invalid config key 'approach."
    dt = a["dt_s"]
    s = a["segments"]
    n = Setup.from_config(a).segments.n_samples
    if n > MAX_APPROACH_SAMPLES:
        out.append(f"{k}segments': N0 + L*N = {n} samples exceeds the limit "
                   f"{MAX_APPROACH_SAMPLES} (memory)")
        return out
    for key, seeds, samples in (("n_seeds", a["n_seeds"], n),
                                ("convergence_study.n_seeds", a["convergence_study"]["n_seeds"],
                                 s["N0"] + a["convergence_study"]["data_samples"])):
        if seeds * samples > MAX_APPROACH_SEED_SAMPLES:
            out.append(f"{k}{key}': {seeds} seeds x {samples} samples exceeds the limit "
                       f"{MAX_APPROACH_SEED_SAMPLES} (memory)")
    if s["N0"] + a["convergence_study"]["data_samples"] > MAX_APPROACH_SAMPLES:
        out.append(f"{k}convergence_study.data_samples': N0 + data_samples exceeds the limit "
                   f"{MAX_APPROACH_SAMPLES} (memory)")
    if out:
        return out
    nf = a.get("nav_floor")
    nf_problem = _nav_floor_problem(a) if nf else None
    if nf_problem:
        out.append(f"{k}nav_floor.arcs_s': {nf_problem}")
    roll = a["roll"]
    if roll["steps_deg"] and not _multiple(roll["step_interval_s"], dt):
        out.append(f"{k}roll.step_interval_s': {roll['step_interval_s']} s is not a multiple of "
                   f"approach.dt_s = {dt} s")
    g = a["geometry"]
    d = np.asarray(g["v_inf_dir"], float)
    dn = float(np.linalg.norm(d))
    if dn == 0:
        out.append(f"{k}geometry.v_inf_dir': the approach direction is zero")
        return out
    if float(np.linalg.norm(np.cross(d / dn, [0.0, 0.0, 1.0]))) < 1e-6:
        out.append(f"{k}geometry.v_inf_dir': {list(g['v_inf_dir'])} is along the ecliptic pole "
                   "(the aim-offset direction v_inf_dir x z is undefined)")
        return out
    if g["range_km"] <= dynamics.R_MARS_KM:          # refused by opnav.core.checks.approach_rules
        return out
    T = dt * max(n, s["N0"] + a["convergence_study"]["data_samples"])
    if nf and not nf_problem:
        T = max(T, max(nf["arcs_s"]))
    rmin = _approach_min_range_km(a, T)
    if rmin <= dynamics.R_MARS_KM:
        out.append(f"{k}geometry': the arc reaches Mars' surface within its {T:g} s "
                   "(dt_s x samples); raise geometry.aim_offset_km or range_km, or shorten the arc")
        return out
    cam = a["camera"]
    disc = scenario.mars_disc_px(rmin, cam["ifov_arcsec"])
    if disc > cam["pixels"]:
        out.append(f"{k}camera': Mars ({disc:.0f} px across at its closest, {rmin:.0f} km) does "
                   f"not fit the {cam['pixels']} px detector; raise camera.ifov_arcsec or "
                   "geometry.range_km")
    half_fov = cam["pixels"] * cam["ifov_arcsec"] / 2.0
    for key in ("truth_bias_arcsec", "theta_init_arcsec"):
        off = math.hypot(a[key][0], a[key][1])
        if off >= half_fov:
            out.append(f"{k}{key}': a misalignment of {off:g} arcsec (x, y) puts Mars off the "
                       f"detector (half field of view {half_fov:g} arcsec)")
    if not out:    # the user's own estimators: imported, signature, name, a probe on a small window
        from .estimators import problems as estimator_problems

        out += estimator_problems(a)
    return out
