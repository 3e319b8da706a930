"""Small shared builders for the paper-B tests: filter states, and the ``landing`` config
parsed once, as the workflow's scripts parse it (opnav.landing.setup)."""

import numpy as np
from scipy.spatial.transform import Rotation

from opnav.landing import ekf
from opnav.landing.setup import Setup, scenario_sections


def landing_setup(section) -> Setup:
    """A ``landing`` config mapping (or a rule's part of it) parsed: the :class:`Setup` every
    paper-B function takes."""
    return Setup.from_config(section)


def scenario_setups(section) -> dict[str, Setup]:
    """The setup of every camera scenario of a ``landing`` config mapping, in config order (the
    workflow's per-scenario mappings, ``setup.scenario_sections``, each parsed)."""
    return {n: Setup.from_config(c) for n, c in scenario_sections(section).items()}


def random_nav_states(rng: np.random.Generator, n: int) -> ekf.NavState:
    """``n`` plausible descent estimates (one per run): positions up to 6 km above the
    ground (m), velocities (m/s), random attitudes R_LtoB, the unknown landmark on the
    ground near the lander (m), and an SPD covariance with per-state scales."""
    r = np.c_[rng.uniform(-4000, 4000, (n, 2)), rng.uniform(300, 6000, n)]
    v = rng.uniform(-60, 60, (n, 3))
    R = Rotation.random(n, random_state=rng).as_matrix()
    p = np.c_[r[:, :2] + rng.uniform(-2000, 2000, (n, 2)), np.zeros(n)]
    A = rng.normal(size=(n, 12, 12)) * np.array([30, 30, 30, 1, 1, 1, 0.01, 0.01, 0.01, 50, 50, 50])
    P = A @ np.swapaxes(A, 1, 2) / 12 + np.eye(12) * 1e-6
    return ekf.NavState(r, v, R, p, P)
