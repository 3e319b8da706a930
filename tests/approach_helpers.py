"""Small shared builders for the paper-A tests."""

import numpy as np
from scipy.spatial.transform import Rotation

from opnav.approach.ekf import Window
from opnav.config import load_config


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
