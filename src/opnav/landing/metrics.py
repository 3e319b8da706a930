"""Observability / information metrics for landmark selection (paper B, sec. 2.2;
SPEC B.3 baselines and B-X1).

Description
-----------
Every metric scores a *candidate* unknown landmark p_cand (in {L}, m) given the
lander state and the known landmark at the {L} origin, from the two-landmark
bearing Jacobian H (6 x 12, paper eq. 14-18, columns [dr, dv, dtheta, dp_cand],
``opnav.landing.measurement.selection_jacobian``, cross-checked against its
CasADi derivation in :mod:`opnav.landing.casadi_model`).  LARGER IS BETTER for all of them:

==========  ================================================================
``svd``     sigma_min(H): smallest *structural* singular value (see below)
``gdop``    1 / trace[(H^T H)^+]  (paper's GDOP-type metric, pseudo-inverse)
``cond``    1 / cond(H) = sigma_min / sigma_max (structural)
``logdet``  D-optimal  log det(P^-1 + H^T R^-1 H)          (B-X1, beyond paper)
``mineig``  E-optimal  lambda_min(P^-1 + H^T R^-1 H)        (B-X1, beyond paper)
``svd_w``   ``svd`` of the whitened H_w = R^-1/2 H P^1/2         (B-X1, beyond paper)
``gdop_w``  ``gdop`` of H_w                                       (B-X1, beyond paper)
``cond_w``  ``cond`` of H_w                                       (B-X1, beyond paper)
==========  ================================================================

Whitened variants: H mixes units (1/m in the position and landmark columns,
1 in the attitude columns), so its smallest structural singular value is set
by the 1/range block and ``svd``, ``gdop`` and ``cond`` rank candidates
identically (see below). Scaling H by the prior covariance square root
(Cholesky factor L, P = L L^T; any square root gives the same singular
values) and by R^-1/2 makes every column "one prior sigma" and every row
"one noise sigma": H_w = C^-1 H L with R = C C^T. Its rank is still 4, and
the three scores are taken from its four structural singular values as for
H. They need ``ctx.P`` and ``ctx.R_meas``; there is no closed form, every path
builds H_w explicitly.

Rank choice (documented deviation from a literal reading of the SPEC)
---------------------------------------------------------------------
Each unit-bearing block of H has the left null vector b_i: b_i^T H_C = 0 and
b_i^T [b_i x] = 0 (eq. 16-18), because a unit vector has only two degrees of
freedom.  Hence rank(H) <= 4 for every geometry, and the 5th and 6th singular
values of the 6 x 12 H are zero up to rounding (~1e-16): the smallest of the 6
singular values is rounding noise and 1/cond(H) over all 6 is 0 for every
candidate, so they cannot rank landmarks.  We therefore use the four
*structural* singular values s1 >= s2 >= s3 >= s4 (those of the 4 x 12
tangent-plane projection T^T H, which is how a pixel measurement enters):
``svd`` = s4, ``cond`` = s4 / s1, ``gdop`` = 1 / sum_i s_i^-2.  For ``gdop`` this
is exactly trace[(H^T H)^+]^-1 with the pseudo-inverse rank tolerance set at
rank 4; the per-candidate reference computes it with ``numpy.linalg.pinv(H,
rcond=1e-10)`` (singular values below 1e-10 sigma_max dropped) and agrees
whenever s4 > 1e-10 s1 (always in the descent geometry, where s4/s1 ~ 1e-5 and
the structural zeros are ~1e-16).  As s4 -> 0 the structural score goes to 0
continuously instead of jumping as a tolerance-based rank would.

Closed form (the fast path)
---------------------------
The structural singular values are invariant to the attitude R_LtoB (H =
blockdiag(R, R) H_L blockdiag(I, I, R^T, I) with orthogonal factors), and
depend only on x = 1/rho_1, y = 1/rho_2 (inverse ranges to the known and the
candidate landmark, 1/m) and c = cos(gamma) = u . w (unit lines of sight).
Reducing H H^T to tangent bases aligned with u x w gives a 2 x 2 diagonal
coupling, so (with a = 1 + x^2, d = 1 + 2 y^2, m = (a + d)/2, e = (a - d)/2)

    k1 = c + x y,  k2 = 1 + c x y,
    s^2 in { m + sqrt(e^2 + k_j^2),  D_j / (m + sqrt(e^2 + k_j^2)) },  j = 1, 2,
    D1 = a d - k1^2 = sin^2(gamma) + (x - c y)^2 + (2 - c^2) y^2 + x^2 y^2,
    D2 = a d - k2^2 = (x - c y)^2 + (2 - c^2) y^2 + (2 - c^2) x^2 y^2,

written without cancellation.  Tests prove it equal to the SVD of the
CasADi-derived H (relative 1e-9; the closed form is the more accurate of the two,
LAPACK's s4 carries ~eps s1 / s4 ~ 1e-12 relative error).  Note the mixed units
of H (1/m for position columns, 1 for attitude columns): s1..s3 ~ 1 come from
the attitude columns and s4 ~ 1/range from the position columns: for ranges
>> 1 m, s4^2 ~ ((x - c y)^2 + (2 - c^2) y^2) / 2 and s1 ~ sqrt(2), so ``svd``
mostly rewards short candidate ranges; ``cond`` ~ s4 / sqrt(2) and ``gdop`` =
s4^2 (1 + O(s4^2)) (1/s4^2 ~ 1e8 m^2 dwarfs 1/s1..3^2 ~ 1-10), so all three
paper baselines rank candidates identically in the descent geometry (checked:
identical argsort over 300 candidates at the Table 1 state) and can differ
only in timing.

Information metrics (``logdet``, ``mineig``) need ``ctx.P`` (12 x 12 prior
covariance of [r (m), v (m/s), dtheta (rad), p (m)]) and ``ctx.R_meas`` (6 x 6
bearing-noise covariance, rad^2); they depend on the attitude through P.
Both are computed from the information Lambda = P^-1 + H^T R^-1 H:

* log det as 2 sum(log(diag(cholesky))) of the Jacobi-equilibrated matrix plus
  a k*eps jitter (escalated only if Cholesky fails), never log(prod);
* lambda_min as 1 / lambda_max of the posterior covariance, which keeps
  relative accuracy where eigvalsh on the mixed-unit information (entries
  1e-7 .. 1e7) loses it (the per-candidate reference does the obvious
  eigvalsh(Lambda) and is off by up to ~1e-5 relative in low-altitude cases).
  It is in SI units (m, rad) and therefore unit-dependent.  Caution: a single
  epoch of two bearings cannot inform velocity or the new landmark's depth,
  so with a large isotropic landmark prior in P (e.g. (2000 m)^2 I, no
  cross-covariance) lambda_min is that prior's 1/2000^2 for every candidate
  (measured spread 2e-15 relative) and the argmax is decided by rounding; with
  a 50 m prior it varies by ~90 %.  ``logdet`` has no such plateau.

Fast path (``R_meas`` block diagonal with candidate block sigma^2 I_3, the
descent case): the known landmark's information Lambda_k and Sigma_k =
Lambda_k^-1 are formed once per context; the candidate adds G^T G with
G = sigma^-1 T^T H_c (2 x 12, T a basis orthogonal to the candidate bearing --
b^T H_c = 0 exactly, so the radial direction is dropped analytically), giving
a 2 x 2 update: log det Lambda = log det Lambda_k + log det(I_2 + G Sigma_k G^T)
and Sigma_post by Woodbury with a 2 x 2 inverse.  Otherwise the generic path
factors the 12 x 12 Lambda per candidate.  (The 6 x 6 determinant lemma with
S = R + H P H^T was tried and rejected: S has condition ~1e9 because the
radial bearing directions carry only R, and it lost ~1e-6 nats against a
50-digit reference; both paths above match that reference to 1e-8.)

Degenerate inputs (never a silent NaN)
--------------------------------------
* candidate within ``ctx.min_range_m`` of the lander: score -inf;
* candidate or known landmark behind the camera, i.e. b . boresight_B <= 0
  (``ctx.boresight_B``, default body -z per SPEC B.2; None disables): -inf;
* non-finite or wrongly shaped inputs: ``ValueError`` naming the field;
* information metric without ``P``/``R_meas``: ``ValueError``;
* ``P`` or ``R_meas`` not positive definite: ``ValueError``; an information
  matrix whose Cholesky fails even with jitter: -inf.

Implementations and counting
----------------------------
``make_metric(name)`` returns a :class:`Metric`, callable as
``metric(ctx, cand_L) -> scores`` for ``cand_L`` of shape (n, 3) (fastest
faithful implementation: closed form or batched numpy) and
``metric.scalar(ctx, p_L) -> float`` (minimal-overhead single candidate, the
path a sequential golden-section search calls; ``metric(ctx, cand (1, 3))``
dispatches to it).  ``metric.matrix_scalar`` is the paper's explicit matrix
computation for one candidate done as lean as we could (H of eq. 14-18 with
the known-landmark rows cached, one LAPACK dgesvd of the 6 x 12 H, or the
12 x 12 information); ``metric.numpy_H`` with one candidate dispatches to it,
with n > 1 it builds all H in numpy and applies batched LAPACK.
``metric.reference`` calls the compiled CasADi Function once per candidate
(slow, obvious); ``metric.casadi_map`` uses ``Function.map(n)``.

Screening (the batched planner's edge rule, which scores every detected
landmark): ``metric.screen(ctx, cand_L, rtol=None) -> (lo, hi)`` bounds the
explicit path's score of each candidate cheaply (logdet: the tangent update;
mineig: Rayleigh-Ritz bounds on lambda_max of the posterior covariance, with
``rtol`` narrowed by bisection on its inertia for the candidates that can be
the best; whitened: the 4 x 4 tangent Gram matrix, its eigenvalues bounded by
2 x 2 algebra and computed only for the candidates near the best; H baselines:
the closed form), so that only a short list needs the explicit path (tested:
the bounds hold the explicit score on random contexts).

Batch over planning contexts (runs): ``metric.batch(stack_contexts(ctxs),
cand_L (R, n, 3), mask (R, n) or None) -> (R, n)`` scores n candidates for each
of R contexts in one vectorised call (the batched descent's call; ragged
candidate lists padded and masked), with each run's own numbers;
``metric(ctx, cand_L)`` is its R = 1 case.  Every path adds the number of candidates it scored to
``metric.n_evals`` (and 1 to ``metric.n_calls``); ``metric.reset()`` zeroes both.
See ``benchmarks/bench_metrics.py`` for the timings; on this machine (2 shared
cores, median, us per candidate evaluation): svd/gdop/cond ~2-4 (scalar closed
form) vs ~30 (matrix_scalar: H + SVD) vs ~150-300 (one CasADi Function call +
numpy SVD); logdet ~6, mineig ~27 (scalar) vs ~30-50 (matrix) vs ~200-300 (CasADi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.linalg.lapack import dgesvd as _dgesvd
from scipy.linalg.lapack import dposv as _dposv
from scipy.linalg.lapack import dpotrf as _dpotrf
from scipy.linalg.lapack import dsyev as _dsyev

from opnav.landing import measurement as me
from opnav.rotations import cross

METRIC_NAMES = ("svd", "gdop", "cond", "logdet", "mineig", "svd_w", "gdop_w", "cond_w")
H_METRICS = ("svd", "gdop", "cond")
INFO_METRICS = ("logdet", "mineig")
#: whitened baselines (B-X1): the paper's H metric of H_w = R^-1/2 H P^1/2
WHITENED = {"svd_w": "svd", "gdop_w": "gdop", "cond_w": "cond"}
#: structural rank of the 6 x 12 two-bearing Jacobian (2 per unit bearing)
STRUCTURAL_RANK = 4
_EYE3 = np.eye(3)
_JITTER12 = 12 * np.finfo(float).eps * np.eye(12)
#: pseudo-inverse rank tolerance of the reference GDOP, relative to sigma_max
PINV_RCOND = 1e-10


def _vec3(name: str, a) -> np.ndarray:
    a = np.array(a, dtype=float)  # a private copy: the per-context cache must not go stale
    if a.shape != (3,):
        raise ValueError(f"MetricContext.{name} must have shape (3,), got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"MetricContext.{name} must be finite, got {a}")
    return a


def _mat(name: str, a, n: int, symmetric: bool = False) -> np.ndarray:
    a = np.array(a, dtype=float)  # a private copy: the per-context cache must not go stale
    if a.shape != (n, n):
        raise ValueError(f"MetricContext.{name} must have shape ({n}, {n}), got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"MetricContext.{name} must be finite")
    if symmetric and np.abs(a - a.T).max() > 1e-10 * np.abs(a).max():
        raise ValueError(f"MetricContext.{name} must be symmetric")
    return a


@dataclass(frozen=True, eq=False)
class MetricContext:
    """Everything a metric needs besides the candidate.

    r_L: lander position in {L} (m); v_L: velocity (m/s, enters no metric);
    R_LtoB: rotation {L} -> {B}; p_known_L: known landmark (m, the {L} origin in
    paper B); P: 12 x 12 prior covariance of [r, v, dtheta, p] (m, m/s, rad, m)
    for the information metrics, or None; R_meas: 6 x 6 bearing-noise covariance
    (rad^2) or None; boresight_B: camera boresight in {B} (candidates with
    b . boresight_B <= 0 are behind the camera and score -inf; None disables);
    min_range_m: candidates closer than this to the lander score -inf.
    """

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
        s(self, "r_L", _vec3("r_L", self.r_L))
        s(self, "v_L", _vec3("v_L", self.v_L))
        s(self, "p_known_L", _vec3("p_known_L", self.p_known_L))
        R = _mat("R_LtoB", self.R_LtoB, 3)
        (a, b, c), (d, e, f), (g, h, i) = R.tolist()
        det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
        if det <= 0 or np.abs(R @ R.T - _EYE3).max() > 1e-8:
            raise ValueError("MetricContext.R_LtoB must be a proper rotation matrix")
        s(self, "R_LtoB", R)
        if self.P is not None:
            s(self, "P", _mat("P", self.P, 12, symmetric=True))
        if self.R_meas is not None:
            s(self, "R_meas", _mat("R_meas", self.R_meas, 6, symmetric=True))
        if self.boresight_B is not None:
            bs = _vec3("boresight_B", self.boresight_B)
            nb = np.linalg.norm(bs)
            if nb == 0:
                raise ValueError("MetricContext.boresight_B must be non-zero (or None)")
            s(self, "boresight_B", bs / nb)
        if not (math.isfinite(self.min_range_m) and self.min_range_m >= 0):
            raise ValueError("MetricContext.min_range_m must be finite and >= 0")
        s(self, "_cache", {})

    @classmethod
    def trusted(cls, r_L, v_L, R_LtoB, p_known_L, P=None, R_meas=None, boresight_B=None,
                min_range_m: float = 1e-6) -> "MetricContext":
        """A context from inputs already validated once (per descent, by the
        caller): no copies, no checks, so building it is not timed as metric
        work on the planner's path. ``boresight_B`` must be a unit vector or
        None; arrays must be float64 of the documented shapes and not be
        modified while the context is in use."""
        self = object.__new__(cls)
        s = object.__setattr__
        for k, v in (("r_L", r_L), ("v_L", v_L), ("R_LtoB", R_LtoB), ("p_known_L", p_known_L),
                     ("P", P), ("R_meas", R_meas), ("boresight_B", boresight_B),
                     ("min_range_m", float(min_range_m)), ("_cache", {})):
            s(self, k, v)
        return self

    # ---- per-context precomputation (cached on the frozen instance) ----
    def _geom(self):
        """(u, x, boresight_in_L, known_ok): known line of sight, 1/rho_1, ..."""
        c = self._cache
        if "geom" not in c:
            d1 = self.p_known_L - self.r_L
            rho1 = float(np.linalg.norm(d1))
            bs_L = None if self.boresight_B is None else self.R_LtoB.T @ self.boresight_B
            known_ok = rho1 > self.min_range_m and (bs_L is None or float(d1 @ bs_L) > 0.0)
            u = d1 / rho1 if rho1 > 0 else np.full(3, np.nan)
            c["geom"] = (u, (1.0 / rho1) if rho1 > 0 else math.inf, bs_L, known_ok)
        return c["geom"]

    def _info(self):
        """(P, R_meas, P^-1, R_meas^-1) for the information metrics."""
        c = self._cache
        if "info" not in c:
            if self.P is None or self.R_meas is None:
                missing = [k for k in ("P", "R_meas") if getattr(self, k) is None]
                raise ValueError(f"information metrics need MetricContext.{' and '.join(missing)}")
            try:
                np.linalg.cholesky(self.P)
                np.linalg.cholesky(self.R_meas)
            except np.linalg.LinAlgError:
                raise ValueError("MetricContext.P and R_meas must be positive definite") from None
            Pinv = np.linalg.inv(self.P)
            W = np.linalg.inv(self.R_meas)
            c["info"] = (self.P, self.R_meas, 0.5 * (Pinv + Pinv.T), 0.5 * (W + W.T))
        return c["info"]


# --------------------------------------------------------------------------
# linear-algebra helpers
# --------------------------------------------------------------------------


def chol_logdet(A: np.ndarray, jitter: float | None = None) -> np.ndarray:
    """log det of a stack of SPD matrices (..., k, k) as 2 sum(log(diag(L))) of
    the Jacobi-equilibrated matrix D^-1/2 A D^-1/2 + jitter I, plus sum(log D).

    ``jitter`` defaults to k * machine epsilon (~1e-15, shifts log det by
    < 1e-8 for equilibrated eigenvalues >= 1e-6); a matrix whose Cholesky still
    fails is retried with the jitter multiplied by 1e3 up to 1e-8, then scored
    -inf (non-positive-definite; never NaN)."""
    A = np.asarray(A, dtype=float)
    k = A.shape[-1]
    if jitter is None:
        jitter = k * np.finfo(float).eps
    dg = np.diagonal(A, axis1=-2, axis2=-1)
    out = np.full(A.shape[:-2], -np.inf)
    ok = np.all(dg > 0, axis=-1) & np.all(np.isfinite(A), axis=(-2, -1))
    if not np.any(ok):
        return out
    s = 1.0 / np.sqrt(dg[ok])
    As = A[ok] * s[..., :, None] * s[..., None, :]
    eye = np.eye(k)
    try:
        L = np.linalg.cholesky(As + jitter * eye)
        vals = 2.0 * np.sum(np.log(np.diagonal(L, axis1=-2, axis2=-1)), axis=-1)
    except np.linalg.LinAlgError:
        vals = np.full(As.shape[0], -np.inf)
        for i, Ai in enumerate(As):
            j = jitter
            while j <= 1e-8:
                try:
                    vals[i] = 2.0 * np.sum(np.log(np.diag(np.linalg.cholesky(Ai + j * eye))))
                    break
                except np.linalg.LinAlgError:
                    j *= 1e3
    out[ok] = vals - 2.0 * np.sum(np.log(s), axis=-1)
    return out


def structural_singular_values(x, y, c, s2):
    """The 4 nonzero singular values of H (descending, last axis) from
    x = 1/rho_1, y = 1/rho_2 (1/m), c = u . w and s2 = |u x w|^2 (closed form,
    module docstring).  Broadcasts over arrays."""
    lam = _structural_sq(x, y, c, s2)
    return np.sqrt(np.stack(lam, axis=-1))


def structural_scores(name: str, x, y, c, s2) -> np.ndarray:
    """The paper's H baselines (``name`` in :data:`H_METRICS`: svd, gdop, cond;
    larger is better) in closed form from the pair geometry of
    :func:`structural_singular_values` (x = 1/rho_1, y = 1/rho_2 in 1/m, c = u . w,
    s2 = |u x w|^2), broadcast over arrays: the scores of :meth:`Metric.batch`'s
    fast path, for callers that hold the geometry already (the batched planner)."""
    return _scores_from_sq(name, *_structural_sq(x, y, c, s2))


def _structural_sq(x, y, c, s2):
    """(l1+, l1-, l2+, l2-) squared singular values, cancellation-free."""
    a = 1.0 + x * x
    d = 1.0 + 2.0 * y * y
    m = 0.5 * (a + d)
    e = 0.5 * (a - d)
    k1 = c + x * y
    k2 = 1.0 + c * x * y
    xy2 = x * x * y * y
    base = (x - c * y) ** 2 + (2.0 - c * c) * y * y
    D1 = s2 + base + xy2
    D2 = base + (1.0 + s2) * xy2  # (2 - c^2) x^2 y^2
    lp1 = m + np.sqrt(e * e + k1 * k1)
    lp2 = m + np.sqrt(e * e + k2 * k2)
    return lp1, D1 / lp1, lp2, D2 / lp2


def _scores_from_sq(name, lp1, lm1, lp2, lm2):
    if name == "svd":
        return np.sqrt(np.minimum(lm1, lm2))
    if name == "cond":
        return np.sqrt(np.minimum(lm1, lm2) / np.maximum(lp1, lp2))
    # gdop: 1 / sum 1/s^2 = 1 / sum_j (l+ + l-)/(l+ l-); l+ l- = D_j
    with np.errstate(divide="ignore"):
        tr = (lp1 + lm1) / (lp1 * lm1) + (lp2 + lm2) / (lp2 * lm2)
        return 1.0 / tr


def _scores_from_H(name: str, H: np.ndarray, ctx: MetricContext) -> np.ndarray:
    """The obvious linear algebra on explicit H (n, 6, 12)."""
    if name in WHITENED:
        Ci, L = _whitening(ctx)
        return _whitened_scores(name, Ci @ H @ L)
    if name in H_METRICS:
        s = np.linalg.svd(H, compute_uv=False)  # descending, 6 values
        if name == "svd":
            return s[:, STRUCTURAL_RANK - 1]
        if name == "cond":
            return s[:, STRUCTURAL_RANK - 1] / s[:, 0]
        Hp = np.linalg.pinv(H, rcond=PINV_RCOND)  # (H^T H)^+ = H^+ H^+T
        return 1.0 / np.einsum("nij,nij->n", Hp, Hp)
    P, Rm, _, _ = ctx._info()
    Lam = np.linalg.inv(P) + np.einsum("nki,kl,nlj->nij", H, np.linalg.inv(Rm), H)
    Lam = 0.5 * (Lam + np.swapaxes(Lam, 1, 2))
    if name == "logdet":
        return chol_logdet(Lam)
    return np.linalg.eigvalsh(Lam)[:, 0]


def _info_scores_fast(name: str, H: np.ndarray, info) -> np.ndarray:
    """Batched information metrics for H (..., 6, 12) and ``info = (P, R_meas,
    P^-1, R_meas^-1)`` (each broadcast against H's leading dimensions): logdet by
    equilibrated Cholesky of the 12 x 12 information; mineig = 1 / lambda_max of
    the posterior covariance via the 6 x 6 innovation covariance S = R + H P H^T."""
    P, Rm, Pinv, W = info
    Ht = np.swapaxes(H, -1, -2)
    if name == "logdet":
        Lam = Pinv + Ht @ W @ H
        return chol_logdet(0.5 * (Lam + np.swapaxes(Lam, -1, -2)))
    HP = H @ P  # (..., 6, 12)
    S = HP @ Ht + Rm
    S = 0.5 * (S + np.swapaxes(S, -1, -2))
    K = np.linalg.solve(S, HP)  # S^-1 H P
    Ppost = P - np.swapaxes(HP, -1, -2) @ K
    Ppost = 0.5 * (Ppost + np.swapaxes(Ppost, -1, -2))
    lmax = np.linalg.eigvalsh(Ppost)[..., -1]
    with np.errstate(divide="ignore"):
        return np.where(lmax > 0, 1.0 / lmax, -np.inf)


def _tangent_setup(ctx: MetricContext):
    """Per-context pieces of the tangent-plane information update, or None.

    Applies when R_meas is block diagonal with an isotropic candidate block
    (sigma^2 I_3, the descent case).  Then, with Lambda_k = P^-1 + H_k^T W_kk H_k
    the information after the known landmark and Sigma_k its inverse, the
    candidate's bearing adds w H_c^T H_c = G^T G with G = sqrt(w) T^T H_c (2 x 12,
    T a body-frame basis orthogonal to the candidate bearing b: b^T H_c = 0
    exactly, so the radial direction carries nothing and is dropped analytically):

        log det Lambda = log det Lambda_k + log det(I_2 + G Sigma_k G^T),
        Sigma_post = Sigma_k - (G Sigma_k)^T (I_2 + G Sigma_k G^T)^-1 G Sigma_k,

    a 2 x 2 update instead of a 12 x 12 factorisation, and free of the ~1e9
    condition number of R + H P H^T.
    """
    c = ctx._cache
    if "tangent" not in c:
        P, Rm, Pinv, W = ctx._info()
        iso = (
            not np.any(Rm[0:3, 3:6])
            and not np.any(Rm[3:6, 0:3])
            and Rm[3, 3] > 0
            and np.array_equal(Rm[3:6, 3:6], Rm[3, 3] * _EYE3)
        )
        if not iso:
            c["tangent"] = None
        else:
            Hk = me.selection_jacobian(ctx.r_L, ctx.R_LtoB, ctx.p_known_L, ctx.p_known_L)[0:3]
            Lk = Pinv + Hk.T @ W[0:3, 0:3] @ Hk
            Lk = 0.5 * (Lk + Lk.T)
            ld = float(chol_logdet(Lk[None])[0])
            sc = 1.0 / np.sqrt(np.diagonal(Lk))
            As = Lk * (sc[:, None] * sc[None, :])
            Sig = np.linalg.inv(As) * (sc[:, None] * sc[None, :])
            c["tangent"] = (1.0 / Rm[3, 3], 0.5 * (Sig + Sig.T), ld)
    return c["tangent"]


def _tangent_scores(name: str, G: np.ndarray, Sig: np.ndarray, ld) -> np.ndarray:
    """logdet / mineig from the whitened tangent rows G (..., 2, 12)
    (``measurement.tangent_jacobian``) and the known-landmark posterior Sigma_k
    (..., 12, 12) with its log det ``ld`` (...), see :func:`_tangent_setup`."""
    if Sig.ndim == 2:   # one context: one GEMM for all candidates (the bits of the
        GS = (G.reshape(-1, 12) @ Sig).reshape(G.shape)     # broadcast matmul, 6x faster)
    else:
        GS = G @ Sig  # (..., 2, 12)
    Q = GS @ np.swapaxes(G, -1, -2)
    a = 1.0 + Q[..., 0, 0]
    b = 0.5 * (Q[..., 0, 1] + Q[..., 1, 0])
    e = 1.0 + Q[..., 1, 1] - b * b / a  # Schur complement, >= 1
    if name == "logdet":
        return ld + np.log(a) + np.log(e)
    det = a * e
    Minv = np.empty_like(Q)
    Minv[..., 0, 0] = (1.0 + Q[..., 1, 1]) / det
    Minv[..., 1, 1] = a / det
    Minv[..., 0, 1] = Minv[..., 1, 0] = -b / det
    Spost = Sig - np.swapaxes(GS, -1, -2) @ Minv @ GS
    lmax = np.linalg.eigvalsh(0.5 * (Spost + np.swapaxes(Spost, -1, -2)))[..., -1]
    with np.errstate(divide="ignore"):
        return np.where(lmax > 0, 1.0 / lmax, -np.inf)


def _tangent_scalar(name: str, ctx: MetricContext, tg, d0: float, d1: float, d2: float, rho: float) -> float:
    """:func:`_tangent_scores` for one candidate at offset d = p - r in floats,
    G from ``measurement.tangent_jacobian_scalar``."""
    w, Sig, ld = tg
    c = ctx._cache
    if "R_rows" not in c:
        c["R_rows"] = ctx.R_LtoB.tolist()
    G = me.tangent_jacobian_scalar(c["R_rows"], d0, d1, d2, rho, math.sqrt(w))
    GS = G @ Sig
    (q00, q01), (q10, q11) = (GS @ G.T).tolist()
    a = 1.0 + q00
    b = 0.5 * (q01 + q10)
    e = 1.0 + q11 - b * b / a
    if name == "logdet":
        return ld + math.log(a) + math.log(e)
    det = a * e
    Minv = np.array([[(1.0 + q11) / det, -b / det], [-b / det, a / det]])
    Spost = Sig - GS.T @ (Minv @ GS)
    wv, _, info = _dsyev(Spost + Spost.T, compute_v=0)
    lmax = 0.5 * wv[-1]
    return 1.0 / lmax if info == 0 and lmax > 0 else -math.inf


def _whitening(ctx: MetricContext):
    """(C^-1 (6, 6), L (12, 12)) with R_meas = C C^T and P = L L^T (cached)."""
    c = ctx._cache
    if "whiten" not in c:
        P, Rm, _, _ = ctx._info()
        Cr = np.linalg.cholesky(Rm)
        c["whiten"] = (np.linalg.inv(Cr), np.linalg.cholesky(P))
    return c["whiten"]


def _whitened_scores(name: str, Hw: np.ndarray) -> np.ndarray:
    """The ``WHITENED[name]`` score of whitened H_w = C^-1 H L (..., 6, 12), batched
    (the single-candidate matrix path, :func:`_matrix_score`, takes one LAPACK SVD)."""
    # the singular values squared are the eigenvalues of the 6 x 6 Gram matrix
    # Hw Hw^T (LAPACK dsyevd, ~5x faster than a 6 x 12 SVD per candidate; relative
    # error of s4 ~ eps (s1 / s4)^2, tested against the SVD)
    G = Hw @ np.swapaxes(Hw, -1, -2)
    lam = np.linalg.eigvalsh(0.5 * (G + np.swapaxes(G, -1, -2)))[..., ::-1][..., :STRUCTURAL_RANK]
    return _whitened_from_sv(name, np.sqrt(np.maximum(lam, 0.0)))


def _whitened_from_sv(name: str, s: np.ndarray) -> np.ndarray:
    """The ``WHITENED[name]`` score from the four structural singular values of
    H_w (..., 4), descending."""
    base = WHITENED[name]
    if base == "svd":
        return s[..., -1]
    if base == "cond":
        return s[..., -1] / s[..., 0]
    return 1.0 / np.sum(1.0 / (s * s), axis=-1)


# ---- screening: cheap scores or bounds of many candidates (the batched edge rule)

def _whitened_tangent_setup(ctx: MetricContext):
    """Per-context pieces of the whitened metrics' tangent form, or None unless
    R_meas = sigma^2 I_6 (the descent case).

    Then C^-1 = I / sigma and H_w H_w^T = H P H^T / sigma^2. Each 3-row block of
    H has its bearing as left null vector (module docstring), so H = T T^T H
    with T = blockdiag(T_k, T_c) (6 x 4, orthonormal tangent bases of the two
    bearings), and the four nonzero eigenvalues of H_w H_w^T, the squared
    structural singular values of H_w, are those of the 4 x 4

        M = G P G^T,  G = [G_k; G_c] = T^T H / sigma (4 x 12),

    G_k the known landmark's tangent rows (no landmark columns), G_c the
    candidate's (``measurement.tangent_jacobian``). Returns (1/sigma, P, G_k P,
    G_k P G_k^T)."""
    c = ctx._cache
    if "wtangent" not in c:
        P, Rm, _, _ = ctx._info()
        s2 = float(Rm[0, 0])
        if s2 > 0 and np.array_equal(Rm, s2 * np.eye(6)):
            sc = 1.0 / math.sqrt(s2)
            # the known landmark's own rows: its bearing and range, no landmark columns
            Gk = me.tangent_jacobian(ctx.r_L, ctx.R_LtoB, ctx.p_known_L, sc).copy()
            Gk[:, 9:12] = 0.0
            GkP = Gk @ P
            c["wtangent"] = (sc, P, GkP, GkP @ Gk.T)
        else:
            c["wtangent"] = None
    return c["wtangent"]


#: the whitened screen's crude bounds: candidates whose upper bound is within this
#: relative margin of the best lower bound get the exact 4 x 4 eigenvalues (far wider
#: than the planner's short-list margin, so the short list is the exact one's)
_CRUDE_MARGIN = 1e-3


def _lmax2(a00, a01, a11):
    """Larger eigenvalue of the symmetric 2 x 2 [[a00, a01], [a01, a11]] (arrays)."""
    h = 0.5 * (a00 - a11)
    return 0.5 * (a00 + a11) + np.sqrt(h * h + a01 * a01)


def _whitened_crude_bounds(name: str, Kinv, kap, Bt, D):
    """Bounds (lo, hi) on the ``svd_w`` / ``cond_w`` score of candidates whose 4 x 4
    tangent Gram matrix is M = [[K, B], [B^T, D]] (:func:`_whitened_tangent_scores`;
    K and its eigenvalues ``kap`` (ascending) the same for every candidate, ``Bt`` =
    B^T and D (n, 2, 2)), from 2 x 2 algebra, and a mask of the candidates where
    they are unusable (non-finite, or the Schur complement not positive definite).

    With b = |B|_F >= |B|_2 and x = (y, z) a unit vector, x^T M x lies between
    the eigenvalues of [[kap_1, -b], [-b, d_1]] and [[kap_2, b], [b, d_2]] (d_i of
    D), which bound lambda_min(M) below and lambda_max(M) above; interlacing
    (K and D are principal submatrices) gives lambda_max(M) >= max(kap_2, d_2)
    and lambda_min(M) <= min(kap_1, d_1). The same on M^-1 = [[A11, A12], [A12^T,
    A22]] (block inverse: X = K^-1 B, S = D - B^T X, A22 = S^-1, A12 = -X S^-1,
    A11 = K^-1 + X S^-1 X^T): lambda_max(M^-1) = 1 / lambda_min(M) lies between
    max(|A11|_2, |A22|_2) and the larger eigenvalue of [[|A11|_2, |A12|_F],
    [|A12|_F, |A22|_2]]. The scores are sqrt(lambda_min) (svd_w) and
    sqrt(lambda_min / lambda_max) (cond_w)."""
    d00, d01, d11 = D[:, 0, 0], 0.5 * (D[:, 0, 1] + D[:, 1, 0]), D[:, 1, 1]
    hd = 0.5 * (d00 - d11)
    rd = np.sqrt(hd * hd + d01 * d01)
    d_lo, d_hi = 0.5 * (d00 + d11) - rd, 0.5 * (d00 + d11) + rd
    b2 = np.einsum("nij,nij->n", Bt, Bt)
    k1, k2 = float(kap[0]), float(kap[-1])
    h1, h2 = 0.5 * (k1 - d_lo), 0.5 * (k2 - d_hi)
    lmin_lo = np.maximum(0.5 * (k1 + d_lo) - np.sqrt(h1 * h1 + b2), 0.0)
    lmin_hi = np.minimum(k1, d_lo)
    lmax_lo = np.maximum(k2, d_hi)
    lmax_hi = 0.5 * (k2 + d_hi) + np.sqrt(h2 * h2 + b2)
    # M^-1 blocks, elementwise 2 x 2 algebra (B = Bt^T: B_ij = Bt_ji)
    (i00, i01), (i10, i11) = Kinv.tolist()
    b00, b01, b10, b11 = Bt[:, 0, 0], Bt[:, 1, 0], Bt[:, 0, 1], Bt[:, 1, 1]
    x00, x01 = i00 * b00 + i01 * b10, i00 * b01 + i01 * b11               # X = K^-1 B
    x10, x11 = i10 * b00 + i11 * b10, i10 * b01 + i11 * b11
    s00 = d00 - (b00 * x00 + b10 * x10)                                     # S = D - B^T X
    s11 = d11 - (b01 * x01 + b11 * x11)
    s01 = d01 - 0.5 * ((b00 * x01 + b10 * x11) + (b01 * x00 + b11 * x10))
    det = s00 * s11 - s01 * s01
    bad = ~((det > 0) & (s00 > 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        t00, t01, t11 = s11 / det, -s01 / det, s00 / det                    # S^-1 = A22
        y00, y01 = x00 * t00 + x01 * t01, x00 * t01 + x01 * t11             # X S^-1 = -A12
        y10, y11 = x10 * t00 + x11 * t01, x10 * t01 + x11 * t11
        a00 = i00 + (y00 * x00 + y01 * x01)                                 # A11 = K^-1 + X S^-1 X^T
        a11 = i11 + (y10 * x10 + y11 * x11)
        a01 = 0.5 * (i01 + i10) + 0.5 * ((y00 * x10 + y01 * x11) + (y10 * x00 + y11 * x01))
        al, de = _lmax2(a00, a01, a11), _lmax2(t00, t01, t11)
        g2 = y00 * y00 + y01 * y01 + y10 * y10 + y11 * y11
        up = _lmax2(al, np.sqrt(g2), de)
        lmin_lo = np.maximum(lmin_lo, 1.0 / up)
        lmin_hi = np.minimum(lmin_hi, 1.0 / np.maximum(al, de))
        if WHITENED[name] == "svd":
            lo, hi = np.sqrt(lmin_lo), np.sqrt(lmin_hi)
        else:
            lo, hi = np.sqrt(lmin_lo / lmax_hi), np.sqrt(lmin_hi / lmax_lo)
    bad |= ~(np.isfinite(lo) & np.isfinite(hi) & (lo <= hi))
    return lo, hi, bad


def _whitened_tangent_scores(name: str, ctx: MetricContext, wt, p: np.ndarray
                             ) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lo, hi) on the whitened scores of candidates ``p`` (n, 3) from the
    4 x 4 tangent Gram matrix M = [[K, B], [B^T, D]] of
    :func:`_whitened_tangent_setup` (K = G_k P G_k^T, the same for every
    candidate): ``gdop_w`` = 1 / tr(M^-1) by the block inverse, tr(M^-1) =
    tr(K^-1) + tr(S^-1) + tr(X S^-1 X^T) with X = K^-1 B and S = D - B^T X
    (2 x 2 algebra; lo = hi); ``svd_w`` and ``cond_w`` from
    :func:`_whitened_crude_bounds` for every candidate, then, for those that
    can still be within :data:`_CRUDE_MARGIN` of the best (and where the crude
    bounds are unusable), M's eigenvalues by batched LAPACK (dsyevd of a 4 x 4,
    ~2x cheaper than H_w H_w^T's 6 x 6; lo = hi; a Newton iteration on the 2 x 2
    secular equation was measured slower in numpy): about 1 % of the detected
    landmarks of a descent's planning call (measured), the same values as
    eigenvalues of all. Tested against the explicit path."""
    sc, P, GkP, K = wt
    n = len(p)
    G = me.tangent_jacobian(ctx.r_L, ctx.R_LtoB, p, sc)           # (n, 2, 12)
    G2 = G.reshape(2 * n, 12)                                     # one GEMM for all candidates
    GP = (G2 @ P).reshape(n, 2, 12)
    Bt = (G2 @ GkP.T).reshape(n, 2, 2)                             # B^T = G_c P G_k^T
    D = GP @ np.swapaxes(G, 1, 2)           # (stacked matmul: ~4x einsum's speed here)
    D = 0.5 * (D + np.swapaxes(D, 1, 2))
    c = ctx._cache
    if "wtangent_K" not in c:
        c["wtangent_K"] = (np.linalg.inv(K), np.linalg.eigvalsh(K))
    Kinv, kap = c["wtangent_K"]                                  # K^-1, eig(K)
    if WHITENED[name] == "gdop":
        X = Kinv @ np.swapaxes(Bt, 1, 2)                           # K^-1 B (n, 2, 2)
        S = D - Bt @ X
        s00, s01, s11 = S[:, 0, 0], 0.5 * (S[:, 0, 1] + S[:, 1, 0]), S[:, 1, 1]
        det = s00 * s11 - s01 * s01
        with np.errstate(divide="ignore", invalid="ignore"):
            Si = np.stack([np.stack([s11, -s01], -1), np.stack([-s01, s00], -1)], -2) / det[:, None, None]
            tr = np.trace(Kinv) + (s00 + s11) / det + np.einsum("nij,njk,nik->n", X, Si, X)
            v = np.where(det > 0, 1.0 / tr, 0.0)
        return v, v
    if kap[0] > 0 and np.all(np.isfinite(Kinv)):
        lo, hi, bad = _whitened_crude_bounds(name, Kinv, kap, Bt, D)
        best = np.max(np.where(bad, -np.inf, lo), initial=-np.inf)
        ex = np.flatnonzero(bad | (hi >= best * (1.0 - _CRUDE_MARGIN)))
    else:                                   # (K not positive definite: every candidate exactly)
        lo, hi, ex = np.empty(n), np.empty(n), np.arange(n)
    M = np.empty((ex.size, 4, 4))
    M[:, 0:2, 0:2] = K
    M[:, 2:4, 0:2] = Bt[ex]
    M[:, 0:2, 2:4] = np.swapaxes(Bt[ex], 1, 2)
    M[:, 2:4, 2:4] = D[ex]
    lam = np.linalg.eigvalsh(M)[:, ::-1]
    lo[ex] = hi[ex] = _whitened_from_sv(name, np.sqrt(np.maximum(lam, 0.0)))
    return lo, hi


def _mineig_top(tg):
    """(k, s (12,) descending, V (12, 12)) of the known-landmark posterior
    Sigma_k (:func:`_tangent_setup`), k the smallest count of its largest
    eigenvalues with s_(k+1) <= s_1 / 2 (at most 4)."""
    w, Sig, ld = tg
    s, V = np.linalg.eigh(Sig)
    s, V = s[::-1].copy(), V[:, ::-1].copy()
    k = 1
    while k < 4 and s[k] > 0.5 * s[0]:
        k += 1
    return k, s, V


def _mineig_bounds(ctx: MetricContext, tg, p: np.ndarray, rtol: float | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (lo, hi) on ``mineig`` = 1 / lambda_max(Sigma_post) of candidates
    ``p`` (n, 3), from the tangent update of :func:`_tangent_setup` without a
    12 x 12 eigenproblem per candidate.

    In the eigenbasis V of Sigma_k (eigenvalues s_1 >= s_2 >= ...), Sigma_post
    = diag(s) - W^T W with W = L^T G Sigma_k V (2 x 12), L L^T = M^-1 and
    M = I + G Sigma_k G^T (a rank-2 downdate). Split V at the k largest
    eigenvalues: the top block A = diag(s_t) - W_t^T W_t (k x k), the coupling
    C = -W_t^T W_r and the rest B <= s_(k+1) I (Sigma_post <= Sigma_k).
    Rayleigh-Ritz gives lambda_max >= lambda_max(A); for a unit x = (a, b),
    x^T Sigma_post x <= lambda_max(A) |a|^2 + 2 |C|_F |a| |b| + s_(k+1) |b|^2,
    so lambda_max <= the larger eigenvalue of [[lambda_max(A), |C|_F],
    [|C|_F, s_(k+1)]] (and <= s_1).

    ``rtol``: the brackets of the candidates that can still be the best (lower
    bound of lambda_max not above the smallest upper bound) are then halved
    until each is within ``rtol`` relative, by bisection on the inertia of
    Sigma_post - lambda I: with D = diag(s - lambda), the number of its
    eigenvalues above lambda is #(s_i > lambda) + #pos(I_2 - W D^-1 W^T) - 2
    (Haynsworth inertia additivity on [[D, W^T], [W, I]]), a 2 x 2 test."""
    c = ctx._cache
    if "mineig_top" not in c:
        c["mineig_top"] = _mineig_top(tg)
    k, s, V = c["mineig_top"]
    w, Sig, ld = tg
    n = len(p)
    G = me.tangent_jacobian(ctx.r_L, ctx.R_LtoB, p, math.sqrt(w))   # (n, 2, 12)
    GS = (G.reshape(2 * n, 12) @ Sig).reshape(n, 2, 12)             # one GEMM for all candidates
    Q = GS @ np.swapaxes(G, 1, 2)           # (stacked matmul: ~4x einsum's speed here)
    a = 1.0 + Q[:, 0, 0]
    b = 0.5 * (Q[:, 0, 1] + Q[:, 1, 0])
    d = 1.0 + Q[:, 1, 1]
    det = a * d - b * b
    m00, m01, m11 = d / det, -b / det, a / det                      # M^-1
    l00 = np.sqrt(m00)
    l10 = m01 / l00
    l11 = np.sqrt(np.maximum(m11 - l10 * l10, 0.0))
    Y = (GS.reshape(2 * n, 12) @ V).reshape(n, 2, 12)
    W0 = l00[:, None] * Y[:, 0] + l10[:, None] * Y[:, 1]            # W = L^T Y
    W1 = l11[:, None] * Y[:, 1]
    Wt = np.stack([W0[:, :k], W1[:, :k]], axis=1)                   # (n, 2, k)
    A = np.diag(s[:k]) - np.swapaxes(Wt, 1, 2) @ Wt
    lo = np.linalg.eigvalsh(0.5 * (A + np.swapaxes(A, 1, 2)))[:, -1] if k > 1 else A[:, 0, 0].copy()
    Cw = np.swapaxes(Wt, 1, 2) @ np.stack([W0[:, k:], W1[:, k:]], axis=1)
    c2 = np.einsum("nij,nij->n", Cw, Cw)
    half = 0.5 * (lo - s[k])
    hi = np.minimum(0.5 * (lo + s[k]) + np.sqrt(half * half + c2), s[0])
    lo = np.minimum(lo, hi)
    if rtol is not None:
        _bisect_lambda_max(s, W0, W1, lo, hi, rtol)
    with np.errstate(divide="ignore"):
        return np.where(hi > 0, 1.0 / hi, -np.inf), np.where(lo > 0, 1.0 / lo, np.inf)


#: :func:`_bisect_lambda_max`: this few candidates left to narrow get lambda_max by
#: LAPACK instead (a bisection step costs ~25 us of numpy calls whatever its size, and
#: a descent's planning call spends ~15 of its ~21 steps on 1-8 candidates: measured)
_EXACT_FEW = 8


def _bisect_lambda_max(s, W0, W1, lo, hi, rtol: float, max_iter: int = 64) -> None:
    """Narrow the brackets lo <= lambda_max(diag(s) - W^T W) <= hi in place
    (W rows W0, W1 (n, 12)) of the candidates that can still have the smallest
    lambda_max, until each is within ``rtol`` (see :func:`_mineig_bounds`); once
    at most :data:`_EXACT_FEW` are left, their lambda_max is computed (batched
    LAPACK, clipped into the bracket: lo = hi)."""
    for _ in range(max_iter):
        act = np.flatnonzero((lo <= hi.min()) & (hi - lo > rtol * np.abs(hi)))
        if not act.size:
            return
        if act.size <= _EXACT_FEW:
            w0, w1 = W0[act], W1[act]
            A = np.diag(s) - (w0[:, :, None] * w0[:, None, :] + w1[:, :, None] * w1[:, None, :])
            lam = np.clip(np.linalg.eigvalsh(A)[:, -1], lo[act], hi[act])
            lo[act] = hi[act] = lam
            return
        mid = 0.5 * (lo[act] + hi[act])
        with np.errstate(divide="ignore", invalid="ignore"):
            dinv = 1.0 / (s[None, :] - mid[:, None])
        w0, w1 = W0[act], W1[act]
        a = 1.0 - np.einsum("ni,ni->n", w0 * w0, dinv)
        c = 1.0 - np.einsum("ni,ni->n", w1 * w1, dinv)
        b = np.einsum("ni,ni->n", w0 * w1, dinv)
        det = a * c - b * b
        npos = np.where(det < 0, 1, np.where(a + c > 0, 2, 0))
        above = (s[None, :] > mid[:, None]).sum(axis=1) + npos - 2 >= 1   # lambda_max > mid
        ok = np.isfinite(det)
        lo[act] = np.where(ok & above, mid, lo[act])
        hi[act] = np.where(ok & ~above, mid, hi[act])
        if not ok.all():                  # mid on an eigenvalue of Sigma_k: stop there
            return


def _candidate_H(ctx: MetricContext, d0: float, d1: float, d2: float, rho: float) -> np.ndarray:
    """H (6 x 12) of eq. 14-18 for one candidate at offset d = p - r: the
    known-landmark rows cached on ``ctx``, the candidate rows from
    ``measurement.jacobian_blocks`` (same values as ``measurement.selection_jacobian``)."""
    c = ctx._cache
    if "known_rows" not in c:
        Hb = me.selection_jacobian(ctx.r_L, ctx.R_LtoB, ctx.p_known_L, ctx.p_known_L)
        Hb[3:6] = 0.0
        c["known_rows"] = Hb
    H = c["known_rows"].copy()
    inv = 1.0 / rho
    _, HC, Sb = me.jacobian_blocks(ctx.R_LtoB, np.array([d0 * inv, d1 * inv, d2 * inv]), inv)
    H[3:6, 0:3] = -HC  # eq. 15
    H[3:6, 6:9] = Sb   # eq. 16
    H[3:6, 9:12] = HC  # eq. 17
    return H


def _matrix_scalar(name: str, ctx: MetricContext, d0: float, d1: float, d2: float, rho: float) -> float:
    """The explicit matrix computation for one candidate with minimal overhead:
    H by eq. 14-18, then one LAPACK SVD (dgesvd) of the 6 x 12 H for
    svd/gdop/cond (gdop from the singular values above PINV_RCOND sigma_max,
    i.e. exactly the pseudo-inverse trace), or the generic 12 x 12 information."""
    return _matrix_score(name, ctx, _candidate_H(ctx, d0, d1, d2, rho))


def _matrix_score(name: str, ctx: MetricContext, H: np.ndarray) -> float:
    """The explicit matrix computation on one 6 x 12 H (see :func:`_matrix_scalar`)."""
    if name in WHITENED:
        Ci, L = _whitening(ctx)
        # (ndarray.dot: the same BLAS gemm as @ on one pair, without the matmul
        # ufunc's dispatch; this is the per-pair explicit path of every search)
        sv = _dgesvd(Ci.dot(H).dot(L), compute_uv=0)[1]
        return float(_whitened_from_sv(name, sv[None, :STRUCTURAL_RANK])[0])
    if name not in H_METRICS:
        return _info_scalar(name, ctx, H)
    sv = _dgesvd(H, compute_uv=0)[1]
    if name == "svd":
        return float(sv[STRUCTURAL_RANK - 1])
    if name == "cond":
        return float(sv[STRUCTURAL_RANK - 1] / sv[0])
    keep = sv[sv > PINV_RCOND * sv[0]]
    return float(1.0 / np.sum(1.0 / (keep * keep)))


def _info_scalar(name: str, ctx: MetricContext, H: np.ndarray) -> float:
    """Single-candidate information metric, generic R_meas: equilibrated Cholesky
    of the 12 x 12 information (logdet) or the posterior covariance (mineig),
    with direct LAPACK calls.  Same formulas as the batch path."""
    P, Rm, Pinv, W = ctx._info()
    if name == "logdet":
        Lam = Pinv + H.T.dot(W).dot(H)
        s = 1.0 / np.sqrt(np.diagonal(Lam))
        As = Lam * (s[:, None] * s[None, :]) + _JITTER12
        Lc, info = _dpotrf(As, lower=1)  # reads the lower triangle only
        if info != 0:
            return float(chol_logdet(Lam[None])[0])
        return float(2.0 * (np.log(np.diagonal(Lc)).sum() - np.log(s).sum()))
    HP = H.dot(P)
    _, K, info = _dposv(HP.dot(H.T) + Rm, HP)  # S^-1 H P, S = R + H P H^T
    if info != 0:
        return -math.inf
    Ppost = P - HP.T.dot(K)
    w, _, info = _dsyev(Ppost + Ppost.T, compute_v=0)
    lmax = 0.5 * w[-1]
    return 1.0 / lmax if info == 0 and lmax > 0 else -math.inf


def _matrix_scores(name: str, st: "ContextStack", ri: np.ndarray, H: np.ndarray) -> np.ndarray:
    """:func:`_matrix_score` of many pairs (run ``ri`` (K,) of ``st``, H (K, 6, 12)),
    the same bits: the matrix products and elementwise steps of the whitened and
    information metrics for all pairs at once (numpy's stacked matmul runs per
    matrix the BLAS gemm that ``ndarray.dot`` runs on one, bit-equal whatever the
    memory order: measured), the LAPACK factorisations pair by pair (the per-pair
    numpy overhead was ~3/4 of a pair's 15-20 us). Tested equal to
    :meth:`Metric.matrix_scalar`."""
    K = len(ri)
    tk = st.take
    if name in H_METRICS:
        return np.array([_matrix_score(name, st.ctxs[r], h) for r, h in zip(ri.tolist(), H)])
    if name in WHITENED:
        Ci, L = st.stacked("whiten", _whitening)
        Hw = (tk(Ci, ri) @ H) @ tk(L, ri)
        sv = np.array([_dgesvd(h, compute_uv=0)[1][:STRUCTURAL_RANK] for h in Hw]).reshape(K, -1)
        return _whitened_from_sv(name, sv)
    P, Rm, Pinv, W = (tk(a, ri) for a in st.stacked("info", MetricContext._info))
    out = np.empty(K)
    if name == "logdet":                          # _info_scalar's steps, stacked
        Lam = Pinv + (np.swapaxes(H, -1, -2) @ W) @ H
        s = 1.0 / np.sqrt(np.diagonal(Lam, axis1=-2, axis2=-1))
        As = Lam * (s[:, :, None] * s[:, None, :]) + _JITTER12
        dg = np.empty((K, 12))
        bad = []
        for k in range(K):
            Lc, info = _dpotrf(As[k], lower=1)
            if info != 0:
                bad.append(k)
                dg[k] = 1.0
            else:
                dg[k] = np.diagonal(Lc)
        out[:] = 2.0 * (np.log(dg).sum(axis=-1) - np.log(s).sum(axis=-1))
        for k in bad:
            out[k] = float(chol_logdet(Lam[k][None])[0])
        return out
    HP = H @ P
    S = HP @ np.swapaxes(H, -1, -2) + Rm
    Kg = np.zeros((K, 6, 12))
    ok = np.ones(K, bool)
    for k in range(K):
        _, Kk, info = _dposv(S[k], HP[k])      # S^-1 H P
        if info != 0:
            ok[k] = False
        else:
            Kg[k] = Kk
    Ppost = P - np.swapaxes(HP, -1, -2) @ Kg
    for k in range(K):
        if not ok[k]:
            out[k] = -math.inf
            continue
        w, _, info = _dsyev(Ppost[k] + Ppost[k].T, compute_v=0)
        lmax = 0.5 * w[-1]
        out[k] = 1.0 / lmax if info == 0 and lmax > 0 else -math.inf
    return out


# --------------------------------------------------------------------------
# the metric object
# --------------------------------------------------------------------------


def _as_cands(cand_L) -> np.ndarray:
    c = np.asarray(cand_L, dtype=float)
    if c.ndim == 1:
        c = c[None, :]
    if c.ndim != 2 or c.shape[1] != 3:
        raise ValueError(f"cand_L must have shape (n, 3), got {np.shape(cand_L)}")
    if not np.all(np.isfinite(c)):
        raise ValueError("cand_L must be finite")
    return c


class ContextStack:
    """A batch of planning contexts (one :class:`MetricContext` per run) with
    their per-run arrays stacked along a leading run axis R: ``r_L`` (R, 3),
    ``R_LtoB`` (R, 3, 3), ``p_known_L`` (R, 3), the known line of sight ``u``
    (R, 3) and inverse range ``x`` (R,), ``bs_L`` (R, 3) or None, ``known_ok``
    and ``min_range`` (R,). Per-run precomputations (whitening, the
    tangent-plane setup, the information pieces) come from each context's own
    cache, stacked on first use. Build it once per planning step
    (:func:`stack_contexts`) and pass it to :meth:`Metric.batch`."""

    def __init__(self, ctxs):
        self.ctxs = tuple(ctxs)
        if not self.ctxs:
            raise ValueError("stack_contexts: no contexts")
        geo = [c._geom() for c in self.ctxs]
        self.r_L = np.stack([c.r_L for c in self.ctxs])
        self.R_LtoB = np.stack([c.R_LtoB for c in self.ctxs])
        self.p_known_L = np.stack([c.p_known_L for c in self.ctxs])
        self.u = np.stack([g[0] for g in geo])
        self.x = np.array([g[1] for g in geo])
        has_bs = [g[2] is not None for g in geo]
        if any(has_bs) and not all(has_bs):
            raise ValueError("stack_contexts: boresight_B must be given for every context or for none")
        self.bs_L = np.stack([g[2] for g in geo]) if all(has_bs) else None
        self.known_ok = np.array([g[3] for g in geo], dtype=bool)
        self.min_range = np.array([c.min_range_m for c in self.ctxs])
        self._per_run = {}

    def __len__(self):
        return len(self.ctxs)

    def per_run(self, key: str, fn):
        """``fn(ctx)`` for every run, computed once (cached on the stack)."""
        if key not in self._per_run:
            self._per_run[key] = [fn(c) for c in self.ctxs]
        return self._per_run[key]

    def stacked(self, key: str, fn, fill=None):
        """The tuple ``fn(ctx)`` of arrays stacked over runs, computed once;
        runs where ``fn`` returns None get ``fill``."""
        k = "stacked:" + key
        if k not in self._per_run:
            vals = [fill if v is None else v for v in self.per_run(key, fn)]
            self._per_run[k] = tuple(np.stack(v) for v in zip(*vals))
        return self._per_run[k]

    def take(self, a: np.ndarray, ri: np.ndarray) -> np.ndarray:
        """Per-run array ``a`` (R, ...) at the pairs' runs ``ri`` (one run: the
        run's own array, broadcast, without a copy per candidate)."""
        return a[0] if len(self.ctxs) == 1 else a[ri]


def stack_contexts(ctxs) -> ContextStack:
    """A :class:`ContextStack` of the contexts ``ctxs`` (one per run)."""
    return ctxs if isinstance(ctxs, ContextStack) else ContextStack(ctxs)


def _single_stack(ctx: MetricContext) -> ContextStack:
    c = ctx._cache
    if "stack" not in c:
        c["stack"] = ContextStack((ctx,))
    return c["stack"]


def _offsets(st: ContextStack, c: np.ndarray):
    """``(d = c - r_L, |d|, valid)`` for candidates ``c`` (R, n, 3): valid = beyond
    ``min_range``, in front of the camera, and the known landmark usable."""
    d = c - st.r_L[:, None, :]
    rho = np.sqrt(np.einsum("...i,...i->...", d, d))
    ok = rho > st.min_range[:, None]
    if st.bs_L is not None:
        ok &= (d @ st.bs_L[:, :, None])[..., 0] > 0.0
    ok &= st.known_ok[:, None]
    return d, rho, ok


def _pairs(st: ContextStack, c: np.ndarray, mask=None):
    """Valid (run, candidate) pairs of candidates ``c`` (R, n, 3): ``(ok (R, n),
    run index (K,), p (K, 3), d = p - r (K, 3), |d| (K,))``."""
    d, rho, ok = _offsets(st, c)
    if mask is not None:
        ok &= mask
    if len(st) == 1:  # one context: 1-D selections (cheaper), run index all 0
        j = np.flatnonzero(ok[0])
        return ok, np.zeros(j.size, np.intp), c[0, j], d[0, j], rho[0, j]
    ri = np.nonzero(ok)[0]
    return ok, ri, c[ok], d[ok], rho[ok]


def _valid(ctx: MetricContext, c: np.ndarray):
    """(d2, rho2, valid mask) for candidates c (n, 3) of one context."""
    d, rho, ok = _offsets(_single_stack(ctx), c[None])
    return d[0], rho[0], ok[0]


_NO_TANGENT = (math.nan, np.zeros((12, 12)), math.nan)


def _score_pairs(name: str, st: ContextStack, ri, p, d, rho) -> np.ndarray:
    """Scores of the valid pairs (run ``ri`` (K,), candidate ``p`` (K, 3)): the
    closed form (svd/gdop/cond), the whitened H of ``measurement.selection_jacobian``
    (B-X1 whitened), or the information update (tangent-plane 2 x 2 update for runs
    with isotropic candidate noise, else the generic 12 x 12 path)."""
    tk = st.take
    if name in H_METRICS:
        u = tk(st.u, ri)
        w = d / rho[:, None]
        cr = cross(u, w)
        # row sums (not w @ u): the bits of one candidate at a time, whatever the batch
        add = np.add.reduce
        return structural_scores(name, tk(st.x, ri), 1.0 / rho, add(w * u, axis=-1),
                                 add(cr * cr, axis=-1))
    if name in WHITENED:
        Ci, L = st.stacked("whiten", _whitening)
        H = me.selection_jacobian(tk(st.r_L, ri), tk(st.R_LtoB, ri), tk(st.p_known_L, ri), p)
        return _whitened_scores(name, tk(Ci, ri) @ H @ tk(L, ri))
    tan_ok = np.array([t is not None for t in st.per_run("tangent", _tangent_setup)])
    if tan_ok.all():
        w, Sig, ld = st.stacked("tangent", _tangent_setup)
        G = me.tangent_jacobian(tk(st.r_L, ri), tk(st.R_LtoB, ri), p, np.sqrt(tk(w, ri)))
        return _tangent_scores(name, G, tk(Sig, ri), tk(ld, ri))
    out = np.empty(len(ri))
    tan = tan_ok[ri]
    if tan.any():   # runs of both kinds in one batch
        rs = ri[tan]
        w, Sig, ld = st.stacked("tangent", _tangent_setup, _NO_TANGENT)
        G = me.tangent_jacobian(st.r_L[rs], st.R_LtoB[rs], p[tan], np.sqrt(w[rs]))
        out[tan] = _tangent_scores(name, G, Sig[rs], ld[rs])
    rs = ri[~tan]
    info = st.stacked("info", MetricContext._info)
    H = me.selection_jacobian(tk(st.r_L, rs), tk(st.R_LtoB, rs), tk(st.p_known_L, rs), p[~tan])
    out[~tan] = _info_scores_fast(name, H, tuple(tk(a, rs) for a in info))
    return out


class Metric:
    """A selection metric (larger is better) with evaluation counters.

    ``metric(ctx, cand_L (n,3)) -> (n,)`` fastest faithful batch path;
    ``metric.scalar(ctx, p_L (3,)) -> float`` minimal-overhead single candidate;
    ``metric.reference``, ``metric.casadi_map``, ``metric.numpy_H``: the
    CasADi-per-candidate, CasADi ``Function.map`` and numpy-H paths (same values).
    ``n_evals`` counts candidate evaluations, ``n_calls`` calls, over all paths.
    """

    larger_is_better = True

    def __init__(self, name: str):
        if name not in METRIC_NAMES:
            raise ValueError(f"unknown metric {name!r}; expected one of {METRIC_NAMES}")
        self.name = name
        self.n_evals = 0
        self.n_calls = 0

    def __repr__(self):
        return f"Metric({self.name!r}, n_evals={self.n_evals}, n_calls={self.n_calls})"

    def reset(self) -> None:
        self.n_evals = 0
        self.n_calls = 0

    def _count(self, n: int) -> None:
        self.n_evals += n
        self.n_calls += 1

    # ---- fastest batch path ----
    def __call__(self, ctx: MetricContext, cand_L) -> np.ndarray:
        c = _as_cands(cand_L)
        if c.shape[0] == 1:  # the sequential golden-section case: scalar fast path
            return np.array([self.scalar(ctx, c[0])])
        self._count(c.shape[0])
        return self._batch(_single_stack(ctx), c[None], None)[0]

    def batch(self, ctxs, cand_L, mask=None, path: str = "fast") -> np.ndarray:
        """Scores (R, n) of candidates ``cand_L`` (R, n, 3) (m, {L}) for R planning
        contexts ``ctxs`` (a sequence of :class:`MetricContext` or a
        :class:`ContextStack`, one per run): the fastest faithful batch path
        (closed form, or H from ``measurement`` and batched LAPACK), the same
        numbers as ``metric(ctx_r, cand_L[r])`` run by run. ``mask`` (R, n)
        bool marks real candidates (ragged candidate lists padded to n); masked
        entries score -inf and may hold any value. Counts the real candidates.
        ``path="matrix"``: the explicit matrix computation per pair (H of eq.
        14-18 for all pairs at once, then the LAPACK SVD / 12 x 12 information
        of :meth:`matrix_scalar`, the same bits as it: the planner's default
        ``eval_path``)."""
        st = stack_contexts(ctxs)
        c = np.asarray(cand_L, dtype=float)
        if c.ndim != 3 or c.shape[0] != len(st) or c.shape[2] != 3:
            raise ValueError(f"cand_L must have shape ({len(st)}, n, 3), got {c.shape}")
        if mask is not None:
            mask = np.asarray(mask, dtype=bool)
            if mask.shape != c.shape[:2]:
                raise ValueError(f"mask must have shape {c.shape[:2]}, got {mask.shape}")
            c = np.where(mask[..., None], c, st.r_L[:, None, :])  # padding: at the lander (invalid)
        if not np.all(np.isfinite(c)):
            raise ValueError("cand_L must be finite")
        self._count(int(c.shape[0] * c.shape[1] if mask is None else mask.sum()))
        return self._batch(st, c, mask, path)

    def _batch(self, st: ContextStack, c: np.ndarray, mask, path: str = "fast") -> np.ndarray:
        ok, ri, p, d, rho = _pairs(st, c, mask)
        out = np.full(ok.shape, -np.inf)
        if not ri.size:
            return out
        if path == "fast":
            out[ok] = _score_pairs(self.name, st, ri, p, d, rho)
        elif path == "matrix":  # H of all pairs at once, then per-pair LAPACK
            tk = st.take
            H = me.selection_jacobian(tk(st.r_L, ri), tk(st.R_LtoB, ri), tk(st.p_known_L, ri), p)
            out[ok] = _matrix_scores(self.name, st, ri, H)
        else:
            raise ValueError(f"Metric.batch: path must be 'fast' or 'matrix', got {path!r}")
        return out

    def screen(self, ctx: MetricContext, cand_L, rtol: float | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
        """Cheap bounds ``(lo, hi)`` (n,) on the score of each candidate
        ``cand_L`` (n, 3), for screening many candidates before the explicit
        path (the batched planner's edge rule): the closed form (svd, gdop,
        cond; lo = hi), the tangent-plane update (logdet; lo = hi), rigorous
        bounds without a 12 x 12 eigenproblem per candidate (mineig,
        :func:`_mineig_bounds`), the 4 x 4 tangent Gram matrix (whitened, when
        R_meas = sigma^2 I, :func:`_whitened_tangent_setup`), else the fast
        path. They hold for the explicit path's values up to rounding (tested);
        the caller adds a tolerance. -inf where invalid (both). ``rtol``:
        mineig narrows the bounds of the candidates that can be the best to
        within ``rtol`` relative (the others keep their screening bounds)."""
        c = _as_cands(cand_L)
        self._count(c.shape[0])
        _, _, ok = _valid(ctx, c)
        lo = np.full(c.shape[0], -np.inf)
        hi = lo.copy()
        if ok.any():
            p = c[ok]
            tg = _tangent_setup(ctx) if self.name == "mineig" else None
            wt = _whitened_tangent_setup(ctx) if self.name in WHITENED else None
            if tg is not None:
                lo[ok], hi[ok] = _mineig_bounds(ctx, tg, p, rtol)
            elif wt is not None:
                lo[ok], hi[ok] = _whitened_tangent_scores(self.name, ctx, wt, p)
            else:
                lo[ok] = hi[ok] = self._batch(_single_stack(ctx), p[None], None)[0]
        return lo, hi

    # ---- minimal-overhead single candidate (golden-section inner loop) ----
    def scalar(self, ctx: MetricContext, p_L) -> float:
        self.n_evals += 1
        self.n_calls += 1
        u, x, bs_L, known_ok = ctx._geom()
        r = ctx.r_L
        d0 = float(p_L[0]) - float(r[0])
        d1 = float(p_L[1]) - float(r[1])
        d2 = float(p_L[2]) - float(r[2])
        if not (math.isfinite(d0) and math.isfinite(d1) and math.isfinite(d2)):
            raise ValueError("p_L must be finite")
        rho2 = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not known_ok or rho2 <= ctx.min_range_m:
            return -math.inf
        if bs_L is not None and d0 * bs_L[0] + d1 * bs_L[1] + d2 * bs_L[2] <= 0.0:
            return -math.inf
        if self.name in WHITENED:
            return _matrix_scalar(self.name, ctx, d0, d1, d2, rho2)
        if self.name not in H_METRICS:
            tg = _tangent_setup(ctx)
            if tg is not None:
                return _tangent_scalar(self.name, ctx, tg, d0, d1, d2, rho2)
            return _info_scalar(self.name, ctx, _candidate_H(ctx, d0, d1, d2, rho2))
        y = 1.0 / rho2
        w0, w1, w2 = d0 * y, d1 * y, d2 * y
        u0, u1, u2 = float(u[0]), float(u[1]), float(u[2])
        cg = u0 * w0 + u1 * w1 + u2 * w2
        c0, c1, c2 = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
        s2 = c0 * c0 + c1 * c1 + c2 * c2
        a = 1.0 + x * x
        dd = 1.0 + 2.0 * y * y
        m = 0.5 * (a + dd)
        e2 = (0.5 * (a - dd)) ** 2
        xy = x * y
        k1 = cg + xy
        k2 = 1.0 + cg * xy
        base = (x - cg * y) ** 2 + (2.0 - cg * cg) * y * y
        D1 = s2 + base + xy * xy
        D2 = base + (1.0 + s2) * xy * xy
        lp1 = m + math.sqrt(e2 + k1 * k1)
        lp2 = m + math.sqrt(e2 + k2 * k2)
        lm1 = D1 / lp1
        lm2 = D2 / lp2
        if self.name == "svd":
            return math.sqrt(min(lm1, lm2))
        if self.name == "cond":
            return math.sqrt(min(lm1, lm2) / max(lp1, lp2))
        if D1 <= 0.0 or D2 <= 0.0:
            return 0.0
        return 1.0 / ((lp1 + lm1) / D1 + (lp2 + lm2) / D2)

    def matrix_scalar(self, ctx: MetricContext, p_L) -> float:
        """One candidate by the explicit matrix computation the paper describes
        (H of eq. 14-18, then a LAPACK SVD / the 12 x 12 information), with
        minimal Python overhead; same value as :meth:`scalar`."""
        self.n_evals += 1
        self.n_calls += 1
        p = np.asarray(p_L, dtype=float)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ValueError(f"p_L must be a finite (3,) vector, got {p_L!r}")
        _, _, bs_L, known_ok = ctx._geom()
        d0, d1, d2 = (p - ctx.r_L).tolist()
        rho2 = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not known_ok or rho2 <= ctx.min_range_m:
            return -math.inf
        if bs_L is not None and d0 * bs_L[0] + d1 * bs_L[1] + d2 * bs_L[2] <= 0.0:
            return -math.inf
        return _matrix_scalar(self.name, ctx, d0, d1, d2, rho2)

    # ---- slower paths with identical values (tests, benchmark) ----
    def _explicit(self, ctx, cand_L, build) -> np.ndarray:
        c = _as_cands(cand_L)
        self._count(c.shape[0])
        _, _, ok = _valid(ctx, c)
        out = np.full(c.shape[0], -np.inf)
        if np.any(ok):
            out[ok] = build(c[ok])
        return out

    def reference(self, ctx: MetricContext, cand_L) -> np.ndarray:
        """One compiled CasADi Function call and one explicit linear-algebra
        evaluation (SVD / pinv / 12 x 12 information) per candidate."""
        # CasADi (its import ~15-20 ms) only on the cross-check paths: no pipeline job uses them
        from opnav.landing import casadi_model as cm

        f = cm.jacobian_function()

        def build(c):
            vals = []
            for p in c:
                H = f(ctx.r_L, ctx.v_L, ctx.p_known_L, p, ctx.R_LtoB).full()
                vals.append(_scores_from_H(self.name, H[None], ctx)[0])
            return np.array(vals)

        return self._explicit(ctx, cand_L, build)

    def casadi_map(self, ctx: MetricContext, cand_L, parallelization: str = "serial") -> np.ndarray:
        """H for all candidates via ``Function.map(n)``, then batched linear algebra."""
        from opnav.landing import casadi_model as cm  # CasADi only on the cross-check paths

        def build(c):
            H = cm.jacobian_casadi_batch(ctx.r_L, ctx.v_L, ctx.p_known_L, c, ctx.R_LtoB, parallelization)
            if self.name in H_METRICS or self.name in WHITENED:
                return _scores_from_H(self.name, H, ctx)
            return _info_scores_fast(self.name, H, ctx._info())

        return self._explicit(ctx, cand_L, build)

    def numpy_H(self, ctx: MetricContext, cand_L) -> np.ndarray:
        """H for all candidates in numpy (eq. 14-18), then batched SVD / pinv /
        Cholesky; a single candidate goes through :meth:`matrix_scalar`."""
        c = _as_cands(cand_L)
        if c.shape[0] == 1:
            return np.array([self.matrix_scalar(ctx, c[0])])

        def build(c):
            H = me.selection_jacobian(ctx.r_L, ctx.R_LtoB, ctx.p_known_L, c)
            if self.name in H_METRICS or self.name in WHITENED:
                return _scores_from_H(self.name, H, ctx)
            return _info_scores_fast(self.name, H, ctx._info())

        return self._explicit(ctx, cand_L, build)


def make_metric(name: str) -> Metric:
    """The selection metric ``name`` (one of :data:`METRIC_NAMES`), larger is
    better; see :class:`Metric` for the call forms and counters."""
    return Metric(name)


ScoreFn = Callable[[MetricContext, np.ndarray], np.ndarray]
