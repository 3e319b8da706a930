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
score the candidate's planned observations, not this H: ``planned_info``.

Rank choice (documented deviation from a literal reading of the SPEC): each
unit-bearing block of H has its bearing as left null vector (b^T H_C = 0,
b^T [b x] = 0), so rank(H) <= 4 and the 5th and 6th singular values are
rounding noise (~1e-16). We use the four *structural* singular values s1 >= ..
>= s4: ``svd`` = s4, ``cond`` = s4 / s1, ``gdop`` = 1 / sum s_i^-2 (exactly
trace[(H^T H)^+]^-1 with the pseudo-inverse rank tolerance at rank 4; the
reference uses ``pinv(H, rcond=1e-10)``).

Closed form (the fast path, compiled: ``kernels.h_metric``): the
structural singular values do not depend on the attitude and, with x = 1/rho_1,
y = 1/rho_2 (1/m) and c = u . w (unit lines of sight to the known landmark and
the candidate), a = 1 + x^2, d = 1 + 2 y^2, m = (a + d)/2, e = (a - d)/2,
k1 = c + x y, k2 = 1 + c x y, are s^2 in {m + sqrt(e^2 + k_j^2), D_j / (m +
sqrt(e^2 + k_j^2))}, D1 = sin^2(gamma) + (x - c y)^2 + (2 - c^2) y^2 + x^2 y^2,
D2 = (x - c y)^2 + (2 - c^2) y^2 + (2 - c^2) x^2 y^2 (no cancellation). Tested
equal to the SVD of the CasADi-derived H. H mixes units (1/m position columns, 1
attitude columns): s4 ~ 1/range, s1 ~ sqrt(2), so ``svd`` mostly rewards short
ranges and ``svd``, ``gdop``, ``cond`` rank candidates alike in the descent.

Validity (``kernels.candidate_ok``): a candidate within ``ctx.min_range_m`` of the
lander or behind the camera (b . boresight_B <= 0; None disables), or with the
known landmark so, scores -inf; bad inputs raise ``ValueError`` naming the field.
``metric(ctx, cand_L (n, 3))`` is the fast path, ``metric.reference`` the paper's
definition (the tests' reference and the "as the paper defines it" timing path):
H of eq. 14-18 from CasADi (``Function.map``), then LAPACK (SVD, pseudo-inverse).
``chol_logdet`` is the project's one log-det rule (``planned_info``, ``kernels.logdet_spd``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from opnav.landing import kernels as K

METRIC_NAMES = H_METRICS = ("svd", "gdop", "cond")
#: structural rank of the 6 x 12 two-bearing Jacobian (2 per unit bearing)
STRUCTURAL_RANK = 4
#: pseudo-inverse rank tolerance of the reference GDOP, relative to sigma_max
PINV_RCOND = 1e-10


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
        """The kernels' per-run constants (``kernels.NQ``) of H baseline ``kind`` (``kernels.KINDS``):
        ``kernels.metric_constants``."""
        def build(ctx):
            q = np.zeros(K.NQ)
            bs = ctx.boresight_B
            K.metric_constants(ctx.r_L, ctx.R_LtoB, np.zeros(3) if bs is None else np.asarray(bs, float),
                               0.0 if bs is None else 1.0, ctx.p_known_L, ctx.min_range_m, q)
            q[11] = kind
            return q
        return self.cached(("q", kind), build)


def chol_logdet(A: np.ndarray, jitter: float | None = None) -> np.ndarray:
    """log det of a stack of SPD matrices (..., k, k) as 2 sum(log(diag(L))) of
    the Jacobi-equilibrated matrix D^-1/2 A D^-1/2 + jitter I, plus sum(log D).
    ``jitter`` defaults to k * machine epsilon; a matrix whose Cholesky still fails
    is retried with the jitter multiplied by 1e3 up to 1e-8, then scored -inf."""
    A = np.asarray(A, dtype=float)
    k = A.shape[-1]
    jitter = k * np.finfo(float).eps if jitter is None else jitter
    dg = np.diagonal(A, axis1=-2, axis2=-1)
    out = np.full(A.shape[:-2], -np.inf)
    ok = np.all(dg > 0, axis=-1) & np.all(np.isfinite(A), axis=(-2, -1))
    if not np.any(ok):
        return out
    s = 1.0 / np.sqrt(dg[ok])
    As = A[ok] * s[..., :, None] * s[..., None, :]
    try:
        vals = 2.0 * np.sum(np.log(np.diagonal(np.linalg.cholesky(As + jitter * np.eye(k)),
                                               axis1=-2, axis2=-1)), axis=-1)
    except np.linalg.LinAlgError:          # one by one, the jitter escalated where needed
        vals = np.full(As.shape[0], -np.inf)
        for i, Ai in enumerate(As):
            j = jitter
            while j <= 1e-8:
                try:
                    vals[i] = 2.0 * np.sum(np.log(np.diag(np.linalg.cholesky(Ai + j * np.eye(k)))))
                    break
                except np.linalg.LinAlgError:
                    j *= 1e3
    out[ok] = vals - 2.0 * np.sum(np.log(s), axis=-1)
    return out


def _scores_from_H(name: str, H: np.ndarray, ctx: MetricContext) -> np.ndarray:
    """The paper's definition on explicit H (n, 6, 12): LAPACK SVD / pseudo-inverse of H."""
    if name == "gdop":
        Hp = np.linalg.pinv(H, rcond=PINV_RCOND)  # (H^T H)^+ = H^+ H^+T
        return 1.0 / np.einsum("nij,nij->n", Hp, Hp)
    return _sv_metric(name, np.linalg.svd(H, compute_uv=False))


def _sv_metric(base: str, s: np.ndarray) -> np.ndarray:
    """``kernels.sv_metric`` of the structural singular values of each row of s (n, >= 4), descending."""
    return np.array([K.sv_metric(K.KINDS[base], *(x * x for x in row[:STRUCTURAL_RANK])) for row in s])


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

    def _scored(self, ctx: MetricContext, cand_L, build) -> np.ndarray:
        c = np.asarray(cand_L, dtype=float)
        c = c[None, :] if c.ndim == 1 else c
        if c.ndim != 2 or c.shape[1] != 3 or not np.all(np.isfinite(c)):
            raise ValueError(f"cand_L must be finite with shape (n, 3), got {np.shape(cand_L)}")
        self.n_evals += c.shape[0]
        self.n_calls += 1
        ok = K.valid_points(ctx.q(), np.ascontiguousarray(c))
        out = np.full(c.shape[0], -np.inf)
        if ok.any():
            out[ok] = build(c[ok])
        return out

    def __call__(self, ctx: MetricContext, cand_L) -> np.ndarray:
        q = ctx.q(K.KINDS[self.name])
        return self._scored(ctx, cand_L, lambda c: -K.score_points(q, c, np.arange(len(c))))

    def reference(self, ctx: MetricContext, cand_L) -> np.ndarray:
        """The paper's definition: H of every candidate from the CasADi derivation
        (``casadi_model.jacobian_casadi_batch``, ``Function.map``), then LAPACK
        (:func:`_scores_from_H`)."""
        from opnav.landing import casadi_model as cm  # CasADi (~15-20 ms import) only here

        return self._scored(ctx, cand_L, lambda c: _scores_from_H(self.name, cm.jacobian_casadi_batch(
            ctx.r_L, ctx.v_L, ctx.p_known_L, c, ctx.R_LtoB), ctx))


def make_metric(name: str) -> Metric:
    """The selection metric ``name`` (one of :data:`METRIC_NAMES`), larger is better."""
    return Metric(name)
