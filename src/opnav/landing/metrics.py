"""The paper's H baselines for landmark selection (paper B, sec. 2.2; SPEC B.3).

Description
-----------
Every metric scores a *candidate* unknown landmark p_cand (in {L}, m) given the
lander state and the known landmark, from the two-landmark bearing Jacobian H
(6 x 12, paper eq. 14-18, columns [dr, dv, dtheta, dp_cand]). LARGER IS BETTER:

==========  ================================================================
``svd``     sigma_min(H): smallest *structural* singular value (see below)
``gdop``    1 / trace[(H^T H)^+]  (paper's GDOP-type metric, pseudo-inverse)
``cond``    1 / cond(H) = sigma_min / sigma_max (structural)
==========  ================================================================

B-X1's information baselines (logdet, mineig, svd_w, gdop_w, cond_w, logdet_nav)
score the candidate's planned observations, not this H: ``planning.reference``.

Rank choice (documented deviation from a literal reading of the SPEC): each
unit-bearing block of H has its bearing as left null vector (b^T H_C = 0,
b^T [b x] = 0), so rank(H) <= 4 and the 5th and 6th singular values are
rounding noise (~1e-16). We use the four *structural* singular values s1 >= ..
>= s4: ``svd`` = s4, ``cond`` = s4 / s1, ``gdop`` = 1 / sum s_i^-2 (exactly
trace[(H^T H)^+]^-1 with the pseudo-inverse rank tolerance at rank 4; the
reference uses ``pinv(H, rcond=1e-10)``).

Closed form (the fast path, compiled: ``planning.hmetrics.h_metric``): the
structural singular values do not depend on the attitude and, with x = 1/rho_1,
y = 1/rho_2 (1/m) and c = u . w (unit lines of sight to the known landmark and
the candidate), a = 1 + x^2, d = 1 + 2 y^2, m = (a + d)/2, e = (a - d)/2,
k1 = c + x y, k2 = 1 + c x y, are s^2 in {m + sqrt(e^2 + k_j^2), D_j / (m +
sqrt(e^2 + k_j^2))}, D1 = sin^2(gamma) + (x - c y)^2 + (2 - c^2) y^2 + x^2 y^2,
D2 = (x - c y)^2 + (2 - c^2) y^2 + (2 - c^2) x^2 y^2 (no cancellation). Tested
equal to the SVD of the CasADi-derived H. H mixes units (1/m position columns, 1
attitude columns): s4 ~ 1/range, s1 ~ sqrt(2), so ``svd`` mostly rewards short
ranges and ``svd``, ``gdop``, ``cond`` rank candidates alike in the descent.

Validity (``planning.screens.candidate_ok``): a candidate within ``ctx.min_range_m`` of the
lander or behind the camera (b . boresight_B <= 0; None disables), or with the
known landmark so, scores -inf; bad inputs raise ``ValueError`` naming the field.
``metric(ctx, cand_L (n, 3))`` is the fast path, ``metric.reference`` the paper's
definition (the tests' reference and the "as the paper defines it" timing path):
H of eq. 14-18 from CasADi (``Function.map``), then LAPACK (SVD, pseudo-inverse):
``planning.reference.h_metric_reference``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from opnav.landing.planning.layout import KINDS, NQ, Q_KIND
from opnav.landing.planning.hmetrics import metric_constants
from opnav.landing.planning.reference import h_metric_reference
from opnav.landing.planning.screens import valid_points
from opnav.landing.planning.search import score_points

METRIC_NAMES = H_METRICS = ("svd", "gdop", "cond")


def _checked(name: str, a, shape: tuple, symmetric: bool = False) -> np.ndarray:
    a = np.array(a, dtype=float, order="C")  # a private copy: the per-context cache must not go stale
    if a.shape != shape:
        raise ValueError(f"MetricContext.{name} must have shape {shape}, got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"MetricContext.{name} must be finite")
    if symmetric and np.abs(a - a.T).max() > 1e-10 * np.abs(a).max():
        raise ValueError(f"MetricContext.{name} must be symmetric")
    return a


@dataclass(frozen=True, eq=False)
class MetricContext:
    """Everything a metric needs besides the candidate: r_L lander position (m),
    v_L velocity (m/s, enters no metric), R_LtoB rotation {L} -> {B}, p_known_L the
    known landmark (m), P 12 x 12 prior covariance (information and whitened
    metrics) or None, R_meas 6 x 6 bearing-noise covariance (rad^2) or None,
    boresight_B the camera boresight in {B} (None: no behind-camera check),
    min_range_m (m)."""

    r_L: np.ndarray
    v_L: np.ndarray
    R_LtoB: np.ndarray
    p_known_L: np.ndarray
    P: np.ndarray | None = None
    R_meas: np.ndarray | None = None
    boresight_B: np.ndarray | None = field(default_factory=lambda: np.array([0.0, 0.0, -1.0]))
    min_range_m: float = 1e-6

    def __post_init__(self):
        s = object.__setattr__
        for k in ("r_L", "v_L", "p_known_L"):
            s(self, k, _checked(k, getattr(self, k), (3,)))
        R = _checked("R_LtoB", self.R_LtoB, (3, 3))
        if np.linalg.det(R) <= 0 or np.abs(R @ R.T - np.eye(3)).max() > 1e-8:
            raise ValueError("MetricContext.R_LtoB must be a proper rotation matrix")
        s(self, "R_LtoB", R)
        for k, n in (("P", 12), ("R_meas", 6)):
            if getattr(self, k) is not None:
                s(self, k, _checked(k, getattr(self, k), (n, n), symmetric=True))
        if self.boresight_B is not None:
            bs = _checked("boresight_B", self.boresight_B, (3,))
            if not np.linalg.norm(bs) > 0:
                raise ValueError("MetricContext.boresight_B must be non-zero (or None)")
            s(self, "boresight_B", bs / np.linalg.norm(bs))
        if not (math.isfinite(self.min_range_m) and self.min_range_m >= 0):
            raise ValueError("MetricContext.min_range_m must be finite and >= 0")
        s(self, "_cache", {})

    def cached(self, key: str, fn):
        """``fn(self)``, computed once per context."""
        c = self._cache
        if key not in c:
            c[key] = fn(self)
        return c[key]

    def q(self, kind: int = 0) -> np.ndarray:
        """The planner's per-call constants q (``planning.layout.NQ``) of H baseline ``kind``
        (``planning.layout.KINDS``): ``planning.hmetrics.metric_constants``."""
        def build(ctx):
            q = np.zeros(NQ)
            bs = ctx.boresight_B
            metric_constants(ctx.r_L, ctx.R_LtoB, np.zeros(3) if bs is None else np.asarray(bs, float),
                               0.0 if bs is None else 1.0, ctx.p_known_L, ctx.min_range_m, q)
            q[Q_KIND] = kind
            return q
        return self.cached(("q", kind), build)


class Metric:
    """A selection metric (larger is better): ``metric(ctx, cand_L (n, 3))`` the
    fast path, ``metric.reference(ctx, cand_L)`` the paper's definition (CasADi H,
    LAPACK); ``n_evals`` counts candidates scored, ``n_calls`` calls."""

    larger_is_better = True

    def __init__(self, name: str):
        if name not in METRIC_NAMES:
            raise ValueError(f"unknown metric {name!r}; expected one of {METRIC_NAMES}")
        self.name = name
        self.n_evals = self.n_calls = 0

    def __repr__(self):
        return f"Metric({self.name!r}, n_evals={self.n_evals}, n_calls={self.n_calls})"

    def reset(self) -> None:
        self.n_evals = self.n_calls = 0

    def _checked(self, cand_L) -> np.ndarray:
        """The candidates (n, 3), counted; ValueError unless finite with that shape."""
        c = np.asarray(cand_L, dtype=float)
        c = c[None, :] if c.ndim == 1 else c
        if c.ndim != 2 or c.shape[1] != 3 or not np.all(np.isfinite(c)):
            raise ValueError(f"cand_L must be finite with shape (n, 3), got {np.shape(cand_L)}")
        self.n_evals += c.shape[0]
        self.n_calls += 1
        return c

    def __call__(self, ctx: MetricContext, cand_L) -> np.ndarray:
        c = self._checked(cand_L)
        ok = valid_points(ctx.q(), np.ascontiguousarray(c))
        out = np.full(c.shape[0], -np.inf)
        if ok.any():
            c = c[ok]
            out[ok] = -score_points(ctx.q(KINDS[self.name]), c, np.arange(len(c)))
        return out

    def reference(self, ctx: MetricContext, cand_L) -> np.ndarray:
        """The paper's definition (``planning.reference.h_metric_reference``: CasADi H, LAPACK)."""
        return h_metric_reference(self.name, ctx, self._checked(cand_L))


def make_metric(name: str) -> Metric:
    """The selection metric ``name`` (one of :data:`METRIC_NAMES`), larger is better."""
    return Metric(name)
