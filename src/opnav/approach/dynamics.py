"""Heliocentric dynamics of a Mars approach (paper A eq. 2; SPEC A.1).

Description
    State ``X = [r; v]`` of the spacecraft in a heliocentric inertial (ecliptic)
    frame, km and km/s. The acceleration is the Sun's point mass plus the Mars
    third-body perturbation ``f_M = -mu_M (r - X_M)/|r - X_M|^3 - mu_M X_M/|X_M|^3``.
    Mars moves on a Keplerian heliocentric orbit from mean elements.

    * :func:`propagate` integrates the truth with ``solve_ivp`` (DOP853, tight
      tolerances) and returns the state at the sample times.
    * :func:`propagate_with_stm` integrates the same model together with the
      variational equations ``Phi' = F Phi`` and returns the one-step state
      transition matrices ``Phi_{k,k-1}`` at the sample times.

Use
    The filter works in deviations from a reference trajectory (the propagated
    prior mean): ``dX_k = Phi_{k,k-1} dX_{k-1} + W_{k-1}``. The deviations of
    interest are a few hundred km out of 2e8 km, so the second-order remainder
    of the linearisation is below 1e-15 km/s^2 (checked by a finite-difference
    test in ``tests/test_approach_models.py``).

Units: km, s, km^3/s^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MU_SUN = 1.32712440018e11  # km^3/s^2
MU_MARS = 4.282837e4  # km^3/s^2
AU_KM = 1.495978707e8
R_MARS_KM = 3389.5
ARCSEC = np.pi / 180.0 / 3600.0  # rad per arcsec


@dataclass(frozen=True)
class KeplerElements:
    """Mean heliocentric elements of Mars at epoch t = 0 (km, rad)."""

    a_km: float
    e: float
    i: float
    raan: float
    argp: float
    mean_anomaly: float

    @classmethod
    def from_config(cls, c: dict) -> "KeplerElements":
        d = np.deg2rad
        return cls(a_km=c["a_au"] * AU_KM, e=c["e"], i=d(c["i_deg"]), raan=d(c["raan_deg"]),
                   argp=d(c["argp_deg"]), mean_anomaly=d(c["mean_anomaly_deg"]))


def kepler_state(el: KeplerElements, t: np.ndarray, mu: float = MU_SUN) -> np.ndarray:
    """Heliocentric state (..., 6) of a body on a Keplerian ellipse at times ``t`` (s)."""
    t = np.asarray(t, dtype=float)
    n = np.sqrt(mu / el.a_km**3)
    M = el.mean_anomaly + n * t
    E = M.copy() if M.ndim else np.array(M)
    for _ in range(30):  # Newton on Kepler's equation
        E = E - (E - el.e * np.sin(E) - M) / (1.0 - el.e * np.cos(E))
    cE, sE = np.cos(E), np.sin(E)
    b = el.a_km * np.sqrt(1.0 - el.e**2)
    x, y = el.a_km * (cE - el.e), b * sE
    rr = el.a_km * (1.0 - el.e * cE)
    vx, vy = -el.a_km * n * sE * el.a_km / rr, b * n * cE * el.a_km / rr
    cO, sO, cw, sw, ci, si = (np.cos(el.raan), np.sin(el.raan), np.cos(el.argp),
                              np.sin(el.argp), np.cos(el.i), np.sin(el.i))
    P = np.array([cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si])
    Qv = np.array([-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si])
    r = np.multiply.outer(x, P) + np.multiply.outer(y, Qv)
    v = np.multiply.outer(vx, P) + np.multiply.outer(vy, Qv)
    return np.concatenate([r, v], axis=-1)


def acceleration(r: np.ndarray, r_mars: np.ndarray) -> np.ndarray:
    """Sun + Mars third-body acceleration (km/s^2), SPEC A.1; broadcasts over leading axes."""
    d = r - r_mars
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    dn = np.linalg.norm(d, axis=-1, keepdims=True)
    mn = np.linalg.norm(r_mars, axis=-1, keepdims=True)
    return -MU_SUN * r / rn**3 - MU_MARS * d / dn**3 - MU_MARS * r_mars / mn**3


def gravity_gradient(r: np.ndarray, r_mars: np.ndarray) -> np.ndarray:
    """d(acceleration)/dr (3x3, 1/s^2) of :func:`acceleration`."""
    out = np.zeros(r.shape[:-1] + (3, 3))
    for mu, p in ((MU_SUN, r), (MU_MARS, r - r_mars)):
        pn = np.linalg.norm(p, axis=-1)[..., None, None]
        out += mu * (3.0 * np.einsum("...i,...j->...ij", p, p) / pn**5 - np.eye(3) / pn**3)
    return out


def _rhs(el: KeplerElements):
    def f(t, X):
        rm = kepler_state(el, t)[:3]
        return np.concatenate([X[3:], acceleration(X[:3], rm)])
    return f


def propagate(X0: np.ndarray, t: np.ndarray, el: KeplerElements, rtol: float = 1e-13,
              atol: float = 1e-6) -> np.ndarray:
    """Truth states (len(t), 6) from ``X0`` at ``t[0]``, DOP853 with tight tolerances."""
    from scipy.integrate import solve_ivp   # 0.3 s of import: only jobs that integrate pay it

    sol = solve_ivp(_rhs(el), (t[0], t[-1]), np.asarray(X0, float), method="DOP853",
                    t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:  # pragma: no cover
        raise RuntimeError(f"truth propagation failed: {sol.message}")
    return sol.y.T


def propagate_with_stm(X0: np.ndarray, t: np.ndarray, el: KeplerElements, rtol: float = 1e-13,
                       atol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """States (n, 6) and one-step STMs ``Phi_{k,k-1}`` (n, 6, 6) along the trajectory.

    The variational equations ``Phi' = F Phi`` with ``F = [[0, I], [G, 0]]`` are
    integrated with the state (DOP853); ``Phi_{k,k-1} = Phi(t_k) Phi(t_{k-1})^-1``.
    ``Phi_{0,-1}`` is the identity.
    """
    f = _rhs(el)

    def rhs(tt, Y):
        X, Phi = Y[:6], Y[6:].reshape(6, 6)
        rm = kepler_state(el, tt)[:3]
        F = np.zeros((6, 6))
        F[:3, 3:] = np.eye(3)
        F[3:, :3] = gravity_gradient(X[:3], rm)
        return np.concatenate([f(tt, X), (F @ Phi).ravel()])

    Y0 = np.concatenate([np.asarray(X0, float), np.eye(6).ravel()])
    from scipy.integrate import solve_ivp

    sol = solve_ivp(rhs, (t[0], t[-1]), Y0, method="DOP853", t_eval=t, rtol=rtol, atol=atol)
    if not sol.success:  # pragma: no cover
        raise RuntimeError(f"STM propagation failed: {sol.message}")
    X = sol.y[:6].T
    Phi_cum = sol.y[6:].T.reshape(-1, 6, 6)
    step = np.empty_like(Phi_cum)
    step[0] = np.eye(6)
    step[1:] = np.linalg.solve(Phi_cum[:-1].transpose(0, 2, 1),
                               Phi_cum[1:].transpose(0, 2, 1)).transpose(0, 2, 1)
    return X, step
