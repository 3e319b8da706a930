"""IMU synthesis, noise, pre-integration and dead reckoning (paper B eq. 1-2).

Description
-----------
The IMU samples at ``dt`` (s, config ``landing.imu.rate_hz``). Sample ``k``
holds, over ``[t_k, t_k + dt]``, a constant body angular rate ``w_k`` (rad/s,
{B} relative to {L}, in {B}) and a constant specific force ``f_k`` (m/s^2, in
{B}) applied at the mid-step attitude. The propagation scheme (exact for this
sample model) is::

    R_BtoL(k+1) = R_BtoL(k) Exp(w_k dt)
    R_mid       = R_BtoL(k) Exp(w_k dt / 2)
    v(k+1)      = v(k) + (R_mid f_k + g) dt
    r(k+1)      = r(k) + v(k) dt + (R_mid f_k + g) dt^2 / 2

:func:`synthesize` inverts it on the truth (so zero-noise dead reckoning
reproduces the truth velocity and attitude at the IMU nodes to round-off, and
the position to the trapezoidal-rule error of the polynomial truth).
Paper assumption 1: planet rotation terms of eq. 2 are neglected.

Noise (paper sec. 3): each sample gets independent white Gaussian noise of
standard deviation ``sigma_a`` (m/s^2) per axis on ``f`` and ``sigma_w``
(rad/s) per axis on ``w``. The per-sample standard deviation is the paper's
number whatever the rate (so the effective noise density scales with the rate).

Pre-integration (:func:`preintegrate`) groups the samples of each filter
interval ``Delta t = n_sub dt`` and returns the rotation, velocity and position
increments in the body frame at the start of the interval; the filter's
closed-form propagation (``opnav.landing.ekf.propagate``) applies them. It is
a compiled kernel (``opnav.core.compiled``), a loop over intervals and samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from opnav.core.compiled import kernel, warms
from opnav.core.rotations import exp_so3, exp_so3_into, log_so3

__all__ = ["synthesize", "add_noise", "Preintegrated", "preintegrate", "dead_reckon"]


def synthesize(v: np.ndarray, R_LtoB: np.ndarray, dt: float, g) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free IMU samples ``(f, w)``, each (n-1, 3), from the truth velocity
    ``v`` (n, 3) m/s and attitude ``R_LtoB`` (n, 3, 3) at the IMU nodes."""
    if dt <= 0:
        raise ValueError(f"IMU step must be positive, got {dt}")
    R_BtoL = np.swapaxes(np.asarray(R_LtoB, float), 1, 2)
    dR = np.einsum("nji,njk->nik", R_BtoL[:-1], R_BtoL[1:])     # R_k^T R_{k+1}
    w = log_so3(dR) / dt
    R_mid = R_BtoL[:-1] @ exp_so3(w * dt / 2)
    acc = (v[1:] - v[:-1]) / dt - np.asarray(g, float)
    f = np.einsum("nji,nj->ni", R_mid, acc)                      # R_mid^T acc
    return f, w


def add_noise(f: np.ndarray, w: np.ndarray, sigma_a: float, sigma_w: float,
              rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """IMU samples with white noise (``sigma_a`` m/s^2, ``sigma_w`` rad/s per axis)."""
    return (f + sigma_a * rng.standard_normal(f.shape),
            w + sigma_w * rng.standard_normal(w.shape))


@dataclass(frozen=True)
class Preintegrated:
    """Per filter interval ``j`` (all in the body frame at the interval start):
    ``dR`` (m, 3, 3) = R_BtoL(i)^T R_BtoL(j); ``dv`` (m, 3) m/s and ``dp`` (m, 3) m,
    the specific-force parts of the velocity and position increments."""

    dR: np.ndarray
    dv: np.ndarray
    dp: np.ndarray
    dt: float          # IMU step, s
    n_sub: int         # IMU samples per interval


@kernel
def _preintegrate(F, W, dt, dR, dv, dp) -> None:
    """Per interval ``j`` of ``F``, ``W`` (m, n_sub, 3): the increments into ``dR``
    (m, 3, 3), ``dv``, ``dp`` (m, 3), sample by sample (module docstring)."""
    half = np.empty((3, 3))
    mid = np.empty((3, 3))
    phi = np.empty(3)
    for j in range(F.shape[0]):
        R = dR[j]
        for a in range(3):
            dv[j, a] = 0.0
            dp[j, a] = 0.0
            for b in range(3):
                R[a, b] = 1.0 if a == b else 0.0
        for k in range(F.shape[1]):
            for a in range(3):
                phi[a] = W[j, k, a] * dt / 2
            exp_so3_into(phi, half)
            for a in range(3):                 # R_mid = dR half
                for b in range(3):
                    mid[a, b] = R[a, 0] * half[0, b] + R[a, 1] * half[1, b] + R[a, 2] * half[2, b]
            for a in range(3):
                inc = (mid[a, 0] * F[j, k, 0] + mid[a, 1] * F[j, k, 1] + mid[a, 2] * F[j, k, 2]) * dt
                dp[j, a] += dv[j, a] * dt + 0.5 * inc * dt
                dv[j, a] += inc
            for a in range(3):                 # dR = R_mid half
                for b in range(3):
                    R[a, b] = mid[a, 0] * half[0, b] + mid[a, 1] * half[1, b] + mid[a, 2] * half[2, b]


@warms
def _warm() -> None:
    preintegrate(np.zeros((2, 3)), np.zeros((2, 3)), 0.1, 2)


def preintegrate(f: np.ndarray, w: np.ndarray, dt: float, n_sub: int) -> Preintegrated:
    """Group IMU samples (n_int * n_sub, 3) into ``n_int`` intervals of ``n_sub``
    (the kernel ``_preintegrate``, one loop over the samples of each interval)."""
    n = f.shape[0]
    if n % n_sub:
        raise ValueError(f"{n} IMU samples do not split into intervals of {n_sub}")
    m = n // n_sub
    dR = np.empty((m, 3, 3))
    dv = np.empty((m, 3))
    dp = np.empty((m, 3))
    _preintegrate(np.array(f, float, order="C").reshape(m, n_sub, 3),
                  np.array(w, float, order="C").reshape(m, n_sub, 3), float(dt), dR, dv, dp)
    return Preintegrated(dR=dR, dv=dv, dp=dp, dt=dt, n_sub=n_sub)


def apply_increment(r, v, R_LtoB, dR, dv, dp, Dt: float, g):
    """One filter interval of the closed-form propagation: returns ``(r, v, R_LtoB)``."""
    R_BtoL = R_LtoB.T
    g = np.asarray(g, float)
    r_new = r + v * Dt + R_BtoL @ dp + 0.5 * g * Dt**2
    v_new = v + R_BtoL @ dv + g * Dt
    R_new = (R_BtoL @ dR).T
    return r_new, v_new, R_new


def dead_reckon(r0, v0, R0_LtoB, pre: Preintegrated, g) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IMU-only propagation over all intervals: states at the m+1 interval nodes."""
    m = pre.dv.shape[0]
    Dt = pre.dt * pre.n_sub
    r = np.empty((m + 1, 3))
    v = np.empty((m + 1, 3))
    R = np.empty((m + 1, 3, 3))
    r[0], v[0], R[0] = r0, v0, R0_LtoB
    for j in range(m):
        r[j + 1], v[j + 1], R[j + 1] = apply_increment(r[j], v[j], R[j], pre.dR[j], pre.dv[j],
                                                       pre.dp[j], Dt, g)
    return r, v, R
