"""The yaw-convergence verdict (B-T3 summary, scorecard) flips with the data."""

import numpy as np

from opnav.landing.montecarlo import MonteCarlo, yaw_convergence


def _runs(shrink: float) -> MonteCarlo:
    rng = np.random.default_rng(3)
    scale = np.linspace(1.0, shrink, 40)[None, :, None]
    return MonteCarlo(err_rpy_deg=rng.normal(size=(200, 40, 3)) * scale)


def test_shrinking_yaw_envelope_reads_converging_and_a_flat_one_does_not():
    from opnav.report.landing.summary import yaw_reason

    assert yaw_convergence(_runs(0.2), 0.5, "depth").converges
    flat = yaw_convergence(_runs(1.0), 0.5, "depth")
    assert not flat.converges and "not below 50%" in yaw_reason(flat) and flat.n_runs == 200
