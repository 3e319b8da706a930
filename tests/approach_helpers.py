"""Small shared builders for the paper-A tests."""

import numpy as np
from scipy.spatial.transform import Rotation

from opnav.approach.ekf import Window
from opnav.approach.setup import Setup
from opnav.core.config import load_config


def small_window(n=6, seed=0, rvar=1.0, q=0.1):
    """A small, well-conditioned linear model in the form of the approach filter."""
    rng = np.random.default_rng(seed)
    Phi = np.empty((n + 1, 6, 6))
    for k in range(n + 1):
        Phi[k] = np.eye(6) + 0.1 * rng.standard_normal((6, 6))
    C = Rotation.random(n + 1, random_state=seed).as_matrix()
    u_ref = rng.standard_normal((n + 1, 3)) * 5.0 + np.array([0.0, 0.0, 50.0])
    Rvar = rvar * (0.5 + rng.random((n + 1, 3)))
    return Window(Phi, C, u_ref, Rvar, q * np.eye(6)), rng


def approach_cfg(**segments):
    cfg = load_config()["approach"]
    cfg["segments"].update(segments)
    return cfg


def approach_setup(**segments) -> Setup:
    """:func:`approach_cfg` parsed once: the :class:`Setup` every paper-A function takes."""
    return Setup.from_config(approach_cfg(**segments))


def random_filter_problem(seed, S, n, per_seed=False):
    """A random EM-EKF problem on :func:`small_window` for hypothesis tests: the window (with
    per-seed variances (n+1, S, 3) if ``per_seed``), its generator, measurements z (S, n+1, 3),
    small misalignments theta (S, 3), start means x0 (S, 6) and an SPD start covariance P0."""
    win, rng = small_window(n=n, seed=seed % 997)
    if per_seed:
        win = Window(win.Phi, win.C, win.u_ref, 0.5 + rng.random((n + 1, S, 3)), win.Q)
    z = rng.standard_normal((S, n + 1, 3)) * 3 + win.u_ref
    theta = rng.normal(size=(S, 3)) * 0.05
    x0 = rng.normal(size=(S, 6))
    A = rng.standard_normal((6, 6))
    return win, rng, z, theta, x0, A @ A.T + np.eye(6)
