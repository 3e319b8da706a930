"""Test-only helpers of paper B's landing filter that the pipeline does not run."""

from __future__ import annotations

import numpy as np

from opnav.core.rotations import skew
from opnav.landing.measurement import blocks


def jacobian_blocks(R_LtoB, u, inv_rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(b, H_C, [b x])`` from the unit line of sight ``u`` (..., 3) in {L} and the inverse
    range ``inv_rho`` (...) (1/m): the bearing (eq. 12), ``H_C = (R_LtoB - b u^T) / |rho|``
    (eq. 18, 1/m) and the attitude block ``[b x]`` (eq. 16), by the kernel
    ``measurement.blocks`` run by run, broadcast over leading dimensions."""
    R = np.asarray(R_LtoB, dtype=float)
    u = np.asarray(u, dtype=float)
    inv = np.asarray(inv_rho, dtype=float)
    shape = np.broadcast_shapes(R.shape[:-2], u.shape[:-1], inv.shape)
    Rf = np.array(np.broadcast_to(R, shape + (3, 3)), order="C").reshape(-1, 3, 3)
    uf = np.array(np.broadcast_to(u, shape + (3,)), order="C").reshape(-1, 3)
    invf = np.array(np.broadcast_to(inv, shape), order="C").reshape(-1)
    b = np.empty(uf.shape)
    HC = np.empty((b.shape[0], 3, 3))
    for k in range(b.shape[0]):
        blocks(Rf[k], uf[k], float(invf[k]), b[k], HC[k])
    b = b.reshape(shape + (3,))
    return b, HC.reshape(shape + (3, 3)), skew(b)
