"""EM estimation of the camera misalignment (paper A sec. 2.2-2.3, eq. 10-27; SPEC A.3).

Description
    E-step: with the smoothed moments ``X_{k|N}, P_{k|N}`` (and ``P_{k,k-1|N}``)
    of one window, the expected complete-data log-likelihood (eq. 21) depends
    on theta only through ``-1/2 sum_k Tr(R_k^-1 B_k(theta))`` (eq. 23, 26).

    M-step (closed form): with the small-angle ``A_m = I - [theta x]`` and the
    Mars vector in the calibrated camera frame ``u_k = A_c^i,k (X_M - r_k)``,
    ``z_k - A_m u_k = e_k - [u_k x] theta`` with ``e_k = z_k - u_k``, so

        Tr(R^-1 B(theta)) = sum_k E[(e_k - U_k theta)^T W_k (e_k - U_k theta)],
        U_k = [u_k x], W_k = R_k^-1,

    is quadratic in theta; its minimiser solves ``N theta = b`` with
    ``N = sum E[U^T W U]``, ``b = sum E[U^T W e]`` (expectations over the
    smoothed Gaussian of ``u_k``). ``N`` is singular along the boresight roll
    tz (``u`` along the camera z axis): directions whose eigenvalue is below
    ``tz_tol`` times the largest are held at their current value and reported
    unobservable.

    Iterations: :func:`em_window` runs plain EM (``method="plain"``) or the
    SQUAREM accelerator of Varadhan & Roland (2008, scheme S3, with the
    stabilising EM step and a monotonicity fall-back to the plain double step,
    ``method="squarem"``). Both never decrease the observed-data
    log-likelihood (prediction-error decomposition, reported per evaluation).

Units: rad inside; arcsec only in outputs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .ekf import POS, FilterResult, Window, run_filter
from .smoother import SmootherResult, bryson_frazier

EPS = np.zeros((3, 3, 3))
EPS[0, 1, 2] = EPS[1, 2, 0] = EPS[2, 0, 1] = 1.0
EPS[0, 2, 1] = EPS[2, 1, 0] = EPS[1, 0, 2] = -1.0


@dataclass
class EStats:
    """Sufficient statistics of the M-step: ``N theta = b`` (S,3,3), (S,3)."""

    N: np.ndarray
    b: np.ndarray
    J_stars: np.ndarray | None = None  # (3, 3) the star images' part of N (``stars`` variant)


def los_moments(s: SmootherResult, win: Window) -> tuple[np.ndarray, np.ndarray]:
    """Mean (S,n,3) and second moment E[u u^T] (S,n,3,3) of u_k, samples 1..n.

    ``E[u u^T] = C P_rr C^T + m m^T`` with ``(C P C^T)_im = sum_j sum_l (C_ij P_jl) C_ml``,
    summed in that order (j outer, l inner) from zero: the bits of
    ``numpy.einsum("kij,skjl,kml->skim", C, P, C)`` (a test checks it), as whole-array
    products over (seed, sample), about four times faster than the einsum."""
    C = win.C[1:]
    m = win.u_ref[1:] - np.einsum("kij,skj->ski", C, s.xs[:, 1:, :3])
    Ct = np.ascontiguousarray(C.transpose(1, 2, 0))  # (i, j, k)
    Pt = np.ascontiguousarray(s.Ps[:, 1:, :3, :3].transpose(2, 3, 0, 1))  # (j, l, s, k)
    mt = np.ascontiguousarray(m.transpose(2, 0, 1))  # (i, s, k)
    Mom = np.empty(m.shape + (3,))
    for i in range(3):
        a = [[Ct[i, j] * Pt[j, l] for l in range(3)] for j in range(3)]
        for k in range(3):
            acc = 0.0
            for j in range(3):
                for l in range(3):
                    acc = acc + a[j][l] * Ct[k, l]
            Mom[..., i, k] = acc + mt[i] * mt[k]
    return m, Mom


def estep(z: np.ndarray, s: SmootherResult, win: Window) -> EStats:
    """E-step statistics of eq. 23/26 for the closed-form M-step (see module docstring)."""
    m, Mom = los_moments(s, win)
    w = win.weights(z.shape[0])  # (S,n,3)
    zz = z[:, 1:]
    N = np.einsum("ijk,sti,inl,stjn->skl", EPS, w, EPS, Mom, optimize=True)
    b = (np.einsum("ijk,stj,sti,sti->sk", EPS, m, w, zz, optimize=True)
         - np.einsum("ijk,sti,stji->sk", EPS, w, Mom, optimize=True))
    if win.stars is not None and win.star_y is not None:  # star images: a direct measurement of theta
        from .stars import normal_equations

        J, h = normal_equations(win.stars, win.star_y)
        return EStats(N + J, b + h, J)
    return EStats(N, b)


def mstep(st: EStats, theta: np.ndarray, tz_tol: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form minimiser of Tr(R^-1 B(theta)) in the observable subspace.

    Returns the new theta (S,3) and a boolean (S,3) mask of the eigen-directions
    kept fixed (unobservable), sorted like ``numpy.linalg.eigh``.
    """
    lam, V = np.linalg.eigh(st.N)
    keep = lam > tz_tol * lam[:, -1:]
    if st.J_stars is not None:  # star images observe every direction they inform (tz too), however
        # weakly next to the Mars vector's lateral information: held only where they add nothing
        sj = np.einsum("sik,ij,sjk->sk", V, st.J_stars, V)
        keep |= sj > tz_tol * np.linalg.eigvalsh(st.J_stars)[-1]
    inv = np.where(keep, 1.0 / np.where(keep, lam, 1.0), 0.0)
    r = st.b - np.einsum("sij,sj->si", st.N, theta)
    step = np.einsum("sij,sj,skj,sk->si", V, inv, V, r)
    return theta + step, ~keep


def trace_RinvB(theta: np.ndarray, z: np.ndarray, s: SmootherResult, win: Window) -> np.ndarray:
    """Tr(sum R_k^-1 B_k(theta)) evaluated directly from eq. 23 (S,), for checks.

    ``B_k = H P_{k|N} H^T + (z_k - h(X_{k|N}))(...)^T`` with the small-angle ``H``.
    """
    from .camera import misalignment_small

    A = misalignment_small(theta)  # (S,3,3)
    H = -np.einsum("sij,kjl->skil", A, win.C[1:])
    u = win.u_ref[1:] - np.einsum("kij,skj->ski", win.C[1:], s.xs[:, 1:, :3])
    res = z[:, 1:] - np.einsum("sij,skj->ski", A, u)
    w = win.weights(z.shape[0])
    HPH = np.einsum("skij,skjl,skml->skim", H, s.Ps[:, 1:, :3, :3], H)
    return (np.einsum("ski,skii->s", w, HPH) + np.einsum("ski,ski,ski->s", w, res, res))


def expected_complete_loglik(theta: np.ndarray, z: np.ndarray, s: SmootherResult, win: Window,
                             mu0: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """Eq. 21 without constants: the E-step function Q(theta | theta_r) (S,).

    Uses the A term (eq. 22) with the lag-one smoothed covariance ``P_{k,k-1|N}``.
    """
    n = win.n
    P0 = np.broadcast_to(P0, (z.shape[0], 6, 6))
    d0 = s.xs[:, 0] - mu0
    E0 = s.Ps[:, 0] + np.einsum("si,sj->sij", d0, d0)
    val = -0.5 * (np.linalg.slogdet(P0)[1] + np.trace(np.linalg.solve(P0, E0), axis1=1, axis2=2))
    Qinv = np.linalg.inv(win.Q)
    val -= 0.5 * n * np.linalg.slogdet(win.Q)[1]
    Aterm = 0.0
    for k in range(1, n + 1):
        Phi = win.Phi[k]
        dm = s.xs[:, k] - s.xs[:, k - 1] @ Phi.T
        Ak = (np.einsum("si,sj->sij", dm, dm) + s.Ps[:, k] - s.Plag[:, k] @ Phi.T
              - Phi @ s.Plag[:, k].transpose(0, 2, 1) + Phi @ s.Ps[:, k - 1] @ Phi.T)
        Aterm = Aterm + np.einsum("ij,sji->s", Qinv, Ak)
    val -= 0.5 * Aterm
    val += 0.5 * np.log(win.weights(z.shape[0])).sum(axis=(1, 2))
    val -= 0.5 * trace_RinvB(theta, z, s, win)
    return val


@dataclass
class EMTrace:
    """Per-evaluation history of one EM run over a window."""

    theta: list = field(default_factory=list)  # (S,3) after each map evaluation
    loglik: list = field(default_factory=list)  # (S,) observed-data LL at the evaluated theta
    unobservable: np.ndarray | None = None  # (S,3) bool, of the last M-step
    last_filter: FilterResult | None = None
    last_smoother: SmootherResult | None = None


def em_map(theta, z, x0, P0, win, tz_tol):
    """One EM map theta -> theta' (filter, smoother, E-step, M-step) and LL(theta)."""
    f = run_filter(z, theta, x0, P0, win, predicted=False)
    s = bryson_frazier(f, win, POS)  # identical to rts() (tested), no 6x6 inverses; position only
    new, unobs = mstep(estep(z, s, win), theta, tz_tol)
    ll = f.loglik
    if win.stars is not None and win.star_y is not None:
        from .stars import loglik

        ll = ll + loglik(win.stars, win.star_y, theta)
    return new, ll, unobs, f, s


def em_window(z: np.ndarray, theta0: np.ndarray, x0: np.ndarray, P0: np.ndarray, win: Window,
              iterations: int, method: str = "plain", tz_tol: float = 1e-6) -> EMTrace:
    """EM over one window with a budget of ``iterations`` EM maps.

    ``plain``: that many EM iterations (paper M); ``squarem``: ceil(M/3) SQUAREM
    cycles of 3 maps each, i.e. ``3 ceil(M/3)`` maps (6 for M = 5: the budget is
    rounded *up* to whole cycles; :func:`maps_per_segment` gives the count).
    """
    tr = EMTrace()
    theta = np.array(theta0, float)

    def F(th):
        new, ll, unobs, f, s = em_map(th, z, x0, P0, win, tz_tol)
        tr.theta.append(new)
        tr.loglik.append(ll)
        tr.unobservable = unobs
        tr.last_filter, tr.last_smoother = f, s
        return new, ll

    if method == "plain":
        for _ in range(iterations):
            theta, _ = F(theta)
    elif method == "squarem":
        for _ in range(max(1, -(-iterations // 3))):
            theta = squarem_cycle(theta, F)
    else:
        raise ValueError(f"approach.em.method must be 'plain' or 'squarem', got {method!r}")
    return tr


def maps_per_segment(method: str, iterations: int) -> int:
    """EM map evaluations :func:`em_window` spends on one segment (plain: M; SQUAREM: 3 ceil(M/3))."""
    return iterations if method == "plain" else 3 * max(1, -(-iterations // 3))


def ml_estimate(z: np.ndarray, theta0: np.ndarray, x0: np.ndarray, P0: np.ndarray, win: Window,
                tz_tol: float = 1e-6, max_maps: int = 60, step_tol_rad: float = 1e-4 * np.pi / 648000.0,
                per_seed: bool = True) -> tuple[np.ndarray, np.ndarray, EMTrace]:
    """Maximum-likelihood theta of one window's data: SQUAREM cycles from ``theta0`` until
    the cycle step in (tx, ty) is below ``step_tol_rad``, or ``max_maps`` maps.

    ``per_seed`` (default): each seed stops at its own first cycle that meets the step
    criterion and only the seeds still moving are iterated, so the other seeds of the batch
    (a Snakemake job's cases, ``approach.scatter``) no longer decide how long a seed iterates
    (they still touch its last bits, which SQUAREM amplifies to ~1e-4 arcsec on flat
    likelihoods), and stopped seeds cost nothing more. ``per_seed=False``: every seed is
    iterated until all meet it in the same cycle (the whole history of every seed, for the
    convergence study).

    Returns theta_ML (S,3), a per-seed flag that the step criterion was met, and the
    trace of every map (its last entries are the reference iterates; with ``per_seed``, a
    stopped seed keeps its estimate in ``theta`` and has NaN ``loglik``).
    """
    th = np.array(theta0, float)
    S = th.shape[0]
    tr = EMTrace()
    done = np.zeros(S, bool)
    act = np.arange(S)
    P0 = np.asarray(P0, float)
    while len(tr.theta) < max_maps and act.size:
        if act.size < S:               # (only per_seed ever drops seeds)
            t = em_window(z[act], th[act], x0[act], P0[act] if P0.ndim == 3 else P0, win.rows(act),
                          3, "squarem", tz_tol)
        else:
            t = em_window(z, th, x0, P0, win, 3, "squarem", tz_tol)
        for th_m, ll_m in zip(t.theta, t.loglik):
            full, ll = th.copy(), np.full(S, np.nan)
            full[act], ll[act] = th_m, ll_m
            tr.theta.append(full)
            tr.loglik.append(ll)
        if tr.unobservable is None:
            tr.unobservable = np.zeros((S, 3), bool)
        tr.unobservable[act] = t.unobservable
        new = t.theta[-1]
        step_ok = np.abs(new - th[act])[:, :2].max(1) < step_tol_rad
        th[act] = new
        if per_seed:
            done[act] = step_ok
            act = act[~step_ok]
        else:
            done[:] = step_ok
            if done.all():
                break
    return th, done, tr


def contraction_per_map(theta_start: np.ndarray, theta_end: np.ndarray, theta_ml: np.ndarray,
                        maps: int, floor_rad: float = 1e-6 * np.pi / 648000.0) -> np.ndarray:
    """Measured contraction factor per EM map toward the ML estimate of the same data (S,).

    ``(d_end / d_start) ** (1 / maps)`` with ``d = max(|tx - tx_ML|, |ty - ty_ML|)``:
    about 1 means the iteration does not approach its fixed point (stalled), 0 means
    it got there at once. NaN where the start is already within ``floor_rad`` of it.
    """
    d0 = np.abs(theta_start - theta_ml)[:, :2].max(1)
    d1 = np.abs(theta_end - theta_ml)[:, :2].max(1)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = (np.maximum(d1, 1e-300) / d0) ** (1.0 / max(maps, 1))
    return np.where(d0 > floor_rad, rate, np.nan)


#: Convergence labels of an EM run (SPEC A.3c as read in issue 28): from the data, not the start.
CONVERGED, STALLED, UNFINISHED = "converged", "stalled", "not converged"


def convergence_labels(dist_ml_arcsec: np.ndarray, rate: np.ndarray, ml_tol_arcsec: float,
                       rate_max: float) -> np.ndarray:
    """Per seed, what the EM run reached, read from the data it used (S,) str:

    * ``converged``: within ``ml_tol_arcsec`` (in tx and ty) of the maximum-likelihood
      estimate of that data, wherever it started;
    * ``stalled``: farther than that, and its measured contraction factor per map toward
      the ML estimate is at least ``rate_max`` (about 1: the iteration does not approach
      its fixed point);
    * ``not converged``: farther than that but still contracting (its map budget ran out).

    Whether a converged estimate means anything is the bound's reading, not this label's
    (:func:`opnav.approach.report.identifiability_reading`). Two starts on the same data
    reach the same ML estimate, hence the same label."""
    dist = np.asarray(dist_ml_arcsec, float)
    slow = np.nan_to_num(np.asarray(rate, float), nan=0.0) >= rate_max
    return np.where(dist <= ml_tol_arcsec, CONVERGED, np.where(slow, STALLED, UNFINISHED))


def squarem_cycle(theta0: np.ndarray, F) -> np.ndarray:
    """One SQUAREM (S3) cycle per seed, monotone in the observed-data log-likelihood."""
    th1, ll0 = F(theta0)
    th2, _ = F(th1)
    r = th1 - theta0
    v = th2 - th1 - r
    nr, nv = np.linalg.norm(r, axis=1), np.linalg.norm(v, axis=1)
    alpha = np.where(nv > 0, -nr / np.where(nv > 0, nv, 1.0), -1.0)
    alpha = np.minimum(alpha, -1.0)[:, None]
    th_acc = theta0 - 2.0 * alpha * r + alpha**2 * v
    th3, ll_acc = F(th_acc)
    ok = (ll_acc >= ll0)[:, None]
    return np.where(ok, th3, th2)
