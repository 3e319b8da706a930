"""Config-time physics and consistency checks, run before any job.

Description
-----------
The JSON schema checks each key alone (type, range); :func:`config_problems`
checks what only several keys together decide, so that a config that would
crash, hang or quietly produce garbage inside a job is refused at once, with
one line per problem naming the keys:

* paper A: the arc and roll-step durations versus ``approach.dt_s``; the
  approach direction non-zero and not along the ecliptic pole (the aim-offset
  direction is ``v_inf_dir x z``); the arc starting outside Mars and not
  hitting it; Mars (at its closest along the arc, two-body Mars-centred
  hyperbola) fitting the detector; the truth misalignment keeping Mars on the
  detector; ``table1_variants`` inside ``variants`` and ``peers.variants``
  inside ``table1_variants``; memory bounds (data
  length, seeds x samples);
* paper B: ``duration_s`` a multiple of ``filter.dt_s``, ``imu.rate_hz x
  filter.dt_s`` an integer; the lander above ground (and above the
  measurement-cut-off altitude, and above its initial position errors) and its
  nominal guidance trajectory not through the ground; a planning margin that
  leaves part of the detector; the landing site in the configured camera's view at the
  start and while the filter measures (a parameter study runs these checks on
  every swept value: :func:`opnav.studies.plan`);
  every method name known to :func:`opnav.landing.planner.available_methods`
  (the planner's own registry); the B-X1 reference among the flown methods;
  the B-F5 instant inside the descent on a filter step; memory bounds;
* both: ``results_dir`` non-empty and outside the checkout's tracked folders.

Use: :func:`opnav.config.validate_config` calls :func:`config_problems` after
the schema (Snakefile validation and the ``opnav`` CLI both go through it).
Every check reads the package's own models (camera, guidance, constants), so
it follows them when they change. Units as in the config.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["config_problems", "approach_problems", "landing_problems", "results_dir_problems",
           "TRACKED_DIRS", "MAX_APPROACH_SAMPLES", "MAX_APPROACH_SEED_SAMPLES",
           "MAX_LANDING_IMU_SAMPLES", "MAX_LANDING_RUN_STEPS"]

#: Memory bounds. An approach arc of n samples keeps n one-step STMs (6x6) per
#: geometry and (seeds x n) filter states and covariances per batch.
MAX_APPROACH_SAMPLES = 200_000
MAX_APPROACH_SEED_SAMPLES = 2_000_000
#: A descent keeps its truth at every IMU sample; a Monte Carlo keeps per-run
#: histories of every filter step.
MAX_LANDING_IMU_SAMPLES = 1_000_000
MAX_LANDING_RUN_STEPS = 5_000_000

#: Folders of the checkout that hold tracked files: results_dir may not be
#: (inside) one of them, nor the checkout itself.
TRACKED_DIRS = ("paper", "src", "config", "workflow", "profiles", "tests", "benchmarks", ".git",
                ".snakemake")


def _multiple(value: float, step: float, tol: float = 1e-9) -> bool:
    k = round(value / step)
    return k >= 1 and abs(k * step - value) <= tol * max(1.0, abs(value))


def _duplicates(items) -> list:
    seen, dup = set(), []
    for x in items:
        if x in seen and x not in dup:
            dup.append(x)
        seen.add(x)
    return dup


def config_problems(config: dict, root: str | Path | None = None,
                    workdir: str | Path | None = None) -> list[str]:
    """Every problem of a schema-valid ``config`` (defaults filled), one line each,
    naming the key(s). ``root`` is the checkout (default: the working directory),
    ``workdir`` where relative outputs go (default: ``root``)."""
    out = results_dir_problems(config.get("results_dir", "results"), root, workdir)
    if "approach" in config:
        out += approach_problems(config["approach"])
    if "landing" in config:
        out += landing_problems(config["landing"])
    return out


def results_dir_problems(results_dir: str, root: str | Path | None = None,
                         workdir: str | Path | None = None) -> list[str]:
    """``results_dir`` must be non-empty, not the checkout ``root`` (default: the
    working directory) and not inside one of its tracked folders; a relative
    ``results_dir`` is taken from ``workdir`` (where Snakemake writes; default
    ``root``)."""
    if not str(results_dir).strip():
        return ["invalid config key 'results_dir': empty (generated files would land in the checkout)"]
    base = Path(root or Path.cwd()).resolve()
    p = Path(results_dir)
    p = (p if p.is_absolute() else Path(workdir or base) / p).resolve()
    if p == base:
        return [f"invalid config key 'results_dir': {results_dir!r} is the checkout itself"]
    for d in TRACKED_DIRS:
        t = base / d
        if p == t or t in p.parents:
            return [f"invalid config key 'results_dir': {results_dir!r} is inside the tracked "
                    f"folder {d}/ (choose e.g. 'results')"]
    return []


# --------------------------------------------------------------------- paper A

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

    X0 = scenario.initial_truth(a) - dynamics.kepler_state(
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


def approach_problems(a: dict) -> list[str]:
    """Cross-key problems of the ``approach`` section (see module docstring)."""
    from opnav.approach import dynamics, scenario

    out: list[str] = []
    k = "invalid config key 'approach."
    dt = a["dt_s"]
    s = a["segments"]
    n = scenario.n_samples(a)
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
    roll = a["roll"]
    if roll["steps_deg"] and not _multiple(roll["step_interval_s"], dt):
        out.append(f"{k}roll.step_interval_s': {roll['step_interval_s']} s is not a multiple of "
                   f"approach.dt_s = {dt} s")
    for key in ("variants", "table1_variants", "methods"):
        node = a
        for part in key.split("."):
            node = node[part]
        dup = _duplicates(node)
        if dup:
            out.append(f"{k}{key}': duplicated {', '.join(map(str, dup))}")
    extra = [v for v in a["table1_variants"] if v not in a["variants"]]
    if extra:
        out.append(f"{k}table1_variants': {', '.join(extra)} not in approach.variants "
                   f"({', '.join(a['variants'])})")
    peers = a.get("peers", {}).get("variants", [])
    extra = [v for v in peers if v not in a["table1_variants"]]
    if extra:  # A-P1 sets the peer beside the A-X2 results of those variants
        out.append(f"{k}peers.variants': {', '.join(extra)} not in approach.table1_variants "
                   f"({', '.join(a['table1_variants'])})")
    dup = _duplicates(peers)
    if dup:
        out.append(f"{k}peers.variants': duplicated {', '.join(map(str, dup))}")
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
    if g["range_km"] <= dynamics.R_MARS_KM:
        out.append(f"{k}geometry.range_km': the arc starts inside Mars "
                   f"({g['range_km']} km <= Mars radius {dynamics.R_MARS_KM} km)")
        return out
    T = dt * max(n, s["N0"] + a["convergence_study"]["data_samples"])
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
    return out


# --------------------------------------------------------------------- paper B

def landing_problems(c: dict) -> list[str]:
    """Cross-key problems of the ``landing`` section (see module docstring)."""
    from opnav.landing.camera import camera_from_config
    from opnav.landing.planner import available_methods
    from opnav.landing.trajectory import truth_states

    out: list[str] = []
    k = "invalid config key 'landing."
    T, Dt, rate = c["duration_s"], c["filter"]["dt_s"], c["imu"]["rate_hz"]
    if not _multiple(T, Dt):
        out.append(f"{k}duration_s': {T} s is not a multiple of landing.filter.dt_s = {Dt} s")
    if not _multiple(rate * Dt, 1.0):
        out.append(f"{k}imu.rate_hz': rate_hz x filter.dt_s = {rate} x {Dt} = {rate * Dt:g} "
                   "is not a positive integer")
    n_steps = max(1, round(T / Dt))
    if T * rate > MAX_LANDING_IMU_SAMPLES:
        out.append(f"{k}imu.rate_hz': duration_s x rate_hz = {T * rate:.0f} IMU samples exceeds "
                   f"the limit {MAX_LANDING_IMU_SAMPLES} (memory)")
    for key, runs in (("mc.n_runs", c["mc"]["n_runs"]),):
        if runs * n_steps > MAX_LANDING_RUN_STEPS:
            out.append(f"{k}{key}': {runs} runs x {n_steps} filter steps exceeds the limit "
                       f"{MAX_LANDING_RUN_STEPS} (memory)")
    f5 = c["figures"]["f5_time_s"]
    if not (0 <= f5 < T) or (f5 > 0 and not _multiple(f5, Dt)):
        out.append(f"{k}figures.f5_time_s': {f5} s must be a filter step "
                   f"(multiple of filter.dt_s = {Dt} s) in [0, duration_s = {T} s)")

    known = available_methods()
    lists = {"mc.methods": c["mc"]["methods"], "extra.methods": c["extra"]["methods"],
             "extra.reference": [c["extra"]["reference"]],
             "single.method": [c["single"]["method"]]}
    for key, names in lists.items():
        bad = [m for m in names if m not in known]
        if bad:
            out.append(f"{k}{key}': unknown planning method {', '.join(map(repr, bad))} "
                       f"(known: {', '.join(known)})")
        dup = _duplicates(names)
        if dup:
            out.append(f"{k}{key}': duplicated {', '.join(dup)}")
    if c["extra"]["n_boot"] == 1:
        out.append(f"{k}extra.n_boot': 1 resample gives no interval; use 0 (paired t only) or >= 2")
    flown = list(c["mc"]["methods"]) + list(c["extra"]["methods"])
    if c["extra"]["reference"] not in flown:
        out.append(f"{k}extra.reference': {c['extra']['reference']!r} is not flown "
                   "(not in landing.mc.methods or landing.extra.methods)")

    r0 = np.asarray(c["initial_state"]["r_m"], float)
    alt_min = c["filter"]["min_update_altitude_m"]
    if r0[2] <= 0:
        out.append(f"{k}initial_state.r_m': the lander starts at altitude {r0[2]:g} m, "
                   "not above the ground z = 0")
        return out
    if c["mc"]["bounds"]["r_m"] >= r0[2]:
        out.append(f"{k}mc.bounds.r_m': initial position errors up to {c['mc']['bounds']['r_m']:g} m "
                   f"would start estimates below the ground (the lander starts at {r0[2]:g} m)")
    half = c["camera"]["pixels"] / 2.0
    if c["planner"]["margin_px"] >= half:
        out.append(f"{k}planner.margin_px': {c['planner']['margin_px']:g} px leaves no part of the "
                   f"{c['camera']['pixels']} px detector to plan landmarks in (must be < {half:g})")
    if r0[2] <= alt_min:
        out.append(f"{k}initial_state.r_m': the lander starts at {r0[2]:g} m, not above "
                   f"filter.min_update_altitude_m = {alt_min:g} m (no measurement would be taken)")
    if out or not _multiple(T, Dt):
        return out
    t = Dt * np.arange(n_steps + 1)
    try:
        tr = truth_states(t, r0, c["initial_state"]["v_mps"], T, c["gravity_mps2"], c["yaw_deg"])
    except (ValueError, np.linalg.LinAlgError) as exc:
        return [*out, f"{k}initial_state': the nominal guidance trajectory is undefined: {exc}"]
    below = np.nonzero(tr.r[:-1, 2] < 0)[0]
    if below.size:
        out.append(f"{k}initial_state': the nominal guidance trajectory goes below ground at "
                   f"t = {t[below[0]]:g} s (initial_state.r_m / v_mps / duration_s)")
        return out
    measuring = tr.r[:, 2] > alt_min                 # where the filter takes bearings
    to_site_B = np.einsum("kij,kj->ki", tr.R_LtoB, -tr.r)
    key = "camera"
    fov = c["camera"]["fov_deg"]
    try:
        cam = camera_from_config(c["camera"])
    except ValueError as exc:
        return [*out, f"{k}{key}': {exc}"]
    seen = cam.in_view(to_site_B)
    if not seen[0]:
        out.append(f"{k}{key}': the landing site is not in the camera's view at t = 0 "
                   f"(fov_deg {fov:g}, tilt_deg {c['camera']['tilt_deg']:g}, "
                   f"tilt_azimuth_deg {c['camera']['tilt_azimuth_deg']:g})")
    elif not np.all(seen[measuring]):
        t_out = t[np.nonzero(measuring & ~seen)[0][0]]
        out.append(f"{k}{key}': the landing site leaves the camera's view at t = {t_out:g} s "
                   f"of the nominal descent (fov_deg {fov:g})")
    return out
